#pragma once

// Scene building and CPU references shared by the lighting GPU tests (lighting_test.cpp,
// lighting_terms_test.cpp): scenes are built in code, written as .glb and loaded through scene.gltf;
// the CPU side ray-casts the same camera and evaluates core/shading's maths.
#include "tests/gpu/gpu_test.hpp"

#include "core/scene/scene.hpp"
#include "core/shading/sh.hpp"

#include <filesystem>
#include <functional>
#include <numbers>
#include <string>
#include <vector>

namespace vitrine::test::lighting {

inline constexpr double kPi = std::numbers::pi;

struct Tri {
    scene::Vertex a, b, c;
};

// A vertex with a unit normal, a tangent perpendicular to it, no UVs, colour and AO 1.
scene::Vertex vertex(glm::vec3 p, glm::vec3 n);

struct SceneBuilder {
    scene::Scene s;

    explicit SceneBuilder(const std::string& name) { s.name = name; }

    // Triangles are wound counter-clockwise seen from the side their vertex normals point to (glTF's
    // front face), whatever order they were given in; degenerate ones (UV sphere poles) are dropped.
    uint32_t mesh(const std::string& name, const std::vector<Tri>& tris, uint32_t material);
    // One layer with constant albedo, metallic and shininess (cavity 1, no emission); returns its index.
    uint32_t material(const std::string& name, glm::vec3 base, float metallic, float shininess);
    void node(const std::string& name, int32_t mesh, glm::vec3 translation = glm::vec3(0.0f));
    // A still glTF camera node at eye looking at target (+Y up); the scene node follows it.
    void camera(glm::vec3 eye, glm::vec3 target, float yfov);
    void sun(glm::vec3 toSun);
    // Writes lighting_<name>.glb into the test's scratch folder.
    std::filesystem::path write();
};

void addQuad(std::vector<Tri>& tris, glm::vec3 c, glm::vec3 u, glm::vec3 v, glm::vec3 n);
std::vector<Tri> boxTris(glm::vec3 half);
// UV sphere: vertices on the sphere, smooth normals (position / radius).
std::vector<Tri> sphereTris(float radius, int segments, int rings);

// Pinhole camera with Vulkan clip conventions (y down), written out from the camera's pose.
struct Pinhole {
    glm::dvec3 position{0.0};
    glm::dquat orientation{1, 0, 0, 0};
    double yfov = 0.8;
    double width = 1, height = 1;

    Pinhole(const scene::Scene& s, int w, int h);
    // Unit world direction of the ray through the centre of pixel (x, y).
    glm::dvec3 ray(int x, int y) const;
};

// Distance along the unit ray (o, d) to the sphere, or a negative value when it misses.
double hitSphere(glm::dvec3 o, glm::dvec3 d, glm::dvec3 centre, double radius);

glm::dvec3 rgb(const Image& img, int x, int y);
shading::Sh9 readSh(const Image& sh);

// The G-buffer stores base colour, metallic, vertex AO and cavity as UNORM8: CPU references use the
// stored values.
glm::vec3 unorm8(glm::vec3 c);
float unorm8(float c);

// Direct sun radiance by core/shading's BRDF (the π convention of brdf.glsl: intensity = E / π).
glm::dvec3 cpuSun(glm::dvec3 n, glm::dvec3 v, glm::dvec3 l, glm::vec3 base, float metallic, float shininess,
                  glm::dvec3 sunE);

// Largest per-channel error of a relative to b.
double relErr(glm::dvec3 a, glm::dvec3 b);

// Directional albedo at NoV of a BRDF x cosine (n = +Z, v in the xz plane): the integral of brdfCosine(n, v, l) over
// the hemisphere of l, by the midpoint rule on `steps` x `steps` cells uniform in cos(theta) and phi.
double directionalAlbedo(double NoV, int steps,
                         const std::function<double(glm::vec3 n, glm::vec3 v, glm::vec3 l)>& brdfCosine);

// KHR_materials_transmission's thin-walled specular BTDF as its description gives it, for light from behind a surface
// of normal n reaching the viewer at v: the GGX lobe of the light mirrored through the surface, lm = l − 2 (n·l) n,
// (1 − F(v·h)) D(n·h) Vis(n·v, n·lm) n·lm with h = |v + lm|, F Schlick's of f0 (core/shading's D and Vis); 0 for
// light on v's side. Written here apart from the renderers' thinTransmissionCosine.
double thinTransmissionLobe(glm::dvec3 n, glm::dvec3 v, glm::dvec3 l, double f0, float alpha);

// A lighting.deferred node reading the nodes of baseNodes(); shadowMap adds a node "shadow".
nlohmann::json lightingNode(nlohmann::json params, bool shadowMap);
// scene (scene.gltf of glb), gbuffer and sky (sky.procedural, 16² faces, no sun disk in the cube map).
nlohmann::json baseNodes(const std::filesystem::path& glb);
nlohmann::json graph(nlohmann::json nodes, nlohmann::json outputs, int w, int h);

} // namespace vitrine::test::lighting
