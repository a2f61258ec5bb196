#include "tests/gpu/lighting_scene.hpp"

#include "core/shading/brdf.hpp"

#include <algorithm>
#include <cmath>

namespace vitrine::test::lighting {

scene::Vertex vertex(glm::vec3 p, glm::vec3 n) {
    scene::Vertex v;
    v.position = p;
    v.normal = glm::normalize(n);
    glm::vec3 ref = std::abs(v.normal.y) < 0.99f ? glm::vec3(0, 1, 0) : glm::vec3(1, 0, 0);
    v.tangent = glm::vec4(glm::normalize(glm::cross(ref, v.normal)), 1.0f);
    return v;
}

uint32_t SceneBuilder::mesh(const std::string& name, const std::vector<Tri>& tris, uint32_t material) {
    scene::Primitive p;
    p.firstIndex = static_cast<uint32_t>(s.indices.size());
    p.vertexOffset = static_cast<uint32_t>(s.vertices.size());
    uint32_t count = 0;
    for (Tri t : tris) {
        glm::vec3 area = glm::cross(t.b.position - t.a.position, t.c.position - t.a.position);
        if (glm::length(area) < 1e-9f) continue;
        if (glm::dot(area, t.a.normal + t.b.normal + t.c.normal) < 0.0f) std::swap(t.b, t.c);
        for (const scene::Vertex& v : {t.a, t.b, t.c}) {
            s.vertices.push_back(v);
            s.indices.push_back(count++);
        }
    }
    p.indexCount = p.vertexCount = count;
    p.material = material;
    s.primitives.push_back(p);
    scene::Mesh m;
    m.name = name;
    m.firstPrimitive = static_cast<uint32_t>(s.primitives.size() - 1);
    m.primitiveCount = 1;
    s.meshes.push_back(m);
    return static_cast<uint32_t>(s.meshes.size() - 1);
}

uint32_t SceneBuilder::material(const std::string& name, glm::vec3 base, float metallic, float shininess) {
    scene::Material m;
    m.name = name;
    scene::MaterialLayer l;
    l.albedo.factor = glm::vec4(base, 1.0f);
    l.metallic = {metallic, 0.0f};
    l.shininess = {shininess, 0.0f};
    m.layers = {l};
    s.materials.push_back(m);
    return static_cast<uint32_t>(s.materials.size() - 1);
}

void SceneBuilder::node(const std::string& name, int32_t mesh, glm::vec3 translation) {
    scene::Node n;
    n.name = name;
    n.mesh = mesh;
    n.local.translation = translation;
    s.nodes.push_back(n);
    s.roots.push_back(static_cast<uint32_t>(s.nodes.size() - 1));
}

void SceneBuilder::camera(glm::vec3 eye, glm::vec3 target, float yfov) {
    scene::Camera lens;
    lens.name = "view";
    lens.yfov = yfov;
    lens.znear = 0.05f;
    s.cameras.push_back(lens);
    scene::Node n;
    n.name = "view";
    n.camera = static_cast<int32_t>(s.cameras.size() - 1);
    n.local.translation = eye;
    n.local.rotation = lookRotation(eye, target);
    s.nodes.push_back(n);
    s.roots.push_back(static_cast<uint32_t>(s.nodes.size() - 1));
}

void SceneBuilder::sun(glm::vec3 toSun) {
    s.hasSun = true;
    s.sun.toSun = glm::normalize(toSun);
}

std::filesystem::path SceneBuilder::write() {
    return writeSceneGlb(s, "lighting_" + s.name);
}
void addQuad(std::vector<Tri>& tris, glm::vec3 c, glm::vec3 u, glm::vec3 v, glm::vec3 n) {
    scene::Vertex p[4] = {vertex(c - u - v, n), vertex(c + u - v, n), vertex(c + u + v, n), vertex(c - u + v, n)};
    tris.push_back({p[0], p[1], p[2]});
    tris.push_back({p[0], p[2], p[3]});
}

std::vector<Tri> boxTris(glm::vec3 half) {
    std::vector<Tri> tris;
    for (int axis = 0; axis < 3; ++axis)
        for (float sign : {-1.0f, 1.0f}) {
            glm::vec3 n(0.0f), u(0.0f), v(0.0f);
            n[axis] = sign;
            u[(axis + 1) % 3] = half[(axis + 1) % 3];
            v[(axis + 2) % 3] = half[(axis + 2) % 3];
            addQuad(tris, n * half[axis], u, v, n);
        }
    return tris;
}

// UV sphere: vertices on the sphere, smooth normals (position / radius).
std::vector<Tri> sphereTris(float radius, int segments, int rings) {
    auto at = [&](int i, int j) {
        double theta = kPi * i / rings, phi = 2.0 * kPi * j / segments;
        glm::vec3 n(static_cast<float>(std::sin(theta) * std::cos(phi)), static_cast<float>(std::cos(theta)),
                    static_cast<float>(std::sin(theta) * std::sin(phi)));
        scene::Vertex v = vertex(n * radius, n);
        v.tangent = glm::vec4(static_cast<float>(-std::sin(phi)), 0.0f, static_cast<float>(std::cos(phi)), 1.0f);
        v.uv0 = glm::vec2(static_cast<float>(j) / segments, static_cast<float>(i) / rings);
        return v;
    };
    std::vector<Tri> tris;
    for (int i = 0; i < rings; ++i)
        for (int j = 0; j < segments; ++j) {
            tris.push_back({at(i, j), at(i + 1, j), at(i + 1, j + 1)});
            tris.push_back({at(i, j), at(i + 1, j + 1), at(i, j + 1)});
        }
    return tris;
}

// ---------------------------------------------------------------------------------------------
// CPU references

Pinhole::Pinhole(const scene::Scene& s, int w, int h) : width(w), height(h) {
    for (const scene::Node& n : s.nodes)
        if (n.camera >= 0) {
            position = glm::dvec3(n.local.translation);
            orientation = glm::dquat(n.local.rotation);
            yfov = s.cameras[n.camera].yfov;
            return;
        }
}

glm::dvec3 Pinhole::ray(int x, int y) const {
    double g = 1.0 / std::tan(0.5 * yfov);
    glm::dvec2 ndc = (glm::dvec2(x, y) + 0.5) / glm::dvec2(width, height) * 2.0 - 1.0;
    return glm::normalize(orientation * glm::dvec3(ndc.x * (width / height) / g, -ndc.y / g, -1.0));
}

double hitSphere(glm::dvec3 o, glm::dvec3 d, glm::dvec3 centre, double radius) {
    glm::dvec3 oc = o - centre;
    double b = glm::dot(oc, d), c = glm::dot(oc, oc) - radius * radius, disc = b * b - c;
    return disc <= 0.0 ? -1.0 : -b - std::sqrt(disc);
}

double thinTransmissionLobe(glm::dvec3 n, glm::dvec3 v, glm::dvec3 l, double f0, float alpha) {
    const double NoL = -glm::dot(n, l), NoV = glm::dot(n, v);
    if (NoL <= 0.0 || NoV <= 0.0) return 0.0;
    const glm::dvec3 lm = l - 2.0 * glm::dot(n, l) * n;
    const glm::dvec3 h = glm::normalize(v + lm);
    const double F = f0 + (1.0 - f0) * std::pow(1.0 - glm::dot(v, h), 5.0);
    return (1.0 - F) * shading::ggxD(static_cast<float>(glm::dot(n, h)), alpha) *
           shading::smithGgxVisibility(static_cast<float>(NoV), static_cast<float>(NoL), alpha) * NoL;
}

glm::dvec3 rgb(const Image& img, int x, int y) {
    const float* p = img.at(x, y);
    return {p[0], p[1], p[2]};
}

shading::Sh9 readSh(const Image& sh) {
    shading::Sh9 s;
    for (int i = 0; i < 9; ++i)
        s.c[i] = rgb(sh, i, 0);
    return s;
}

glm::vec3 unorm8(glm::vec3 c) {
    return glm::round(glm::clamp(c, 0.0f, 1.0f) * 255.0f) / 255.0f;
}

float unorm8(float c) {
    return std::round(std::clamp(c, 0.0f, 1.0f) * 255.0f) / 255.0f;
}

glm::dvec3 cpuSun(glm::dvec3 n, glm::dvec3 v, glm::dvec3 l, glm::vec3 base, float metallic, float shininess,
                  glm::dvec3 sunE) {
    return glm::dvec3(shading::shadeDirectional(glm::vec3(n), glm::vec3(v), glm::vec3(l), unorm8(base), metallic,
                                                shading::roughnessFromShininess(shininess), glm::vec3(sunE / kPi)));
}

double relErr(glm::dvec3 a, glm::dvec3 b) {
    double e = 0.0;
    for (int c = 0; c < 3; ++c)
        e = std::max(e, std::abs(a[c] - b[c]) / std::max(std::abs(b[c]), 1e-30));
    return e;
}

double directionalAlbedo(double NoV, int steps,
                         const std::function<double(glm::vec3 n, glm::vec3 v, glm::vec3 l)>& brdfCosine) {
    const glm::vec3 n(0, 0, 1), v(static_cast<float>(std::sqrt(1.0 - NoV * NoV)), 0.0f, static_cast<float>(NoV));
    double sum = 0.0;
    for (int i = 0; i < steps; ++i) {
        double u = (i + 0.5) / steps, r = std::sqrt(1.0 - u * u);
        for (int j = 0; j < steps; ++j) {
            double phi = 2.0 * kPi * (j + 0.5) / steps;
            glm::vec3 l(static_cast<float>(r * std::cos(phi)), static_cast<float>(r * std::sin(phi)),
                        static_cast<float>(u));
            sum += brdfCosine(n, v, l);
        }
    }
    return sum * (1.0 / steps) * (2.0 * kPi / steps);
}

nlohmann::json lightingNode(nlohmann::json params, bool shadowMap) {
    nlohmann::json in = {{"normal", "gbuffer.normal"},
                         {"base_color", "gbuffer.base_color"},
                         {"material", "gbuffer.material"},
                         {"emissive", "gbuffer.emissive"},
                         {"sheen", "gbuffer.sheen"},
                         {"depth", "gbuffer.depth"},
                         {"sky_sh", "sky.sh"},
                         {"sky", "sky.cubemap"},
                         {"camera", "scene.camera"}};
    if (shadowMap) {
        in["shadow_map"] = "shadow.shadow_map";
        in["cascades"] = "shadow.cascades";
    }
    return {{"type", "lighting.deferred"}, {"in", in}, {"params", params}};
}

// The sun is lit as a directional light, so the sky's cube map (the indirect specular) leaves its
// disk out, as sky.procedural's sun_in_cubemap asks; with it the sun would count twice on glossy
// surfaces.
nlohmann::json baseNodes(const std::filesystem::path& glb) {
    return {{"scene", {{"type", "scene.gltf"}, {"params", {{"path", glb.string()}}}}},
            {"gbuffer", {{"type", "gbuffer.layered"}, {"in", {{"scene", "scene.scene"}}}}},
            {"sky",
             {{"type", "sky.procedural"},
              {"in", {{"scene", "scene.scene"}}},
              {"params", {{"size", 16}, {"sun_in_cubemap", false}}}}}};
}

nlohmann::json graph(nlohmann::json nodes, nlohmann::json outputs, int w, int h) {
    return {{"format", "vitrine-graph/1"},
            {"frame", {{"width", w}, {"height", h}}},
            {"nodes", nodes},
            {"outputs", outputs}};
}

} // namespace vitrine::test::lighting
