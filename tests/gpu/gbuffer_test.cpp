// gbuffer.layered against independent CPU evaluations: per-pixel layer blending, exact jitter-free
// velocity, octahedral normals and Toksvig filtering (MUSEUM_SPEC §2). Every scene is built in code,
// written with exportGlb() and loaded through scene.gltf, so the whole path (glTF round trip, upload,
// camera clock, raster) is what is measured.
#include "tests/gpu/gpu_test.hpp"

#include "core/scene/scene.hpp"
#include "nodes/scene/scene_node.hpp"

#include <glm/gtc/quaternion.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>

namespace vitrine::test {
namespace {

using nlohmann::json;
namespace sc = vitrine::scene;

// ---------------------------------------------------------------------------------------------
// Scene building

struct SceneBuilder {
    sc::Scene s;

    SceneBuilder() { s.name = "gbuffer_test"; }

    uint32_t image(const std::string& name, uint32_t w, uint32_t h, const std::function<glm::u8vec4(uint32_t, uint32_t)>& f) {
        sc::TextureImage img;
        img.name = name;
        img.width = w;
        img.height = h;
        img.pixels.resize(static_cast<size_t>(w) * h * 4);
        for (uint32_t y = 0; y < h; ++y)
            for (uint32_t x = 0; x < w; ++x) {
                glm::u8vec4 v = f(x, y);
                for (int c = 0; c < 4; ++c) img.at(x, y)[c] = v[c];
            }
        s.images.push_back(std::move(img));
        return static_cast<uint32_t>(s.images.size() - 1);
    }

    int32_t texture(uint32_t image, sc::TextureUsage usage, sc::Sampler sampler) {
        sc::Texture t;
        t.name = s.images[image].name;
        t.image = image;
        t.usage = usage;
        t.sampler = sampler;
        s.textures.push_back(t);
        return static_cast<int32_t>(s.textures.size() - 1);
    }

    uint32_t mesh(const std::string& name, const std::vector<sc::Vertex>& v, const std::vector<uint32_t>& idx, uint32_t material) {
        sc::Primitive p;
        p.firstIndex = static_cast<uint32_t>(s.indices.size());
        p.indexCount = static_cast<uint32_t>(idx.size());
        p.vertexOffset = static_cast<uint32_t>(s.vertices.size());
        p.vertexCount = static_cast<uint32_t>(v.size());
        p.material = material;
        s.vertices.insert(s.vertices.end(), v.begin(), v.end());
        s.indices.insert(s.indices.end(), idx.begin(), idx.end());
        s.primitives.push_back(p);
        sc::Mesh m;
        m.name = name;
        m.firstPrimitive = static_cast<uint32_t>(s.primitives.size() - 1);
        m.primitiveCount = 1;
        s.meshes.push_back(m);
        return static_cast<uint32_t>(s.meshes.size() - 1);
    }

    uint32_t node(const std::string& name, int32_t mesh, const sc::Transform& t = {}) {
        sc::Node n;
        n.name = name;
        n.mesh = mesh;
        n.local = t;
        s.nodes.push_back(n);
        return static_cast<uint32_t>(s.nodes.size() - 1);
    }

    void cameraPath(const std::string& name, float yfov, std::vector<sc::CameraKey> keys) {
        sc::Camera lens;
        lens.name = name;
        lens.yfov = yfov;
        lens.znear = 0.05f;
        lens.zfar = 0.0f;
        s.cameras.push_back(lens);
        sc::CameraPath path;
        path.name = name;
        path.camera = static_cast<uint32_t>(s.cameras.size() - 1);
        path.smooth = false;
        path.keys = std::move(keys);
        s.cameraPaths.push_back(path);
    }

    std::filesystem::path write(const std::string& name) { return writeSceneGlb(s, "gbuffer_" + name); }
};

sc::Material singleLayer(float shininess) {
    sc::Material m;
    m.name = "plain";
    sc::MaterialLayer l;
    l.albedo.factor = glm::vec4(0.5f, 0.5f, 0.5f, 1.0f);
    l.shininess = {shininess, 0.0f};
    m.layers = {l};
    return m;
}

// A square in the object's XY plane facing +Z, uv (0,0) at the top-left corner (glTF: v down).
std::vector<sc::Vertex> quadVertices(float half, glm::vec2 uvMin, glm::vec2 uvMax, glm::vec4 color = glm::vec4(1.0f)) {
    std::vector<sc::Vertex> v(4);
    const glm::vec2 corners[4] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
    for (int i = 0; i < 4; ++i) {
        v[i].position = glm::vec3(corners[i] * half, 0.0f);
        v[i].normal = {0, 0, 1};
        v[i].tangent = {1, 0, 0, 1};
        glm::vec2 t = corners[i] * 0.5f + 0.5f; // 0..1, y up
        v[i].uv0 = {glm::mix(uvMin.x, uvMax.x, t.x), glm::mix(uvMin.y, uvMax.y, 1.0f - t.y)};
        v[i].color = color;
    }
    return v;
}
const std::vector<uint32_t> kQuadIndices = {0, 1, 2, 0, 2, 3}; // counter-clockwise seen from +Z

sc::Transform at(glm::vec3 t, glm::quat r = glm::quat(1, 0, 0, 0)) {
    sc::Transform tr;
    tr.translation = t;
    tr.rotation = r;
    return tr;
}

json gbufferGraph(const std::filesystem::path& glb, int w, int h, json sceneParams, json gbufferParams, int frames = 1) {
    sceneParams["path"] = glb.string();
    return {{"format", "vitrine-graph/1"},
            {"frame", {{"width", w}, {"height", h}, {"frames", frames}}},
            {"nodes",
             {{"scene", {{"type", "scene.gltf"}, {"params", sceneParams}}},
              {"gbuffer", {{"type", "gbuffer.layered"}, {"params", gbufferParams}, {"in", {{"scene", "scene.scene"}}}}}}},
            {"outputs",
             {{"normal", "gbuffer.normal"},
              {"base", "gbuffer.base_color"},
              {"material", "gbuffer.material"},
              {"velocity", "gbuffer.velocity"},
              {"emissive", "gbuffer.emissive"},
              {"depth", "gbuffer.depth"}}}};
}

// ---------------------------------------------------------------------------------------------
// Independent CPU mirrors

// Meyer et al. 2010, written from the paper rather than from shaders/common/octahedral.glsl.
glm::dvec3 octDecode(double ex, double ey) {
    glm::dvec3 n(ex, ey, 1.0 - std::fabs(ex) - std::fabs(ey));
    if (n.z < 0.0) {
        double x = n.x, y = n.y;
        n.x = (1.0 - std::fabs(y)) * (x >= 0.0 ? 1.0 : -1.0);
        n.y = (1.0 - std::fabs(x)) * (y >= 0.0 ? 1.0 : -1.0);
    }
    return glm::normalize(n);
}

double srgbToLinear(double c) { return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4); }

// Pinhole camera of CameraState with Vulkan clip conventions (y down), written out independently.
struct Pinhole {
    glm::dvec3 position{0.0};
    glm::dquat orientation{1, 0, 0, 0};
    double yfov = 0.8;
    double width = 1, height = 1;

    double g() const { return 1.0 / std::tan(0.5 * yfov); }
    double aspect() const { return width / height; }
    // World direction of the ray through a pixel position (pixel units, 0..width).
    glm::dvec3 ray(glm::dvec2 pixel) const {
        glm::dvec2 ndc = pixel / glm::dvec2(width, height) * 2.0 - 1.0;
        return orientation * glm::dvec3(ndc.x * aspect() / g(), -ndc.y / g(), -1.0);
    }
    glm::dvec3 toView(glm::dvec3 world) const { return glm::inverse(orientation) * (world - position); }
    glm::dvec2 project(glm::dvec3 world) const {
        glm::dvec3 v = toView(world);
        glm::dvec2 ndc(g() / aspect() * v.x / -v.z, -g() * v.y / -v.z);
        return (ndc + 1.0) * 0.5 * glm::dvec2(width, height);
    }
};

class Gbuffer : public GpuTest {};

// ---------------------------------------------------------------------------------------------
// 1. Layer blending

// Deterministic bytes (an LCG), so the textures are irregular but the same on every run.
struct Bytes {
    uint32_t state;
    uint8_t next() {
        state = state * 1664525u + 1013904223u;
        return static_cast<uint8_t>(state >> 24);
    }
};

struct TexelLookup {
    const sc::Scene& s;
    // Nearest, repeat, level 0: the texel a TextureRef reads at uv, per KHR_texture_transform
    // (uv' = T · R · S · uv). Sets `margin` to the distance (in texels) to the nearest texel edge.
    glm::dvec4 operator()(const sc::TextureRef& r, glm::dvec2 uv, double& margin) const {
        if (!r.valid()) return glm::dvec4(1.0);
        const sc::UvTransform& t = r.transform;
        double c = std::cos(static_cast<double>(t.rotation)), si = std::sin(static_cast<double>(t.rotation));
        glm::dvec2 st(uv.x * t.scale.x, uv.y * t.scale.y);
        glm::dvec2 p(c * st.x + si * st.y + t.offset.x, -si * st.x + c * st.y + t.offset.y);
        const sc::Texture& tex = s.textures[r.texture];
        const sc::TextureImage& img = s.images[tex.image];
        int idx[2];
        const double size[2] = {static_cast<double>(img.width), static_cast<double>(img.height)};
        for (int a = 0; a < 2; ++a) {
            double f = (p[a] - std::floor(p[a])) * size[a];
            double cell = std::floor(f);
            margin = std::min(margin, std::min(f - cell, cell + 1.0 - f));
            idx[a] = std::min(static_cast<int>(cell), static_cast<int>(size[a]) - 1);
        }
        const uint8_t* b = img.at(static_cast<uint32_t>(idx[0]), static_cast<uint32_t>(idx[1]));
        glm::dvec4 v(b[0] / 255.0, b[1] / 255.0, b[2] / 255.0, b[3] / 255.0);
        if (tex.usage == sc::TextureUsage::Color)
            for (int ch = 0; ch < 3; ++ch) v[ch] = srgbToLinear(v[ch]);
        return v;
    }
};

struct Surface {
    glm::dvec4 albedo;
    glm::dvec3 normal; // tangent space, not normalised
    double shininess, metallic, cavity, weight;
};

// The layer stack of material.hpp: layer 0 defines everything, each later layer blends the
// parameters in its `overrides` over the result below by its mask weight.
Surface cpuBlend(const sc::Scene& s, const sc::Material& m, glm::dvec2 uv, double& margin) {
    TexelLookup tex{s};
    auto scalar = [&](const sc::ScalarParam& p) {
        double texel = p.texture.valid() ? tex(p.texture, uv, margin)[p.channel] : 1.0;
        return static_cast<double>(p.atZero) + (static_cast<double>(p.factor) - p.atZero) * texel;
    };
    Surface out{};
    for (size_t i = 0; i < m.layers.size(); ++i) {
        const sc::MaterialLayer& l = m.layers[i];
        double w = 1.0;
        if (i > 0) {
            double texel = l.mask.texture.valid() ? tex(l.mask.texture, uv, margin)[l.mask.channel] : 1.0;
            w = std::clamp(l.mask.factor * texel, 0.0, 1.0);
            out.weight = w;
        }
        uint32_t bits = i == 0 ? sc::kLayerAll : l.overrides;
        auto blend = [&](auto below, auto value) { return below + (value - below) * w; };
        if (bits & sc::kLayerAlbedo)
            out.albedo = blend(out.albedo, glm::dvec4(l.albedo.factor) * tex(l.albedo.texture, uv, margin));
        if (bits & sc::kLayerNormal) {
            glm::dvec3 n(0, 0, 1);
            if (l.normal.texture.valid()) {
                n = glm::dvec3(tex(l.normal.texture, uv, margin)) * 2.0 - 1.0;
                n.x *= l.normal.scale;
                n.y *= l.normal.scale;
            }
            out.normal = blend(out.normal, n);
        }
        if (bits & sc::kLayerShininess) out.shininess = blend(out.shininess, scalar(l.shininess));
        if (bits & sc::kLayerMetallic) out.metallic = blend(out.metallic, scalar(l.metallic));
        if (bits & sc::kLayerCavity) out.cavity = blend(out.cavity, scalar(l.cavity));
    }
    return out;
}

TEST_F(Gbuffer, LayerBlendingMatchesCpuAtTexelCentres) {
    SceneBuilder b;
    sc::Sampler exact;
    exact.magFilter = exact.minFilter = sc::Filter::Nearest;
    exact.mipFilter = sc::MipFilter::None;
    Bytes rng{12345};
    auto randomImage = [&](const char* name, uint32_t size) {
        return b.image(name, size, size, [&](uint32_t, uint32_t) {
            return glm::u8vec4(rng.next(), rng.next(), rng.next(), rng.next());
        });
    };
    auto ref = [](int32_t texture, glm::vec2 scale, glm::vec2 offset, float rotation = 0.0f) {
        sc::TextureRef r;
        r.texture = texture;
        r.transform.scale = scale;
        r.transform.offset = offset;
        r.transform.rotation = rotation;
        return r;
    };
    // Pixel centres of the 64x64 frame sit at u = (i + 0.5) / 64; every transform below keeps them
    // at least 1/8 texel away from texel edges (the test also checks that, per lookup).
    const int32_t albedo0 = b.texture(randomImage("albedo0", 16), sc::TextureUsage::Color, exact);
    const int32_t normal0 = b.texture(b.image("normal0", 8, 8, [&](uint32_t, uint32_t) {
        // Tangent-space normals within ~50° of +Z.
        glm::dvec3 n(rng.next() / 255.0 * 1.6 - 0.8, rng.next() / 255.0 * 1.6 - 0.8, 1.0);
        n = glm::normalize(n) * 0.5 + 0.5;
        return glm::u8vec4(glm::round(n * 255.0), 255);
    }), sc::TextureUsage::Normal, exact);
    const int32_t shin0 = b.texture(randomImage("shininess0", 16), sc::TextureUsage::Data, exact);
    const int32_t metal0 = b.texture(randomImage("metallic0", 8), sc::TextureUsage::Data, exact);
    const int32_t cavity0 = b.texture(randomImage("cavity0", 16), sc::TextureUsage::Data, exact);
    const int32_t albedo1 = b.texture(randomImage("albedo1", 16), sc::TextureUsage::Color, exact);
    const int32_t normal1 = b.texture(b.image("normal1", 8, 8, [](uint32_t, uint32_t) { return glm::u8vec4(255, 0, 128, 255); }),
                                      sc::TextureUsage::Normal, exact);
    const int32_t shin1 = b.texture(randomImage("shininess1", 8), sc::TextureUsage::Data, exact);
    const uint8_t maskLevels[] = {0, 40, 90, 128, 170, 230, 255};
    const int32_t mask = b.texture(b.image("mask", 8, 8, [&](uint32_t, uint32_t) {
        return glm::u8vec4(rng.next(), maskLevels[rng.next() % 7], rng.next(), 255);
    }), sc::TextureUsage::Data, exact);

    sc::Material m;
    m.name = "two_layers";
    sc::MaterialLayer base;
    base.name = "base";
    base.albedo = {glm::vec4(0.9f, 1.0f, 0.8f, 1.0f), ref(albedo0, {1, 1}, {0, 0})};
    base.normal = {0.8f, ref(normal0, {2, 2}, {1.0f / 16, 0})};
    base.shininess = {0.9f, 0.2f, ref(shin0, {1, 1}, {0, 0}, 1.57079632679f), 1}; // rotated 90°, channel g
    base.metallic = {1.0f, 0.0f, ref(metal0, {0.5f, 0.5f}, {0.25f, 0.5f}), 2};   // magnified, channel b
    base.cavity = {1.0f, 0.2f, ref(cavity0, {1, 1}, {0, 0}), 0};
    sc::MaterialLayer top;
    top.name = "top";
    top.albedo = {glm::vec4(0.7f, 0.6f, 1.0f, 0.5f), ref(albedo1, {2, 1}, {0, 0.25f})};
    top.normal = {1.0f, ref(normal1, {1, 1}, {0, 0})};             // not overridden: must not show
    top.shininess = {0.95f, 0.1f, ref(shin1, {1, 1}, {0.125f, 0}), 3}; // channel a
    top.metallic = {1.0f, 1.0f};                                   // not overridden: must not show
    top.cavity = {0.3f, 0.0f};                                     // constant
    top.overrides = sc::kLayerAlbedo | sc::kLayerShininess | sc::kLayerCavity;
    top.mask = {1.5f, ref(mask, {1, 1}, {0, 0}, 3.14159265359f), 1}; // rotated 180°, channel g, clamps
    m.layers = {base, top};
    b.s.materials.push_back(m);

    const glm::vec4 vertexColor(1.0f, 0.8f, 0.6f, 0.75f);
    // yfov 90° at distance 1: the frame sees x, y in [-1, 1]; the quad is larger, with uv 0..1 over
    // exactly what the frame sees.
    b.node("quad", b.mesh("quad", quadVertices(2.0f, {-0.5f, -0.5f}, {1.5f, 1.5f}, vertexColor), kQuadIndices, 0),
           at({0, 0, -1}));
    b.cameraPath("front", 1.57079632679f, {{0.0f, glm::vec3(0.0f), glm::quat(1, 0, 0, 0), 1.57079632679f}});
    const int size = 64;
    auto out = runGraph(gbufferGraph(b.write("layers"), size, size, json::object(), {{"toksvig", false}}));

    const sc::Scene& s = b.s;
    double worst8 = 0.0, worstShin = 0.0, worstNormal = 0.0, worstDepth = 0.0;
    int checked = 0, edgeSkipped = 0, fullTop = 0, noTop = 0, partial = 0, metalDiffers = 0;
    for (int y = 0; y < size; ++y)
        for (int x = 0; x < size; ++x) {
            glm::dvec2 uv((x + 0.5) / size, (y + 0.5) / size);
            double margin = 1.0;
            Surface e = cpuBlend(s, m, uv, margin);
            if (margin < 0.02) {
                ++edgeSkipped;
                continue;
            }
            ++checked;
            fullTop += e.weight == 1.0;
            noTop += e.weight == 0.0;
            partial += e.weight > 0.0 && e.weight < 1.0;
            metalDiffers += e.weight > 0.5 && e.metallic < 0.9;
            const float* base8 = out["base"].at(x, y);
            const float* mat8 = out["material"].at(x, y);
            const float* nrm = out["normal"].at(x, y);
            const double expectBase[4] = {e.albedo.r * vertexColor.r, e.albedo.g * vertexColor.g, e.albedo.b * vertexColor.b,
                                          e.metallic};
            const double expectMat[4] = {e.albedo.a, 0.0, vertexColor.a, e.cavity};
            for (int c = 0; c < 4; ++c) {
                worst8 = std::max(worst8, std::fabs(base8[c] - expectBase[c]));
                worst8 = std::max(worst8, std::fabs(mat8[c] - expectMat[c]));
            }
            worstShin = std::max(worstShin, std::fabs(nrm[3] - e.shininess));
            // Tangent (1,0,0), bitangent (0,1,0), normal (0,0,1): tangent space is world space.
            glm::dvec3 expectN = glm::normalize(e.normal);
            worstNormal = std::max(worstNormal, glm::length(octDecode(nrm[0], nrm[1]) - expectN));
            worstDepth = std::max(worstDepth, std::fabs(nrm[2] - 1.0));
        }
    std::printf("layers: %d pixels, max error 8-bit %.5f (%.2f/255), shininess %.5f, normal %.5f, depth %.5f\n", checked,
                worst8, worst8 * 255.0, worstShin, worstNormal, worstDepth);
    EXPECT_EQ(edgeSkipped, 0);
    EXPECT_EQ(checked, size * size);
    // The mask must exercise all three cases, and the non-overridden metallic must matter somewhere.
    EXPECT_GT(fullTop, 100);
    EXPECT_GT(noTop, 100);
    EXPECT_GT(partial, 100);
    EXPECT_GT(metalDiffers, 100);
    EXPECT_LT(worst8, 2.0 / 255.0);     // 8-bit quantisation (and the GPU's sRGB decode)
    EXPECT_LT(worstShin, 1e-3);         // RGBA16F: step 2^-11 in [0.5, 1)
    EXPECT_LT(worstNormal, 2e-3);       // RGBA16F octahedral components
    EXPECT_LT(worstDepth, 1e-3);
}

// ---------------------------------------------------------------------------------------------
// 2. Velocity

constexpr int kVW = 96, kVH = 64;
constexpr double kFps = 24.0, kStart = 0.25;
constexpr int kFrames = 3; // the last frame is read back; its jitter is Halton index 3, non-trivial

struct VelocityRun {
    Image velocity, normal, depth;
};

VelocityRun runVelocity(const std::filesystem::path& glb, bool jitter) {
    auto out = runGraph(gbufferGraph(glb, kVW, kVH, {{"fps", kFps}, {"start", kStart}, {"jitter", jitter ? "halton" : "off"}}, json::object(), kFrames));
    return {out["velocity"], out["normal"], out["depth"]};
}

struct VelocityStats {
    double worst = 0.0, worstJitter = 0.0, worstDiff = 0.0, worstDepth = 0.0, maxSpeed = 0.0;
    double jitterShift = 0.0; // how much the true velocity changes over the jitter offset
    int covered = 0;
};

// expected(pixel) = the velocity of the surface point seen at that (unjittered) pixel position, and its
// view depth.
VelocityStats compareVelocity(const VelocityRun& plain, const VelocityRun& jittered,
                              const std::function<glm::dvec3(glm::dvec2)>& expected) {
    VelocityStats st;
    const glm::vec2 j = scene::jitterOffset(scene::JitterPattern::Halton, kFrames - 1);
    for (int y = 0; y < kVH; ++y)
        for (int x = 0; x < kVW; ++x) {
            if (plain.depth.at(x, y)[0] <= 0.0f) continue;
            ++st.covered;
            glm::dvec2 p(x + 0.5, y + 0.5);
            glm::dvec3 e = expected(p);
            glm::dvec2 v(plain.velocity.at(x, y)[0], plain.velocity.at(x, y)[1]);
            st.worst = std::max(st.worst, glm::length(v - glm::dvec2(e)));
            st.maxSpeed = std::max(st.maxSpeed, glm::length(glm::dvec2(e)));
            st.worstDepth = std::max(st.worstDepth, std::fabs(plain.normal.at(x, y)[2] - e.z) / e.z);
            // The jittered projection shows the point of unjittered position p - jitter at pixel centre p.
            glm::dvec3 ej = expected(p - glm::dvec2(j));
            glm::dvec2 vj(jittered.velocity.at(x, y)[0], jittered.velocity.at(x, y)[1]);
            st.worstJitter = std::max(st.worstJitter, glm::length(vj - glm::dvec2(ej)));
            st.worstDiff = std::max(st.worstDiff, glm::length(vj - v));
            st.jitterShift = std::max(st.jitterShift, glm::length(glm::dvec2(ej) - glm::dvec2(e)));
        }
    return st;
}

TEST_F(Gbuffer, VelocityOfCameraMotionMatchesReprojection) {
    SceneBuilder b;
    b.s.materials.push_back(singleLayer(0.5f));
    const double planeZ = -6.0;
    b.node("wall", b.mesh("wall", quadVertices(20.0f, {0, 0}, {1, 1}), kQuadIndices, 0), at({0, 0, static_cast<float>(planeZ)}));
    const glm::vec3 p0(0.0f), p1(5.0f, 2.0f, -1.5f);
    const glm::quat q0(1, 0, 0, 0), q1 = glm::angleAxis(0.3f, glm::normalize(glm::vec3(0.2f, 1.0f, 0.0f)));
    const float yfov = 0.8f;
    b.cameraPath("move", yfov, {{0.0f, p0, q0, yfov}, {1.0f, p1, q1, yfov}});
    auto glb = b.write("camera_motion");
    VelocityRun plain = runVelocity(glb, false), jittered = runVelocity(glb, true);

    auto camera = [&](double t) {
        Pinhole c;
        c.position = glm::mix(glm::dvec3(p0), glm::dvec3(p1), t);
        c.orientation = glm::normalize(glm::slerp(glm::dquat(q0), glm::dquat(q1), t));
        c.yfov = yfov;
        c.width = kVW;
        c.height = kVH;
        return c;
    };
    const double t = kStart + (kFrames - 1) / kFps;
    const Pinhole now = camera(t), before = camera(t - 1.0 / kFps);
    VelocityStats st = compareVelocity(plain, jittered, [&](glm::dvec2 p) {
        glm::dvec3 d = now.ray(p);
        double lambda = (planeZ - now.position.z) / d.z;
        glm::dvec3 hit = now.position + lambda * d;
        glm::dvec2 v = p - before.project(hit);
        return glm::dvec3(v, -now.toView(hit).z);
    });
    std::printf("camera velocity: max |v| %.3f px, error %.5f px, jittered %.5f px (vs unjittered %.5f, true change %.5f), depth rel %.2e\n",
                st.maxSpeed, st.worst, st.worstJitter, st.worstDiff, st.jitterShift, st.worstDepth);
    EXPECT_EQ(st.covered, kVW * kVH);
    EXPECT_GT(st.maxSpeed, 1.0); // the test means something
    EXPECT_LT(st.maxSpeed, 8.0); // RG16F keeps < 0.004 px there
    EXPECT_LT(st.worst, 0.01);
    EXPECT_LT(st.worstJitter, 0.01);
    // Jitter does not leak into velocity: the jittered run differs from the plain one only by the
    // change of the true velocity over the sub-pixel offset (a leak would add |jitter| ~ 0.4 px).
    EXPECT_LT(st.worstDiff, st.jitterShift + 0.005);
    EXPECT_LT(st.worstDepth, 1.5e-3); // binary16 keeps < 2^-10 relative, even truncated
}

TEST_F(Gbuffer, VelocityOfObjectMotionMatchesReprojection) {
    SceneBuilder b;
    b.s.materials.push_back(singleLayer(0.5f));
    const uint32_t wall = b.node("wall", b.mesh("wall", quadVertices(20.0f, {0, 0}, {1, 1}), kQuadIndices, 0));
    const glm::vec3 t0(-1.0f, -0.5f, -6.0f), t1(2.0f, 0.5f, -5.0f);
    const glm::quat r0(1, 0, 0, 0), r1 = glm::angleAxis(0.4f, glm::vec3(0, 1, 0));
    b.s.nodes[wall].local = at(t0, r0);
    sc::Animation anim;
    anim.name = "slide";
    anim.samplers = {{sc::Interpolation::Linear, {0.0f, 1.0f}, {glm::vec4(t0, 0.0f), glm::vec4(t1, 0.0f)}},
                     {sc::Interpolation::Linear, {0.0f, 1.0f}, {sc::toVec4(r0), sc::toVec4(r1)}}};
    anim.channels = {{wall, sc::AnimationPath::Translation, 0}, {wall, sc::AnimationPath::Rotation, 1}};
    b.s.animations.push_back(anim);
    const float yfov = 0.8f;
    b.cameraPath("fixed", yfov, {{0.0f, glm::vec3(0.0f), glm::quat(1, 0, 0, 0), yfov}});
    auto glb = b.write("object_motion");
    VelocityRun plain = runVelocity(glb, false), jittered = runVelocity(glb, true);

    auto world = [&](double t) {
        glm::dmat4 m = glm::mat4_cast(glm::normalize(glm::slerp(glm::dquat(r0), glm::dquat(r1), t)));
        m[3] = glm::dvec4(glm::mix(glm::dvec3(t0), glm::dvec3(t1), t), 1.0);
        return m;
    };
    Pinhole cam;
    cam.yfov = yfov;
    cam.width = kVW;
    cam.height = kVH;
    const double t = kStart + (kFrames - 1) / kFps;
    const glm::dmat4 now = world(t), before = world(t - 1.0 / kFps), toObject = glm::inverse(now);
    VelocityStats st = compareVelocity(plain, jittered, [&](glm::dvec2 p) {
        // Intersect the ray with the plane z = 0 of the object, in object space.
        glm::dvec3 o = glm::dvec3(toObject * glm::dvec4(0, 0, 0, 1));
        glm::dvec3 d = glm::dvec3(toObject * glm::dvec4(cam.ray(p), 0));
        glm::dvec3 q = o - (o.z / d.z) * d;
        glm::dvec3 hit = glm::dvec3(now * glm::dvec4(q, 1)), prev = glm::dvec3(before * glm::dvec4(q, 1));
        return glm::dvec3(p - cam.project(prev), -hit.z);
    });
    std::printf("object velocity: max |v| %.3f px, error %.5f px, jittered %.5f px (vs unjittered %.5f, true change %.5f), depth rel %.2e\n",
                st.maxSpeed, st.worst, st.worstJitter, st.worstDiff, st.jitterShift, st.worstDepth);
    EXPECT_EQ(st.covered, kVW * kVH);
    EXPECT_GT(st.maxSpeed, 1.0);
    EXPECT_LT(st.maxSpeed, 8.0);
    EXPECT_LT(st.worst, 0.01);
    EXPECT_LT(st.worstJitter, 0.01);
    EXPECT_LT(st.worstDiff, st.jitterShift + 0.005);
    EXPECT_LT(st.worstDepth, 1.5e-3); // binary16 keeps < 2^-10 relative, even truncated
}

// ---------------------------------------------------------------------------------------------
// 3. Octahedral normals of a sphere

glm::dvec2 octEncode(glm::dvec3 n) {
    n /= std::fabs(n.x) + std::fabs(n.y) + std::fabs(n.z);
    if (n.z >= 0.0) return {n.x, n.y};
    return {(1.0 - std::fabs(n.y)) * (n.x >= 0.0 ? 1.0 : -1.0), (1.0 - std::fabs(n.x)) * (n.y >= 0.0 ? 1.0 : -1.0)};
}

// The spacing of binary16 values around v (what one RGBA16F channel can resolve there).
double halfUlp(double v) {
    double a = std::fabs(v);
    if (a < std::ldexp(1.0, -14)) return std::ldexp(1.0, -24);
    int e = 0;
    std::frexp(a, &e); // a = m 2^e, m in [0.5, 1)
    return std::ldexp(1.0, e - 11);
}

// Möller–Trumbore; returns the distance along d (or -1) and the barycentrics of b and c.
double rayTriangle(glm::dvec3 o, glm::dvec3 d, glm::dvec3 a, glm::dvec3 b, glm::dvec3 c, double& u, double& v) {
    glm::dvec3 e1 = b - a, e2 = c - a, p = glm::cross(d, e2);
    double det = glm::dot(e1, p);
    if (std::fabs(det) < 1e-18) return -1.0;
    glm::dvec3 s = o - a;
    u = glm::dot(s, p) / det;
    glm::dvec3 q = glm::cross(s, e1);
    v = glm::dot(d, q) / det;
    if (u < 0.0 || v < 0.0 || u + v > 1.0) return -1.0;
    return glm::dot(e2, q) / det;
}

TEST_F(Gbuffer, SphereNormalsDecodeToAnalyticNormals) {
    SceneBuilder b;
    b.s.materials.push_back(singleLayer(0.5f));
    // A fine UV sphere (radius 1, outward counter-clockwise triangles, exact unit vertex normals).
    const int lat = 128, lon = 256;
    const double pi = 3.14159265358979323846;
    std::vector<sc::Vertex> verts;
    std::vector<uint32_t> idx;
    std::vector<std::vector<uint32_t>> cellTriangles(lat * lon); // first index of each triangle per cell
    for (int i = 0; i <= lat; ++i)
        for (int j = 0; j <= lon; ++j) {
            double th = pi * i / lat, ph = 2.0 * pi * j / lon;
            sc::Vertex v;
            v.normal = glm::vec3(std::sin(th) * std::cos(ph), std::cos(th), -std::sin(th) * std::sin(ph));
            v.position = v.normal;
            v.tangent = glm::vec4(-std::sin(ph), 0.0, -std::cos(ph), 1.0);
            v.uv0 = glm::vec2(static_cast<float>(j) / lon, static_cast<float>(i) / lat);
            verts.push_back(v);
        }
    auto vid = [&](int i, int j) { return static_cast<uint32_t>(i * (lon + 1) + j); };
    auto tri = [&](int cell, uint32_t a, uint32_t c, uint32_t d) {
        glm::vec3 pa = verts[a].position, pc = verts[c].position, pd = verts[d].position;
        glm::vec3 n = glm::cross(pc - pa, pd - pa);
        if (glm::length(n) < 1e-9f) return; // the pole rows' degenerate halves
        if (glm::dot(n, pa + pc + pd) < 0.0f) std::swap(c, d);
        cellTriangles[cell].push_back(static_cast<uint32_t>(idx.size()));
        idx.insert(idx.end(), {a, c, d});
    };
    for (int i = 0; i < lat; ++i)
        for (int j = 0; j < lon; ++j) {
            tri(i * lon + j, vid(i, j), vid(i + 1, j), vid(i + 1, j + 1));
            tri(i * lon + j, vid(i, j), vid(i + 1, j + 1), vid(i, j + 1));
        }
    const glm::dvec3 centre(0.0, 0.0, -4.0);
    b.node("sphere", b.mesh("sphere", verts, idx, 0), at(glm::vec3(centre)));
    // Looking along -X at the sphere: the visible normals have z of both signs, so both halves of the
    // octahedral map are written.
    const glm::dvec3 eye = centre + glm::dvec3(3.5, 0.8, 0.3);
    const float yfov = 0.8f;
    const glm::quat q = lookRotation(glm::vec3(eye), glm::vec3(centre));
    b.cameraPath("look", yfov, {{0.0f, glm::vec3(eye), q, yfov}});
    const int w = 96, h = 64;
    auto out = runGraph(gbufferGraph(b.write("sphere"), w, h, json::object(), json::object()));

    // The normal the GPU should write at a pixel: the mesh's interpolated vertex normal where the ray
    // hits the polyhedron (searched around the analytic hit's cell).
    auto meshNormal = [&](glm::dvec3 o, glm::dvec3 d, glm::dvec3 sphereHit, glm::dvec3& normal) {
        glm::dvec3 local = glm::normalize(sphereHit - centre);
        int ci = std::clamp(static_cast<int>(std::acos(std::clamp(local.y, -1.0, 1.0)) / (pi / lat)), 0, lat - 1);
        double ph = std::atan2(-local.z, local.x);
        if (ph < 0.0) ph += 2.0 * pi;
        int cj = static_cast<int>(ph / (2.0 * pi / lon));
        double best = 1e30;
        for (int di = -1; di <= 1; ++di)
            for (int dj = -1; dj <= 1; ++dj) {
                int i = ci + di, j = ((cj + dj) % lon + lon) % lon;
                if (i < 0 || i >= lat) continue;
                for (uint32_t first : cellTriangles[i * lon + j]) {
                    const sc::Vertex* t[3] = {&verts[idx[first]], &verts[idx[first + 1]], &verts[idx[first + 2]]};
                    double u = 0.0, v = 0.0;
                    double dist = rayTriangle(o, d, glm::dvec3(t[0]->position) + centre, glm::dvec3(t[1]->position) + centre,
                                              glm::dvec3(t[2]->position) + centre, u, v);
                    if (dist > 0.0 && dist < best) {
                        best = dist;
                        normal = glm::normalize((1.0 - u - v) * glm::dvec3(t[0]->normal) + u * glm::dvec3(t[1]->normal) +
                                                v * glm::dvec3(t[2]->normal));
                    }
                }
            }
        return best < 1e30;
    };

    Pinhole cam;
    cam.position = eye;
    cam.orientation = glm::dquat(q);
    cam.yfov = yfov;
    cam.width = w;
    cam.height = h;
    double worst = 0.0, worstMesh = 0.0, worstUlps = 0.0, worstDepth = 0.0;
    int sampled = 0, negativeZ = 0, positiveZ = 0, coverageMismatch = 0, missedFacet = 0;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            glm::dvec3 d = glm::normalize(cam.ray({x + 0.5, y + 0.5}));
            glm::dvec3 oc = eye - centre;
            double bq = glm::dot(oc, d), disc = bq * bq - (glm::dot(oc, oc) - 1.0);
            bool covered = out["depth"].at(x, y)[0] > 0.0f;
            // Pixels whose ray passes well inside or well outside the silhouette must agree.
            if (disc > 0.02 && !covered) ++coverageMismatch;
            if (disc < -0.02 && covered) ++coverageMismatch;
            if (disc <= 0.0 || !covered) continue;
            glm::dvec3 hit = eye + (-bq - std::sqrt(disc)) * d;
            glm::dvec3 n = glm::normalize(hit - centre);
            // Where the view is within ~53° of the normal (the polyhedron's facets stay close to the sphere).
            if (-glm::dot(n, d) < 0.6) continue;
            ++sampled;
            (n.z < 0.0 ? negativeZ : positiveZ)++;
            const float* g = out["normal"].at(x, y);
            glm::dvec3 decoded = octDecode(g[0], g[1]);
            worst = std::max(worst, glm::length(decoded - n));
            worstDepth = std::max(worstDepth, std::fabs(g[2] + cam.toView(hit).z));
            glm::dvec3 exact(0.0);
            if (!meshNormal(eye, d, hit, exact)) {
                ++missedFacet;
                continue;
            }
            worstMesh = std::max(worstMesh, glm::length(decoded - exact));
            glm::dvec2 code = octEncode(exact);
            for (int c = 0; c < 2; ++c) worstUlps = std::max(worstUlps, std::fabs(g[c] - code[c]) / halfUlp(code[c]));
        }
    std::printf("sphere: %d pixels (%d with n.z < 0); normal error vs the sphere %.2e, vs the mesh %.2e; code error %.2f "
                "binary16 ulps; depth error %.2e m\n",
                sampled, negativeZ, worst, worstMesh, worstUlps, worstDepth);
    EXPECT_EQ(coverageMismatch, 0);
    EXPECT_EQ(missedFacet, 0);
    EXPECT_GT(sampled, 300);
    EXPECT_GT(negativeZ, 50);
    EXPECT_GT(positiveZ, 50);
    // The encoder is exact up to the storage: each RGBA16F code channel within one binary16 ulp of the
    // CPU encoding of the mesh's normal (Vulkan lets a float -> half store round to nearest or toward
    // zero; lavapipe truncates, hence up to 1 ulp rather than 1/2).
    EXPECT_LE(worstUlps, 1.05);
    // Against the analytic sphere: 1 ulp of a code in [0.5, 1) is 2^-11 = 4.9e-4 per channel, which
    // the decode turns into up to ~1.6e-3 on the unit normal; the facets add < 3e-4 at these angles.
    // (1e-3 would need round-to-nearest storage; RGBA16F cannot promise it.)
    EXPECT_LT(worst, 2e-3);
    EXPECT_LT(worstDepth, 4e-3); // half float at 2..4 m (step 2^-9 = 2e-3, truncated) plus the facets' sag
}

// A double-sided quad seen from behind: glTF shades a back face with the normal reversed, so the G-buffer
// normal faces the camera (its vertex normal points away), and a single-sided copy of it is culled.
TEST_F(Gbuffer, BackFacesOfDoubleSidedMaterialsFaceTheViewer) {
    SceneBuilder b;
    sc::Material twoSided = singleLayer(0.5f);
    twoSided.doubleSided = true;
    b.s.materials.push_back(twoSided);
    b.s.materials.push_back(singleLayer(0.5f));
    // Turned half a turn about Y, the quads' front faces point to -Z, away from the camera at the origin that
    // looks down -Z: it sees their backs.
    const glm::quat away = glm::angleAxis(3.14159265f, glm::vec3(0, 1, 0));
    b.node("two_sided", b.mesh("two_sided", quadVertices(1.0f, {0, 0}, {1, 1}), kQuadIndices, 0), at({-1.2f, 0, -4}, away));
    b.node("one_sided", b.mesh("one_sided", quadVertices(1.0f, {0, 0}, {1, 1}), kQuadIndices, 1), at({1.2f, 0, -4}, away));
    b.cameraPath("look", 0.8f, {{0.0f, glm::vec3(0.0f), glm::quat(1, 0, 0, 0), 0.8f}});
    const int w = 64, h = 32;
    auto out = runGraph(gbufferGraph(b.write("back_faces"), w, h, json::object(), json::object()));
    int twoSidedPixels = 0, oneSidedPixels = 0, facingViewer = 0;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            if (out["depth"].at(x, y)[0] <= 0.0f) continue;
            if (x < w / 2) {
                ++twoSidedPixels;
                const float* g = out["normal"].at(x, y);
                // The camera is at the origin looking down -Z: a normal facing it has z > 0 in world space.
                if (octDecode(g[0], g[1]).z > 0.99) ++facingViewer;
            } else {
                ++oneSidedPixels;
            }
        }
    std::printf("back faces: %d double-sided pixels (%d facing the viewer), %d single-sided pixels drawn\n",
                twoSidedPixels, facingViewer, oneSidedPixels);
    EXPECT_GT(twoSidedPixels, 100);
    EXPECT_EQ(facingViewer, twoSidedPixels);
    EXPECT_EQ(oneSidedPixels, 0);
}

// alphaMode MASK: three quads side by side, the base colour's alpha 0.45 and 0.55 with the cut-off at 0.5 (the left
// one cut away, the middle one drawn), and 0.3 with the cut-off at 0.25 (drawn: the material's own cut-off decides).
TEST_F(Gbuffer, AlphaMaskDrawsWhatReachesItsCutoff) {
    SceneBuilder b;
    const float alphas[3] = {0.45f, 0.55f, 0.3f}, cutoffs[3] = {0.5f, 0.5f, 0.25f};
    for (int i = 0; i < 3; ++i) {
        sc::Material m = singleLayer(0.5f);
        m.layers[0].albedo.factor.a = alphas[i];
        m.alphaMode = sc::AlphaMode::Mask;
        m.alphaCutoff = cutoffs[i];
        b.s.materials.push_back(m);
        const std::string name = "mask" + std::to_string(i);
        b.node(name, b.mesh(name, quadVertices(1.5f, {0, 0}, {1, 1}), kQuadIndices, static_cast<uint32_t>(i)),
               at({-5.0f + 5.0f * static_cast<float>(i), 0, -4}, glm::quat(1, 0, 0, 0)));
    }
    b.cameraPath("look", 1.2f, {{0.0f, glm::vec3(0.0f), glm::quat(1, 0, 0, 0), 1.2f}});
    const int w = 96, h = 32;
    auto out = runGraph(gbufferGraph(b.write("alpha_mask"), w, h, json::object(), json::object()));
    int drawn[3] = {0, 0, 0};
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            if (out["depth"].at(x, y)[0] > 0.0f) ++drawn[std::min(3 * x / w, 2)];
    std::printf("alpha mask: %d pixels drawn of the quad below its cut-off, %d and %d of those above it\n", drawn[0],
                drawn[1], drawn[2]);
    EXPECT_EQ(drawn[0], 0);
    EXPECT_GT(drawn[1], 100);
    EXPECT_GT(drawn[2], 100);
}

// ---------------------------------------------------------------------------------------------
// 4. Toksvig through the G-buffer

// Toksvig as documented in shaders/common/brdf.glsl (toksvigRoughness), written out independently:
// GGX alpha = max(roughness^2, 0.002) -> Blinn-Phong exponent s = 2 / alpha^2 - 2, Toksvig's factor
// ft = |Na| / (|Na| + s (1 - |Na|)), alpha'^2 = 2 / (ft s + 2); the G-buffer stores
// shininess' = 1 - roughness' = 1 - alpha'^(1/2).
double cpuToksvigShininess(double shininess, double normalLength) {
    double na = std::clamp(normalLength, 1e-4, 1.0);
    double alpha = std::max((1.0 - shininess) * (1.0 - shininess), 0.002);
    double s = 2.0 / (alpha * alpha) - 2.0;
    double ft = na / (na + s * (1.0 - na));
    double alpha2 = 2.0 / (ft * s + 2.0);
    return 1.0 - std::pow(alpha2, 0.25);
}

// The Toksvig tests' scene: the builder's material 0 on a quad that fills the 90-degree camera looking down -Z.
std::filesystem::path writeFacingQuad(SceneBuilder& b, const char* name) {
    b.node("quad", b.mesh("quad", quadVertices(2.0f, {-0.5f, -0.5f}, {1.5f, 1.5f}), kQuadIndices, 0), at({0, 0, -1}));
    b.cameraPath("front", 1.57079632679f, {{0.0f, glm::vec3(0.0f), glm::quat(1, 0, 0, 0), 1.57079632679f}});
    return b.write(name);
}

TEST_F(Gbuffer, ToksvigLowersShininessOfHighMipsByTheFormula) {
    SceneBuilder b;
    // Columns alternate between normals tilted about ±45° around the bitangent. The bytes are chosen so
    // that no 2x2 average is a rounding tie: x averages to exactly 128, y stays 128, z stays 218.
    const uint32_t n = 16;
    const uint8_t lo = 37, hi = 219, z = 218;
    const uint32_t img = b.image("ridges", n, n, [&](uint32_t x, uint32_t) { return glm::u8vec4(x % 2 ? hi : lo, 128, z, 255); });
    sc::Sampler trilinear; // linear, linear, mip linear, repeat
    const int32_t tex = b.texture(img, sc::TextureUsage::Normal, trilinear);
    const float shininess = 0.8f;
    sc::Material m = singleLayer(shininess);
    m.layers[0].normal.texture.texture = tex;
    // 64 repeats across the 64-pixel frame: 16 texels per pixel, so the 1x1 level 4 is sampled (the
    // same as a quad far away, without shrinking it to a few pixels).
    m.layers[0].normal.texture.transform.scale = glm::vec2(64.0f);
    b.s.materials.push_back(m);
    auto glb = writeFacingQuad(b, "toksvig");
    const int size = 64;
    auto on = runGraph(gbufferGraph(glb, size, size, json::object(), {{"toksvig", true}}));
    auto off = runGraph(gbufferGraph(glb, size, size, json::object(), {{"toksvig", false}}));

    // Every level from 1 on holds (128, 128, 218): the plain average of a lo and a hi column; the direction shaded
    // is that average's. Toksvig reads the length of the mean of the two columns' UNIT normals (the bytes' own
    // lengths, 1.0038 and 1.0094 here, are rounding, not disagreement).
    const glm::dvec3 average = glm::dvec3((lo + hi) / 2.0, 128.0, z) / 255.0 * 2.0 - 1.0;
    const glm::dvec3 unitLo = glm::normalize(glm::dvec3(lo, 128.0, z) / 255.0 * 2.0 - 1.0);
    const glm::dvec3 unitHi = glm::normalize(glm::dvec3(hi, 128.0, z) / 255.0 * 2.0 - 1.0);
    const double len = glm::length(0.5 * (unitLo + unitHi));
    const double expected = cpuToksvigShininess(shininess, len);
    const glm::dvec3 direction = glm::normalize(average); // tangent space = world space on this quad

    double worstOn = 0.0, worstOff = 0.0, worstN = 0.0;
    int notLower = 0;
    for (int y = 0; y < size; ++y)
        for (int x = 0; x < size; ++x) {
            const float* a = on["normal"].at(x, y);
            const float* c = off["normal"].at(x, y);
            worstOn = std::max(worstOn, std::fabs(a[3] - expected));
            worstOff = std::max(worstOff, std::fabs(static_cast<double>(c[3]) - shininess));
            notLower += !(a[3] < c[3] - 0.1f);
            // The averaged normal's direction is kept (renormalised); only its length feeds Toksvig.
            worstN = std::max(worstN, glm::length(octDecode(a[0], a[1]) - direction));
            worstN = std::max(worstN, glm::length(octDecode(c[0], c[1]) - direction));
        }
    std::printf("toksvig: |n| %.4f, shininess %.3f -> expected %.4f, error %.5f (off: error %.5f), normal error %.5f\n", len,
                shininess, expected, worstOn, worstOff, worstN);
    EXPECT_LT(len, 0.75); // the mips really are shortened
    EXPECT_EQ(notLower, 0);
    EXPECT_LT(worstOn, 2e-3); // RGBA16F output; the texels are exact (no filtering between differing values)
    EXPECT_LT(worstOff, 1e-3);
    EXPECT_LT(worstN, 2e-3);
}

// A flat normal map whose bytes decode short of unit length, (128, 128, 254): |n| = 0.9922, as 8-bit rounding
// leaves many nearly flat normals. Its normals all agree, so Toksvig must leave a polished surface polished at
// every level. (Read from the decoded vector's length, it made the museum's roughness-0.05 floor 0.35.)
TEST_F(Gbuffer, ToksvigIgnoresTheRoundingOfFlatNormals) {
    SceneBuilder b;
    const uint32_t n = 16;
    const uint32_t img = b.image("flat", n, n, [&](uint32_t, uint32_t) { return glm::u8vec4(128, 128, 254, 255); });
    const int32_t tex = b.texture(img, sc::TextureUsage::Normal, sc::Sampler{});
    const float shininess = 0.95f;
    sc::Material m = singleLayer(shininess);
    m.layers[0].normal.texture.texture = tex;
    m.layers[0].normal.texture.transform.scale = glm::vec2(64.0f); // level 4 sampled, as above
    b.s.materials.push_back(m);
    auto glb = writeFacingQuad(b, "toksvig_flat");
    const int size = 64;
    auto on = runGraph(gbufferGraph(glb, size, size, json::object(), {{"toksvig", true}}));
    const double wrong = cpuToksvigShininess(shininess, glm::length(glm::dvec3(0.00196, 0.00196, 0.99216)));
    double worst = 0.0;
    for (int y = 0; y < size; ++y)
        for (int x = 0; x < size; ++x) worst = std::max(worst, std::fabs(double(on["normal"].at(x, y)[3]) - shininess));
    std::printf("toksvig, flat map of short bytes: worst shininess error %.5f (from the bytes' length: %.3f)\n", worst,
                shininess - wrong);
    EXPECT_LT(worst, 1e-3);
}

// The normal map's scale (glTF normalTexture.scale) tilts every normal further, so they disagree more: columns
// tilted +-10 deg about the bitangent, drawn at scale 2 (about +-19.4 deg). Expected: Toksvig of the mean of the
// scaled unit normals, computed here; the G-buffer approximates 1 - L as scale^2 (1 - L at scale 1), which
// holds for small slopes (0.0608 against 0.0568 here, measured error 0.009 in shininess). Without the scale the
// shininess would be 0.15 higher.
TEST_F(Gbuffer, ToksvigWidensWithTheNormalScale) {
    SceneBuilder b;
    const uint32_t n = 16;
    const double tilt = glm::radians(10.0);
    auto encode = [](double v) { return static_cast<uint8_t>(std::lround((v * 0.5 + 0.5) * 255.0)); };
    const uint8_t lo = encode(-std::sin(tilt)), hi = encode(std::sin(tilt)), z = encode(std::cos(tilt));
    const uint32_t img = b.image("ridges10", n, n, [&](uint32_t x, uint32_t) { return glm::u8vec4(x % 2 ? hi : lo, 128, z, 255); });
    sc::Sampler trilinear;
    const int32_t tex = b.texture(img, sc::TextureUsage::Normal, trilinear);
    const float shininess = 0.8f, scale = 2.0f;
    sc::Material m = singleLayer(shininess);
    m.layers[0].normal.texture.texture = tex;
    m.layers[0].normal.scale = scale;
    m.layers[0].normal.texture.transform.scale = glm::vec2(64.0f);
    b.s.materials.push_back(m);
    auto glb = writeFacingQuad(b, "toksvig_scale");
    const int size = 64;
    auto on = runGraph(gbufferGraph(glb, size, size, json::object(), {{"toksvig", true}}));
    auto scaled = [&](uint8_t x) {
        glm::dvec3 v = glm::dvec3(x, 128.0, z) / 255.0 * 2.0 - 1.0;
        v.x *= scale;
        v.y *= scale;
        return glm::normalize(v);
    };
    const double len = glm::length(0.5 * (scaled(lo) + scaled(hi)));
    const double expected = cpuToksvigShininess(shininess, len);
    double worst = 0.0;
    for (int y = 0; y < size; ++y)
        for (int x = 0; x < size; ++x) worst = std::max(worst, std::fabs(double(on["normal"].at(x, y)[3]) - expected));
    std::printf("toksvig at normal scale %.1f: |mean| %.4f -> shininess %.4f, worst error %.4f\n", scale, len, expected,
                worst);
    EXPECT_LT(worst, 0.02);
}

// ---------------------------------------------------------------------------------------------
// Texture level of detail must not depend on how a surface is triangulated: a plane drawn as 2 and as
// 512 triangles gives the same base colour. (lavapipe once sampled the smallest mips along triangle
// edges, because implicit derivatives inside the material loop depended on helper invocations.)
TEST_F(Gbuffer, TextureDetailDoesNotDependOnTessellation) {
    auto build = [](int cells) {
        SceneBuilder b;
        const uint32_t n = 64;
        const uint32_t img = b.image("checker", n, n, [](uint32_t x, uint32_t y) {
            uint8_t v = ((x / 4 + y / 4) % 2) ? 230 : 25;
            return glm::u8vec4(v, v, v, 255);
        });
        sc::Material m = singleLayer(0.5f);
        m.layers[0].albedo.factor = glm::vec4(1.0f);
        m.layers[0].albedo.texture.texture = b.texture(img, sc::TextureUsage::Color, sc::Sampler{});
        m.layers[0].albedo.texture.transform.scale = glm::vec2(4.0f);
        b.s.materials.push_back(m);
        // A 6 x 6 m floor in the XZ plane, cells x cells quads sharing their vertices.
        std::vector<sc::Vertex> v;
        std::vector<uint32_t> idx;
        for (int j = 0; j <= cells; ++j)
            for (int i = 0; i <= cells; ++i) {
                sc::Vertex vert;
                float u = static_cast<float>(i) / cells, w = static_cast<float>(j) / cells;
                vert.position = {-3.0f + 6.0f * u, 0.0f, -3.0f + 6.0f * w};
                vert.normal = {0, 1, 0};
                vert.tangent = {1, 0, 0, 1};
                vert.uv0 = {u, w};
                v.push_back(vert);
            }
        for (int j = 0; j < cells; ++j)
            for (int i = 0; i < cells; ++i) {
                uint32_t a = static_cast<uint32_t>(j * (cells + 1) + i), c = a + static_cast<uint32_t>(cells) + 1;
                idx.insert(idx.end(), {a, c, a + 1, a + 1, c, c + 1}); // counter-clockwise seen from +Y
            }
        b.node("floor", b.mesh("floor", v, idx, 0));
        glm::vec3 eye(0.0f, 1.2f, 3.5f);
        b.cameraPath("view", 1.2f, {{0.0f, eye, lookRotation(eye, glm::vec3(0.0f, 0.0f, -1.0f)), 1.2f}});
        return b.write("floor" + std::to_string(cells));
    };
    const int w = 96, h = 64;
    auto coarse = runGraph(gbufferGraph(build(1), w, h, json::object(), json::object()));
    auto fine = runGraph(gbufferGraph(build(16), w, h, json::object(), json::object()));
    double worst = 0.0, sum = 0.0;
    int covered = 0;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            if (coarse["depth"].at(x, y)[0] <= 0.0f) continue; // no floor here (above the horizon)
            ++covered;
            double d = std::fabs(static_cast<double>(coarse["base"].at(x, y)[0]) - fine["base"].at(x, y)[0]);
            worst = std::max(worst, d);
            sum += d;
        }
    std::printf("tessellation: %d floor pixels, max |diff| %.4f, mean %.5f\n", covered, worst, sum / std::max(covered, 1));
    EXPECT_GT(covered, w * h / 3);
    // Equal up to interpolation rounding across different triangles (a wrong mip shows as ~0.4).
    EXPECT_LT(worst, 4.0 / 255.0);
}

} // namespace
} // namespace vitrine::test
