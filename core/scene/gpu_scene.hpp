#pragma once
// The GPU copy of a scene and the objects that travel on scene/camera ports of the render graph.
//
// A scene node (scene.museum, scene.gltf) makes a SceneObject in setup() — CPU data only, so
// `vitrine validate` needs no GPU — and a CameraObject; its execute() uploads the scene on the first
// frame and then, every frame, poses the animated nodes and the camera and writes them to per-frame
// buffers. Raster nodes bind GpuScene::set() (layout: shaders/scene/scene.glsl) and draw through it.

#include "core/gpu/buffer_set.hpp"
#include "core/gpu/resources.hpp"
#include "core/graph/node.hpp"
#include "core/scene/deformation.hpp"
#include "core/scene/jitter.hpp"
#include "core/scene/scene.hpp"
#include "shaders/scene/scene.h"

#include <glm/glm.hpp>

#include <array>
#include <memory>
#include <vector>

namespace vitrine {

class Context;
class GpuBvh;
class ShaderCompiler;
namespace accel {
class SceneBvh;
}

// One frame's camera, as every consumer sees it (CPU mirror of gpu_types::GpuCamera).
struct CameraFrame {
    scene::CameraState state; // pose and lens; state.view / state.world are the view matrix and its inverse
    glm::mat4 proj{1.0f};         // jittered, reverse Z
    glm::mat4 projNoJitter{1.0f}; // reverse Z
    glm::mat4 viewProj{1.0f};
    glm::mat4 viewProjNoJitter{1.0f};
    glm::mat4 prevViewProjNoJitter{1.0f};
    glm::mat4 invViewProj{1.0f};
    glm::vec2 jitter{0.0f}; // pixels
    glm::vec2 prevJitter{0.0f};
    float vertexJitterThreshold = 0.0f; // > 0: per-vertex jitter (shaders/scene/jitter.glsl), pixels per frame
    uint32_t width = 1, height = 1;
    double time = 0.0;
    uint32_t frame = 0;

    gpu_types::GpuCamera gpu() const;
};

class CameraObject final : public PortObject {
public:
    CameraFrame current;
    // The scene node's jitter settings (known at setup, so consumers such as aa.accumulate can check them).
    scene::JitterPattern jitterPattern = scene::JitterPattern::Off;
    uint32_t jitterGrid = 16;
};

struct GpuDraw {
    uint32_t instance = 0;  // index into Scene::instances and the instance buffer
    uint32_t primitive = 0; // index into Scene::primitives
    uint32_t material = 0;
};

struct GpuSceneStats {
    uint64_t geometryBytes = 0;
    uint64_t textureBytes = 0; // all mips
    double uploadMs = 0.0;
};

// Vertex/index buffers, layered materials, textures with mips (normal maps: Toksvig mips built on the
// GPU without renormalising), per-frame instance and camera buffers, and the descriptor set over all of
// them. Everything but the per-frame buffers is uploaded once, in the constructor (waits for the GPU).
// The scene's layered materials as the GPU reads them (scene.h GpuMaterial / GpuLayer); also what the CPU path
// tracer evaluates, so both read one description.
void packMaterials(const scene::Scene& scene, std::vector<gpu_types::GpuMaterial>& materials,
                   std::vector<gpu_types::GpuLayer>& layers);

// Level 0 of every texture as packed RGBA8 texels (r in the low byte) and per texture a uvec4 (first texel, width,
// height, VITRINE_TEXEL_* bits): what ray tracers sample (shaders/scene/scene.glsl VITRINE_SCENE_TEXEL_POOL and the
// CPU path tracer). At least one entry in each.
struct TexelPool {
    std::vector<std::array<uint32_t, 4>> table;
    std::vector<uint32_t> texels;
};
TexelPool packTexelPool(const scene::Scene& scene);

class GpuScene {
public:
    // anisotropy: max anisotropic filtering of the textures; < 0 chooses per device.
    GpuScene(Context& ctx, ShaderCompiler& shaders, const scene::Scene& scene, float anisotropy = -1.0f);
    ~GpuScene();
    GpuScene(const GpuScene&) = delete;
    GpuScene& operator=(const GpuScene&) = delete;

    // Writes this frame's instance transforms (with last frame's for velocity) and camera, and poses the meshes that
    // deform (scene::Deformation: moving skins, animated morph weights). The vertex buffer is then host-visible, and
    // the same deformation with `previous` writes those vertices' last-frame positions (binding 5) for velocity; the
    // ray-tracing BVH follows through SceneObject::reposeBvh(). Safe while recording: the render graph runs one frame
    // in flight, so the GPU is done with the last frame.
    void update(const scene::ScenePose& pose, const scene::ScenePose& previous, const CameraFrame& camera);

    VkDescriptorSetLayout setLayout() const { return mSetLayout; }
    VkDescriptorSet set() const { return mSet; }
    uint32_t textureCount() const { return static_cast<uint32_t>(mTextures.size()); }
    // Opaque and alpha-masked draws (the G-buffer, shadow maps); transparent ones (Material::transparent():
    // alpha BLEND or transmission) are apart, for forward.transparent.
    const std::vector<GpuDraw>& draws() const { return mDraws; }
    const std::vector<GpuDraw>& transparentDraws() const { return mTransparentDraws; }
    const GpuSceneStats& stats() const { return mStats; }
    const GpuImage& texture(uint32_t index) const { return mTextures.at(index); }

    // Binding 0: the scene's Vertex (72 bytes): position, normal, tangent, uv0, uv1, color at locations 0-5.
    static std::vector<VkVertexInputBindingDescription> vertexBindings();
    static std::vector<VkVertexInputAttributeDescription> vertexAttributes();
    // The vertex buffer (scene::Vertex, 72 bytes: 18 floats) and index buffer (uint32, relative to the
    // primitive's vertexOffset), also storage buffers: a ray tracer fetches a hit's vertices from them
    // (GpuBvhPrimitive, shaders/accel/bvh.h).
    const GpuBuffer& vertexBuffer() const { return mVertices; }
    const GpuBuffer& indexBuffer() const { return mIndices; }
    // Both as one descriptor set (binding 0 vertices, 1 indices; compute stage), made on first use: the
    // VITRINE_GEOMETRY_SET of shaders/pathtrace/surface.glsl. Bindings 2 and 3 are the texel pool: level 0 of
    // every texture as packed RGBA8 (binding 3) and a table of where each texture starts, its size, colour
    // space and wrap modes (binding 2, uvec4 per texture; shaders/scene/scene.glsl VITRINE_SCENE_TEXEL_POOL).
    // A ray tracer's invocations hit different textures; one buffer they all index replaces a walk over the
    // sampler array, which costs one texture sample per scene texture on devices without non-uniform indexing.
    const StorageBufferSet& geometrySet();
    // Binds the vertex and index buffers. Then drawIndexed(cmd, draw) per draw.
    void bindGeometry(VkCommandBuffer cmd) const;
    void drawIndexed(VkCommandBuffer cmd, const GpuDraw& draw) const;

private:
    void uploadTextures(ShaderCompiler& shaders);
    void buildToksvigMips(ShaderCompiler& shaders, VkCommandBuffer cmd, const std::vector<uint32_t>& normalMaps);
    void createDescriptors();
    void releaseHandles();

    Context& mCtx;
    const scene::Scene& mScene;
    GpuBuffer mVertices, mIndices, mMaterials, mLayers, mInstances, mCamera;
    GpuBuffer mPrevPositions;       // vec4 per vertex when meshes deform (else one): last frame's positions, binding 5
    GpuBuffer mTexelTable, mTexels; // the texel pool (geometrySet() bindings 2 and 3), made with the set
    StorageBufferSet mGeometrySet;
    std::vector<GpuImage> mTextures;       // one per scene texture
    std::vector<VkSampler> mSamplers;      // one per scene texture
    GpuImage mFallback;                    // bound when the scene has no textures
    VkDescriptorSetLayout mSetLayout = VK_NULL_HANDLE;
    VkDescriptorPool mPool = VK_NULL_HANDLE;
    VkDescriptorSet mSet = VK_NULL_HANDLE;
    std::vector<GpuDraw> mDraws;
    std::vector<GpuDraw> mTransparentDraws;
    GpuSceneStats mStats;
    float mAnisotropy = -1.0f;
    scene::Deformation mDeformation;
    std::vector<scene::Vertex> mPosed; // scratch of update(): Scene::vertices with the deformed meshes posed
};

// What travels on a Scene port. CPU data from setup(); the GPU copy once a pass asks for it.
class SceneObject final : public PortObject {
public:
    explicit SceneObject(std::shared_ptr<const scene::Scene> scene);
    ~SceneObject() override;
    const scene::Scene& scene() const { return *mScene; }
    std::shared_ptr<const scene::Scene> shared() const { return mScene; }
    bool uploaded() const { return mGpu != nullptr; }
    GpuScene& gpu(Context& ctx, ShaderCompiler& shaders) {
        if (!mGpu) mGpu = std::make_unique<GpuScene>(ctx, shaders, *mScene, anisotropy);
        return *mGpu;
    }
    GpuScene& gpu() const; // InternalError before the producer uploaded it

    // The scene's ray-tracing BVH on the GPU (core/accel/gpu_bvh.hpp), for passes that trace rays. The
    // first call loads it from the bake cache ($VITRINE_CACHE_DIR/bake/bvh), or builds and stores it (at rest), and
    // uploads it posed at `pose`, deforming meshes refit; the scene node re-poses it every frame after that (repose()).
    // `transparent`: the BVH that also holds the transparent primitives (accel::BvhBuildOptions::transparent), a second
    // one.
    GpuBvh& bvh(Context& ctx, bool transparent = false);
    bool hasBvh() const { return mGpuBvh[0] != nullptr || mGpuBvh[1] != nullptr; }
    bool bvhFromCache() const { return mBvhFromCache; }
    // Every uploaded BVH at `pose`: its top level, and its deforming meshes' levels refit (accel::SceneBvh::refit).
    void reposeBvh(const scene::ScenePose& pose);
    // What of the scene deforms (made on the first call).
    const scene::Deformation& deformation() const;
    void releaseGpu() override;

    // The pose of this frame and the last one (set by the scene node every frame).
    scene::ScenePose pose, previousPose;
    double time = 0.0;
    float anisotropy = -1.0f; // texture filtering, set by the scene node before the upload

private:
    std::shared_ptr<const scene::Scene> mScene;
    std::unique_ptr<GpuScene> mGpu;
    // [0] without, [1] with the transparent primitives.
    std::unique_ptr<accel::SceneBvh> mBvh[2]; // CPU copy, kept across releaseGpu()
    std::unique_ptr<GpuBvh> mGpuBvh[2];
    mutable std::unique_ptr<scene::Deformation> mDeformation;
    bool mBvhFromCache = false;
};

} // namespace vitrine
