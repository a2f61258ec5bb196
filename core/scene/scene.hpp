#pragma once

// The CPU side of a scene: flat arrays ready for GPU upload (one vertex buffer, one index buffer, draw
// ranges), layered materials (MUSEUM_SPEC §2), a node hierarchy with animations, cameras, camera paths,
// the sun and the rooms that later receive cubemap probes. Filled by loadGltf() (gltf.hpp) or
// buildMuseum() (museum.hpp); read by the scene nodes of the render graph and by the bakers.
//
// Conventions: right-handed, +Y up, metres, seconds, radians (glTF's). Colours are linear unless a
// texture says Srgb. Quaternions are stored as glm::quat; on disk they are x, y, z, w (glTF order).

#include "core/scene/animation.hpp"
#include "core/scene/material.hpp"

#include <cstdint>
#include <limits>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

namespace vitrine::scene {

// Axis-aligned box; empty() until a point is added.
struct Aabb {
    glm::vec3 min{std::numeric_limits<float>::max()};
    glm::vec3 max{std::numeric_limits<float>::lowest()};

    bool empty() const { return min.x > max.x; }
    void expand(const glm::vec3& p) {
        min = glm::min(min, p);
        max = glm::max(max, p);
    }
    void expand(const Aabb& b) {
        if (!b.empty()) {
            expand(b.min);
            expand(b.max);
        }
    }
    bool contains(const glm::vec3& p) const {
        return glm::all(glm::greaterThanEqual(p, min)) && glm::all(glm::lessThanEqual(p, max));
    }
    glm::vec3 center() const { return 0.5f * (min + max); }
    glm::vec3 extent() const { return max - min; }
    Aabb transformed(const glm::mat4& m) const;
};

// One vertex exactly as the GPU reads it: 18 floats, no padding, so a storage buffer with scalar
// (or std430 with float arrays) layout or a vertex buffer with stride 72 maps it 1:1.
struct Vertex {
    glm::vec3 position{0.0f};
    glm::vec3 normal{0.0f, 1.0f, 0.0f};
    // xyz: unit tangent along +u of uv0; w = ±1 with bitangent = cross(normal, tangent.xyz) * w (glTF).
    glm::vec4 tangent{1.0f, 0.0f, 0.0f, 1.0f};
    glm::vec2 uv0{0.0f};
    // Lightmap coordinates. The museum makes them unique per static mesh (non-overlapping charts in
    // [0,1]², one atlas per mesh, each static mesh instanced once); glTF files bring their own
    // TEXCOORD_1, or (0, 0).
    glm::vec2 uv1{0.0f};
    // rgb: linear vertex colour (glTF COLOR_0, multiplies base colour). a: vertex ambient occlusion,
    // 1 = unoccluded (glTF attribute _AO). COLOR_0's own alpha is not kept: coverage comes from the material only.
    glm::vec4 color{1.0f};
};
static_assert(sizeof(Vertex) == 72, "Vertex must stay tightly packed: the GPU side mirrors it");

// What one morph target adds to one vertex at weight 1 (glTF's POSITION, NORMAL and TANGENT displacements).
struct MorphDelta {
    glm::vec3 position{0.0f};
    glm::vec3 normal{0.0f};
    glm::vec3 tangent{0.0f};
};

// A skinned vertex in bind space: glTF's POSITION, NORMAL, TANGENT (the mesh's morph weights applied) with JOINTS_0
// (indices into Skin::joints, held as floats) and WEIGHTS_0.
struct SkinVertex {
    glm::vec3 position{0.0f};
    glm::vec3 normal{0.0f, 1.0f, 0.0f};
    glm::vec4 tangent{1.0f, 0.0f, 0.0f, 1.0f};
    glm::vec4 joints{0.0f};
    glm::vec4 weights{0.0f};
};

// A glTF skin: joint nodes and their inverse bind matrices (identity when the file has none).
struct Skin {
    std::string name;
    std::vector<uint32_t> joints;
    std::vector<glm::mat4> inverseBind;
};

// A draw: an indexed triangle list with one material. Indices are relative to vertexOffset, so a
// primitive draws with vkCmdDrawIndexed(indexCount, 1, firstIndex, vertexOffset, 0).
struct Primitive {
    uint32_t firstIndex = 0;
    uint32_t indexCount = 0;
    uint32_t vertexOffset = 0;
    uint32_t vertexCount = 0;
    uint32_t material = 0;
    // Its Vertex::uv1 is a lightmap parameterisation (charts without overlap inside [0, 1]²): set by the
    // procedural museum for lightmapped meshes and by the glTF loader when TEXCOORD_1 is present. Static
    // instances of such meshes get lightmaps (core/bake/lightmap_atlas.hpp).
    bool lightmapUvs = false;
    Aabb bounds; // object space
    // Morph targets: target t's delta for vertex v is Scene::morphDeltas[firstDelta + t × vertexCount + v]. The
    // vertices themselves are the rest pose, the mesh's weights already applied (Mesh::weights).
    uint32_t firstDelta = 0;
    uint32_t targetCount = 0;
    // Skinned (JOINTS_0 and WEIGHTS_0): its bind-space vertices are Scene::skinVertices[firstSkinVertex + v]; the
    // vertices themselves are the rest pose, skinned by the first node that draws the mesh with a skin.
    bool skinned = false;
    uint32_t firstSkinVertex = 0;
};

// A mesh is a contiguous range of Scene::primitives.
struct Mesh {
    std::string name;
    uint32_t firstPrimitive = 0;
    uint32_t primitiveCount = 0;
    Aabb bounds; // object space, set by Scene::finalize()
    // Morph target weights of the rest pose (glTF's node or mesh `weights`), one per target of its primitives;
    // empty without targets. An animation of the weights re-morphs from here (morphVertices()).
    std::vector<float> weights;
    // The narrowest gap between two charts of its lightmap UVs (Vertex::uv1), in uv1 units: the lightmap atlas sizes
    // the mesh's region so that this gap spans enough texels for bilinear filtering and dilation to keep charts apart
    // (core/bake/lightmap_atlas.hpp). 0: not known (a glTF file's TEXCOORD_1), sized by texel density alone.
    float lightmapChartGap = 0.0f;
};

struct Transform {
    glm::vec3 translation{0.0f};
    glm::quat rotation{1.0f, 0.0f, 0.0f, 0.0f}; // w, x, y, z in glm's constructor
    glm::vec3 scale{1.0f};

    glm::mat4 matrix() const;
};

struct Node {
    std::string name;
    Transform local;
    int32_t parent = -1; // set by Scene::finalize()
    std::vector<uint32_t> children;
    int32_t mesh = -1;
    int32_t camera = -1; // a lens in Scene::cameras, posed by this node
    int32_t skin = -1;   // Scene::skins: its mesh's skinned primitives follow the skin's joints
    // True when an animation moves this node or one of its ancestors (set by Scene::finalize()).
    // Static meshes get lightmaps; dynamic ones are lit by probes only.
    bool dynamic = false;
};

// A mesh placed in the world by a node; one per node that has a mesh and is reachable from a root.
struct MeshInstance {
    uint32_t node = 0;
    uint32_t mesh = 0;
    glm::mat4 world{1.0f}; // at rest (no animation); per-frame values come from Scene::evaluate()
    bool dynamic = false;
    Aabb worldBounds; // at rest
};

enum class Projection : uint8_t { Perspective, Orthographic };

// A lens. yfov/near/far are what the rasteriser needs; the physical fields feed exposure, depth of
// field and bokeh (MUSEUM_SPEC §7). Defaults describe a full-frame DSLR with a ~28 mm lens at f/4.
struct Camera {
    std::string name;
    Projection projection = Projection::Perspective;
    float yfov = 0.8f;              // radians, vertical
    float aspectRatio = 0.0f;       // as authored (0: none); the frame's aspect is what projects (see projection())
    float znear = 0.05f;            // metres
    float zfar = 0.0f;              // metres; 0 = infinite far plane (glTF)
    float xmag = 1.0f, ymag = 1.0f; // orthographic half-extents (metres)
    float sensorWidthMm = 36.0f;
    float sensorHeightMm = 24.0f;
    float fNumber = 4.0f;
    float focusDistance = 5.0f;       // metres
    float shutterTime = 1.0f / 60.0f; // seconds
    float iso = 100.0f;
    uint32_t apertureBlades = 7;

    // Derived from yfov and the sensor so that the two can never disagree.
    float focalLengthMm() const;
};

// One key of a camera path.
struct CameraKey {
    float time = 0.0f;
    glm::vec3 position{0.0f};
    glm::quat orientation{1.0f, 0.0f, 0.0f, 0.0f}; // camera looks down its local -Z, +Y up (glTF)
    float yfov = 0.8f;
};

// A named camera move ("walkthrough", "dolly", "static"). Positions follow a Catmull-Rom spline through
// the keys when smooth (C1, no overshoot handles to author), else straight lines; orientations slerp;
// yfov is linear. Times outside the keys clamp, or wrap when loop is set.
struct CameraPath {
    std::string name;
    uint32_t camera = 0; // the lens in Scene::cameras (near/far/physical); yfov comes from the keys
    bool smooth = true;
    bool loop = false;
    std::vector<CameraKey> keys;

    float duration() const { return keys.empty() ? 0.0f : keys.back().time - keys.front().time; }
    // Velocity (m/s) at a key: the Catmull-Rom tangent when smooth (one-sided at the ends), 0 otherwise.
    // glTF export writes it as the CUBICSPLINE in- and out-tangent, which reproduces the same curve.
    glm::vec3 tangent(size_t key) const;
};

// A camera ready for a frame: matrices follow Vulkan's clip conventions.
struct CameraState {
    glm::vec3 position{0.0f};
    glm::quat orientation{1.0f, 0.0f, 0.0f, 0.0f};
    Camera lens; // lens.yfov is the path's value at this time
    glm::mat4 world{1.0f};
    glm::mat4 view{1.0f};

    // Right-handed view space in, Vulkan clip space out: y points down, depth 0 (near) .. 1 (far), or
    // 1 .. 0 when reverseZ. frameAspect = width / height. Never stretched by lens.aspectRatio, as the Khronos glTF
    // Sample Viewer draws: perspective keeps lens.yfov (the frame's width sets the horizontal field of view);
    // orthographic keeps ymag when frameAspect > 1 (xmag = ymag × frameAspect), else xmag (ymag = xmag / frameAspect).
    glm::mat4 projection(float frameAspect, bool reverseZ = false) const;
};

// The single directional light (MUSEUM_SPEC §3).
struct Sun {
    glm::vec3 toSun{0.0f, 1.0f, 0.0f}; // unit vector from the scene towards the sun
    glm::vec3 color{1.0f};             // linear, max component 1
    // On a surface facing the sun: color × illuminance is the illuminance in linear Rec.709 whose luminance is in lux
    // (for a white sun, illuminance is the lux), as glTF's KHR_lights_punctual directional color × intensity.
    // The shader's π convention is its own.
    float illuminance = 100000.0f;
    float angularDiameter = 0.00931f;  // radians (0.53°): shadow penumbra
};

enum class LightType : uint8_t { Point, Spot };

// A KHR_lights_punctual point or spot light, placed by its node (a spot shines down the node's −Z). Unshadowed;
// the sun (Scene::sun) stays the one shadowed light.
struct PunctualLight {
    std::string name;
    LightType type = LightType::Point;
    glm::vec3 color{1.0f};      // linear
    float intensity = 1.0f;     // candela (lm/sr): the illuminance at distance d facing it is intensity / d²
    float range = 0.0f;         // metres; 0 = infinite (glTF's windowing (1 − (d/range)⁴)² beyond)
    float innerConeAngle = 0.0f;           // radians, spot only
    float outerConeAngle = 0.7853981634f;  // radians, spot only (glTF's default π/4)
    uint32_t node = 0;
};

// A named box of space; the probe placement gives each a cubemap with this influence volume.
struct Room {
    std::string name;
    Aabb bounds;
};

// A localized reflection probe (MUSEUM_SPEC §4), placed in the scene like a light: a cube map captured at
// `position` (ibl.capture) that shades only the pixels inside its influence volume (ibl.localized). Probe i of
// Scene::probes is layer block [6i, 6i + 6) of the captured cube-map array.
enum class ProbeShape : uint8_t { Box, Sphere };

struct ReflectionProbe {
    std::string name;
    glm::vec3 position{0.0f};  // capture point, world
    ProbeShape shape = ProbeShape::Box;
    glm::vec3 center{0.0f};    // influence volume centre, world
    glm::vec3 halfExtents{1.0f}; // box: half sizes along its local axes; sphere: x is the radius
    glm::quat rotation{1.0f, 0.0f, 0.0f, 0.0f}; // box orientation (local -> world)
    float fade = 0.5f;         // metres inside the border over which the blend weight ramps from 0 to 1
    // Overlapping probes blend by weight; a probe's weight is its fade weight times 16^priority, so a
    // higher-priority probe (an alcove inside a hall) dominates where both apply.
    int32_t priority = 0;
    // The parallax correction's proxy [Lagarde12], apart from the influence volume: a box in the probe's own axes
    // (`rotation`) standing for the surroundings the probe sees, e.g. the whole room around a small doorway volume.
    // Box probes only; zero half extents (the default): the influence volume is the proxy.
    glm::vec3 projectionCenter{0.0f};
    glm::vec3 projectionHalfExtents{0.0f};
    bool hasProjection() const { return projectionHalfExtents != glm::vec3(0.0f); }
};

// World transforms of every node and instance at one time.
struct ScenePose {
    std::vector<glm::mat4> nodeWorld;     // index = node
    std::vector<glm::mat4> instanceWorld; // index = instance
    // Morph weights, index = mesh: empty unless an animation drives the weights of a node that draws the mesh (the
    // vertex range is the mesh's, so every node that draws it shows them).
    std::vector<std::vector<float>> meshWeights;
};

struct Scene {
    std::string name;

    std::vector<Vertex> vertices;
    std::vector<uint32_t> indices;
    std::vector<Primitive> primitives;
    std::vector<Mesh> meshes;
    std::vector<MorphDelta> morphDeltas; // see Primitive::firstDelta
    std::vector<Skin> skins;
    std::vector<SkinVertex> skinVertices; // see Primitive::firstSkinVertex

    std::vector<Material> materials;
    std::vector<Texture> textures;
    std::vector<TextureImage> images;

    std::vector<Node> nodes;
    std::vector<uint32_t> roots; // nodes of the displayed scene
    std::vector<MeshInstance> instances;
    std::vector<Camera> cameras;
    std::vector<CameraPath> cameraPaths;
    std::vector<Animation> animations;

    Sun sun;
    bool hasSun = false;
    std::vector<PunctualLight> lights;
    std::vector<Room> rooms;
    std::vector<ReflectionProbe> probes;
    Aabb bounds; // world, at rest, set by finalize()

    // Derives parent links, dynamic flags, instances, primitive/mesh bounds and scene bounds from the
    // primary data. Loaders and builders call it last; call it again after editing nodes or meshes.
    void finalize();

    // Checks every cross-reference and the texture colour spaces; InternalError names the element.
    // Loaders guarantee it; builders and tests call it.
    void validate() const;

    // Node and instance world transforms with every animation applied at time t (seconds).
    ScenePose evaluate(double t) const;

    // The vertices of primitive p with morph weights w instead of the rest weights (Mesh::weights):
    // rest + Σ (w − rest) × delta per target; normals and tangents renormalised. out has p's vertexCount.
    void morphVertices(uint32_t primitive, const std::vector<float>& weights, std::span<Vertex> out) const;

    // The skin matrices of a node with a skin at a pose (glTF: inverse(world of the node) × world of joint j ×
    // inverseBind j, so the node's own transform, applied when drawing, cancels as the specification asks).
    std::vector<glm::mat4> jointMatrices(uint32_t node, const ScenePose& pose) const;
    // The vertices of skinned primitive p under joint matrices: Σ weight × matrix × bind-space vertex; normals and
    // tangents by the inverse transpose, renormalised. out has p's vertexCount.
    void skinPrimitive(uint32_t primitive, const std::vector<glm::mat4>& joints, std::span<Vertex> out) const;
    // World transforms of the nodes at rest (no animation), as finalize() poses the instances.
    ScenePose restPose() const;

    // The named camera path at time t. UserError naming the path and listing the known ones if absent.
    CameraState cameraAt(std::string_view path, double t) const;
    const CameraPath* findCameraPath(std::string_view path) const;

    // 64-bit hash of all content (geometry, materials, textures, nodes, cameras, paths, animations,
    // sun, rooms, probes) but not of derived data. Equal scenes hash equal on every run and build; used by
    // determinism tests and as a key of bake caches.
    uint64_t contentHash() const;
    // The same without the reflection probes and without lightmap UVs (Vertex::uv1 where no material samples
    // texture set 1, Mesh::lightmapChartGap): what light transport depends on, the key of path-traced references,
    // so that moving a probe or re-packing the lightmap charts keeps a converged reference.
    uint64_t lightTransportHash() const;
    // Light transport and the lightmap UVs, without the probes: the key of the lightmap bake.
    uint64_t lightmapHash() const;

    size_t triangleCount() const { return indices.size() / 3; }
    // CPU bytes of geometry and texture pixels: what an upload will roughly cost.
    size_t memoryBytes() const;

private:
    uint64_t hashContent(bool withProbes, bool withLightmapUvs) const;
};

} // namespace vitrine::scene
