// aa.taa and aa.accumulate against independent expectations (MUSEUM_SPEC §6): the tone-mapped running mean of a
// pixel alternating between 0.1 and 100, reprojection of a panned textured plane (no drift, no blur build-up),
// ghosting of a moving object, the depth test on a panning, dollying camera (same surface kept, disocclusion
// rejected, edges following the nearest surface) against CPU ray casts of both frames, and the accumulated zone plate
// against pattern.zoneplate's own supersampling.
// Scenes are built in code, written as glTF and loaded through scene.gltf + gbuffer.layered, so TAA reads the
// real velocity and depth.
#include "tests/gpu/gpu_test.hpp"

#include "core/base/error.hpp"
#include "core/graph/node.hpp"
#include "core/graph/registry.hpp"
#include "core/scene/jitter.hpp"
#include "core/scene/scene.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>

namespace vitrine::test {
namespace {

using nlohmann::json;
namespace sc = vitrine::scene;

// test.sequence: a uniform RGBA32F image of colour `a` on frame 0; then, with `alternate`, `b` and `a` in turn,
// else a one-pixel checkerboard of `b` (x + y even) and `c`.
const char* kSequenceSource = R"(#version 460
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0) writeonly uniform image2D out_color;
layout(push_constant) uniform Push { vec4 even; vec4 odd; } pc;
void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(p, imageSize(out_color)))) return;
    imageStore(out_color, p, vec4((p.x + p.y) % 2 == 0 ? pc.even.rgb : pc.odd.rgb, 1.0));
}
)";

class Sequence final : public Node {
public:
    void setup(SetupContext& ctx) override { mPipeline = ctx.computePipelineSource("test/sequence", kSequenceSource); }
    void execute(ExecuteContext& ctx) override {
        const Params& p = ctx.params();
        const uint32_t f = ctx.frameIndex();
        glm::vec3 even = p.getVec3("a"), odd = even;
        if (f > 0 && p.getBool("alternate")) even = odd = f % 2 ? p.getVec3("b") : p.getVec3("a");
        if (f > 0 && !p.getBool("alternate")) {
            even = p.getVec3("b");
            odd = p.getVec3("c");
        }
        const glm::vec4 push[2] = {glm::vec4(even, 1.0f), glm::vec4(odd, 1.0f)};
        const ImageDesc& out = ctx.output("color").desc();
        ctx.dispatch(mPipeline, push, sizeof(push), out.width, out.height);
    }

private:
    PipelineId mPipeline = 0;
};

NodeSchema sequenceSchema() {
    NodeSchema s;
    s.type = "test.sequence";
    s.doc = "test-only node of test_gpu";
    OutputPort out;
    out.name = "color";
    out.format = VK_FORMAT_R32G32B32A32_SFLOAT;
    out.doc = "test output";
    s.outputs = {out};
    s.params = {{"a", ParamType::Vec3, json::array({0.1, 0.1, 0.1}), {}, {}, {}, "frame 0 (and even frames)"},
                {"b", ParamType::Vec3, json::array({100.0, 100.0, 100.0}), {}, {}, {}, "odd frames / checker"},
                {"c", ParamType::Vec3, json::array({1.0, 1.0, 1.0}), {}, {}, {}, "checker"},
                {"alternate", ParamType::Bool, true, {}, {}, {}, "a, b, a, b ... (else a, then the b/c checker)"}};
    return s;
}
const NodeRegistration kSequence(sequenceSchema(), [] { return std::make_unique<Sequence>(); });

json graph(json nodes, json outputs, int w, int h, int frames) {
    return {{"format", "vitrine-graph/1"},
            {"frame", {{"width", w}, {"height", h}, {"frames", frames}}},
            {"nodes", nodes},
            {"outputs", outputs}};
}

class Taa : public GpuTest {};

// Reinhard on the largest channel and its inverse, written out here: t = c s / (1 + max(c s)), c = t / (1 - max t) / s.
glm::dvec3 tonemapped(glm::dvec3 c, double scale) {
    c = glm::max(c, glm::dvec3(0.0)) * scale;
    return c / (1.0 + std::max({c.x, c.y, c.z}));
}
glm::dvec3 rgb(const Image& img, int x, int y) {
    return {img.at(x, y)[0], img.at(x, y)[1], img.at(x, y)[2]};
}

// A pixel alternating between 0.1 and 100 (a warm colour, so the curve's largest channel matters): with the
// running mean (feedback 1) the output is the mean in the tone-mapped space, not the linear mean (~50).
TEST_F(Taa, ToneMappedBlendConvergesToTheToneMappedMean) {
    const glm::dvec3 a(0.1, 0.06, 0.02), b(100.0, 40.0, 10.0);
    for (double exposure : {0.0, -3.0}) {
        const int frames = 16;
        auto out = runGraph(
            graph({{"src", {{"type", "test.sequence"}, {"params", {{"a", {a.x, a.y, a.z}}, {"b", {b.x, b.y, b.z}}}}}},
                   {"taa",
                    {{"type", "aa.taa"},
                     {"params", {{"clamp", "none"}, {"feedback", 1.0}, {"exposure", exposure}}},
                     {"in", {{"color", "src.color"}, {"history", "taa.color@prev"}}}}}},
                  {{"out", "taa.color"}, {"weight", "taa.weight"}}, 16, 16, frames));
        const double s = std::exp2(exposure);
        const glm::dvec3 expected = 0.5 * (tonemapped(a, s) + tonemapped(b, s));
        double worst = 0.0;
        const Image& img = out.at("out");
        for (int y = 0; y < img.height; ++y)
            for (int x = 0; x < img.width; ++x) {
                const glm::dvec3 d = glm::abs(tonemapped(rgb(img, x, y), s) - expected);
                worst = std::max({worst, d.x, d.y, d.z});
                EXPECT_EQ(img.at(x, y)[3], static_cast<float>(frames)); // the sample count
            }
        const double linear = img.at(3, 3)[0];
        std::printf("exposure %.0f: output red %.4f (linear mean 50.05), tone-mapped %.5f, expected %.5f, worst %.2e\n",
                    exposure, linear, tonemapped(rgb(img, 3, 3), s).x, expected.x, worst);
        EXPECT_LT(worst, 1e-3);
        EXPECT_LT(linear, 25.0); // nowhere near the linear mean
        EXPECT_NEAR(out.at("weight").at(5, 5)[0], (frames - 1.0) / frames, 1e-3);
    }
}

glm::dvec3 toYCoCg(glm::dvec3 c) {
    return {0.25 * c.r + 0.5 * c.g + 0.25 * c.b, 0.5 * c.r - 0.5 * c.b, -0.25 * c.r + 0.5 * c.g - 0.25 * c.b};
}
glm::dvec3 fromYCoCg(glm::dvec3 y) {
    return {y.x + y.y - y.z, y.x + y.z, y.x - y.y - y.z};
}

// Frame 0 is a uniform colour, frame 1 a checkerboard of two others: the second frame's output is the history
// (frame 0) rectified against the checkerboard's 3x3 neighbourhood in YCoCg and blended half and half with the current
// pixel, all in the tone-mapped space; recomputed here for every clamp mode and with sharpening.
TEST_F(Taa, HistoryRectificationMatchesCpu) {
    const glm::dvec3 a(8.0, 0.3, 0.1), b(0.2, 0.5, 0.9), c(3.0, 2.0, 0.4);
    struct Case {
        std::string clamp;
        double gamma, sharpen;
    };
    for (const Case& k : {Case{"none", 1.0, 0.0}, Case{"minmax", 1.0, 0.0}, Case{"variance", 1.0, 0.0},
                          Case{"variance", 0.5, 0.0}, Case{"none", 1.0, 0.6}}) {
        auto out = runGraph(
            graph({{"src",
                    {{"type", "test.sequence"},
                     {"params",
                      {{"a", {a.x, a.y, a.z}}, {"b", {b.x, b.y, b.z}}, {"c", {c.x, c.y, c.z}}, {"alternate", false}}}}},
                   {"taa",
                    {{"type", "aa.taa"},
                     {"params", {{"clamp", k.clamp}, {"gamma", k.gamma}, {"sharpen", k.sharpen}, {"exposure", -1.0}}},
                     {"in", {{"color", "src.color"}, {"history", "taa.color@prev"}}}}}},
                  {{"out", "taa.color"}}, 12, 12, 2));
        const double s = 0.5;
        double worst = 0.0, moved = 0.0;
        for (int y = 1; y < 11; ++y)
            for (int x = 1; x < 11; ++x) {
                glm::dvec3 m1(0.0), m2(0.0), lo(1e30), hi(-1e30), cross(0.0), centre(0.0);
                for (int dy = -1; dy <= 1; ++dy)
                    for (int dx = -1; dx <= 1; ++dx) {
                        const glm::dvec3 t = tonemapped((x + dx + y + dy) % 2 == 0 ? b : c, s);
                        if (dx == 0 && dy == 0)
                            centre = t;
                        else if (dx == 0 || dy == 0)
                            cross += t;
                        const glm::dvec3 yc = toYCoCg(t);
                        m1 += yc;
                        m2 += yc * yc;
                        lo = glm::min(lo, yc);
                        hi = glm::max(hi, yc);
                    }
                glm::dvec3 current = centre;
                if (k.sharpen > 0.0) current = glm::clamp(centre + k.sharpen * (centre - 0.25 * cross), 0.0, 0.9999);
                glm::dvec3 h = toYCoCg(tonemapped(a, s));
                if (k.clamp == "minmax") h = glm::clamp(h, lo, hi);
                if (k.clamp == "variance") {
                    const glm::dvec3 mean = m1 / 9.0, sigma = glm::sqrt(glm::max(m2 / 9.0 - mean * mean, 0.0));
                    const glm::dvec3 boxLo = glm::max(mean - k.gamma * sigma, lo),
                                     boxHi = glm::min(mean + k.gamma * sigma, hi);
                    const glm::dvec3 mid = 0.5 * (boxLo + boxHi), half = 0.5 * (boxHi - boxLo) + 1e-6;
                    const glm::dvec3 units = glm::abs((h - mid) / half);
                    const double most = std::max({units.x, units.y, units.z});
                    if (most > 1.0) h = mid + (h - mid) / most;
                }
                const glm::dvec3 history = glm::clamp(fromYCoCg(h), 0.0, 0.9999);
                const glm::dvec3 expected = 0.5 * (current + history);
                const glm::dvec3 got = tonemapped(rgb(out.at("out"), x, y), s);
                const glm::dvec3 d = glm::abs(got - expected);
                worst = std::max({worst, d.x, d.y, d.z});
                moved = std::max(moved, glm::length(history - tonemapped(a, s)));
            }
        std::printf("clamp %s, gamma %.1f, sharpen %.1f: worst tone-mapped error %.2e (history moved by up to %.3f)\n",
                    k.clamp.c_str(), k.gamma, k.sharpen, worst, moved);
        EXPECT_LT(worst, 2e-5) << k.clamp << " " << k.gamma << " " << k.sharpen;
        if (k.clamp != "none") {
            EXPECT_GT(moved, 0.05) << k.clamp; // the rectification did something
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Scenes

struct Builder {
    sc::Scene s;
    explicit Builder(const std::string& name) { s.name = name; }

    uint32_t texture(uint32_t size, uint32_t seed) {
        sc::TextureImage img;
        img.name = "noise";
        img.width = img.height = size;
        img.pixels.resize(size * size * 4);
        uint32_t state = seed;
        for (uint32_t y = 0; y < size; ++y)
            for (uint32_t x = 0; x < size; ++x) {
                state = state * 1664525u + 1013904223u;
                const uint8_t v = static_cast<uint8_t>(40 + (state >> 24) % 180);
                img.at(x, y)[0] = v;
                img.at(x, y)[1] = static_cast<uint8_t>(255 - v);
                img.at(x, y)[2] = 128;
                img.at(x, y)[3] = 255;
            }
        s.images.push_back(std::move(img));
        sc::Texture t;
        t.name = "noise";
        t.image = static_cast<uint32_t>(s.images.size() - 1);
        t.usage = sc::TextureUsage::Color;
        s.textures.push_back(t);
        return static_cast<uint32_t>(s.textures.size() - 1);
    }

    uint32_t material(glm::vec3 albedo, int32_t texture = -1) {
        sc::Material m;
        m.name = "m" + std::to_string(s.materials.size());
        sc::MaterialLayer l;
        l.albedo.factor = glm::vec4(albedo, 1.0f);
        l.albedo.texture.texture = texture;
        l.shininess = {0.3f, 0.0f};
        m.layers = {l};
        s.materials.push_back(m);
        return static_cast<uint32_t>(s.materials.size() - 1);
    }

    // A square of half-size `half` in the XY plane facing +Z.
    uint32_t quad(float half, uint32_t material) {
        std::vector<sc::Vertex> v(4);
        const glm::vec2 corners[4] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
        for (int i = 0; i < 4; ++i) {
            v[i].position = glm::vec3(corners[i] * half, 0.0f);
            v[i].normal = {0, 0, 1};
            v[i].tangent = {1, 0, 0, 1};
            v[i].uv0 = corners[i] * 0.5f + 0.5f;
            v[i].color = glm::vec4(1.0f);
        }
        sc::Primitive p;
        p.firstIndex = static_cast<uint32_t>(s.indices.size());
        p.indexCount = 6;
        p.vertexOffset = static_cast<uint32_t>(s.vertices.size());
        p.vertexCount = 4;
        p.material = material;
        s.vertices.insert(s.vertices.end(), v.begin(), v.end());
        for (uint32_t i : {0u, 1u, 2u, 0u, 2u, 3u})
            s.indices.push_back(i);
        s.primitives.push_back(p);
        sc::Mesh m;
        m.name = "quad" + std::to_string(s.meshes.size());
        m.firstPrimitive = static_cast<uint32_t>(s.primitives.size() - 1);
        m.primitiveCount = 1;
        s.meshes.push_back(m);
        return static_cast<uint32_t>(s.meshes.size() - 1);
    }

    uint32_t node(uint32_t mesh, glm::vec3 t) {
        sc::Node n;
        n.name = "n" + std::to_string(s.nodes.size());
        n.mesh = static_cast<int32_t>(mesh);
        n.local.translation = t;
        s.nodes.push_back(n);
        return static_cast<uint32_t>(s.nodes.size() - 1);
    }

    void cameraPath(std::vector<sc::CameraKey> keys) {
        sc::Camera lens;
        lens.name = "cam";
        lens.yfov = 0.8f;
        lens.znear = 0.05f;
        lens.zfar = 0.0f;
        s.cameras.push_back(lens);
        sc::CameraPath path;
        path.name = "cam";
        path.camera = 0;
        path.smooth = false;
        path.keys = std::move(keys);
        s.cameraPaths.push_back(path);
    }

    void slide(uint32_t node, glm::vec3 from, glm::vec3 to) {
        sc::Animation anim;
        anim.name = "slide";
        anim.samplers = {{sc::Interpolation::Linear, {0.0f, 1.0f}, {glm::vec4(from, 0.0f), glm::vec4(to, 0.0f)}}};
        anim.channels = {{node, sc::AnimationPath::Translation, 0}};
        s.animations.push_back(anim);
    }
};

// scene.gltf -> gbuffer.layered -> aa.taa over the G-buffer's base colour (the "lit" image of these tests).
json taaSceneGraph(const std::filesystem::path& glb, int w, int h, int frames, json taaParams, bool depth = true,
                   bool velocity = true) {
    json taaIn = {{"color", "gbuffer.base_color"}, {"history", "taa.color@prev"}};
    if (velocity) taaIn["velocity"] = "gbuffer.velocity";
    if (depth) {
        taaIn["depth"] = "gbuffer.normal";
        taaIn["history_depth"] = "gbuffer.normal@prev";
    }
    return graph({{"scene", {{"type", "scene.gltf"}, {"params", {{"path", glb.string()}, {"fps", 24.0}}}}},
                  {"gbuffer", {{"type", "gbuffer.layered"}, {"in", {{"scene", "scene.scene"}}}}},
                  {"taa", {{"type", "aa.taa"}, {"params", taaParams}, {"in", taaIn}}}},
                 {{"out", "taa.color"}, {"in", "gbuffer.base_color"}, {"weight", "taa.weight"}}, w, h, frames);
}

// RMSE over RGB of the pixels at least `margin` from the border (pixels that entered the view lately have no history).
double interiorRmse(const Image& a, const Image& b, int margin) {
    double sum = 0.0;
    int n = 0;
    for (int y = margin; y < a.height - margin; ++y)
        for (int x = margin; x < a.width - margin; ++x)
            for (int c = 0; c < 3; ++c) {
                const double d = a.at(x, y)[c] - b.at(x, y)[c];
                sum += d * d;
                ++n;
            }
    return std::sqrt(sum / n);
}

// A camera panning across a static textured wall (about 0.6 px per frame right and 0.3 down), no jitter: after
// 24 frames the TAA output must still be the current frame (no drift, and no more blur than the history filter
// adds), with the history accepted (depth says same surface) in the interior.
TEST_F(Taa, ReprojectionOfAPanKeepsTheImage) {
    Builder b("taa_pan");
    const uint32_t tex = b.texture(64, 7);
    b.node(b.quad(12.0f, b.material(glm::vec3(1.0f), static_cast<int32_t>(tex))), glm::vec3(0.0f, 0.0f, -5.0f));
    b.cameraPath({{0.0f, glm::vec3(0.0f), glm::quat(1, 0, 0, 0), 0.8f},
                  {1.0f, glm::vec3(1.0f, -0.5f, 0.0f), glm::quat(1, 0, 0, 0), 0.8f}});
    const auto glb = writeSceneGlb(b.s, "taa_pan");
    const int w = 96, h = 64, frames = 24;
    auto run = [&](json params, bool velocity = true) {
        params["clamp"] = "none";
        return runGraph(taaSceneGraph(glb, w, h, frames, params, true, velocity));
    };
    auto cr = run({{"history_filter", "catmull_rom"}});
    auto bilinear = run({{"history_filter", "bilinear"}});
    auto still = run({{"history_filter", "catmull_rom"}}, false);
    auto tooFast = run({{"max_velocity", 0.3}}); // the pan is faster: the history is skipped
    const double eCr = interiorRmse(cr.at("out"), cr.at("in"), 4);
    const double eBilinear = interiorRmse(bilinear.at("out"), bilinear.at("in"), 4);
    const double eStill = interiorRmse(still.at("out"), still.at("in"), 4);
    double weight = 0.0, skipped = 0.0;
    for (int y = 4; y < h - 4; ++y)
        for (int x = 4; x < w - 4; ++x) {
            weight += cr.at("weight").at(x, y)[0] / ((w - 8) * (h - 8));
            skipped += tooFast.at("weight").at(x, y)[0] / ((w - 8) * (h - 8));
        }
    std::printf(
        "pan: RMSE vs input: catmull-rom %.4f, bilinear %.4f, without velocity %.4f; mean history weight %.3f\n", eCr,
        eBilinear, eStill, weight);
    EXPECT_LT(eCr, 0.01);
    EXPECT_GT(eBilinear, 1.5 * eCr); // the filter matters, and the test sees it
    EXPECT_GT(eStill, 4.0 * eCr);    // without reprojection the image smears
    EXPECT_NEAR(weight, 0.9, 0.01);  // the history was accepted: feedback 0.9 reached everywhere inside
    EXPECT_EQ(skipped, 0.0);         // max_velocity below the pan's speed
}

// A bright square sliding over a dark wall at ~2.5 px per frame: where it was, the history holds it; the depth test
// and the clamp must drop it. Trail energy: the summed |output - input| over pixels the square no longer covers,
// relative to the square's own energy (its area x contrast), after 8 frames.
TEST_F(Taa, GhostingTrailOfAMovingObjectIsRejected) {
    Builder b("taa_ghost");
    b.node(b.quad(12.0f, b.material(glm::vec3(0.05f))), glm::vec3(0.0f, 0.0f, -5.0f));
    const uint32_t box = b.node(b.quad(0.5f, b.material(glm::vec3(1.0f))), glm::vec3(-1.0f, 0.0f, -4.0f));
    b.slide(box, glm::vec3(-1.5f, 0.0f, -4.0f), glm::vec3(3.5f, 0.0f, -4.0f));
    b.cameraPath({{0.0f, glm::vec3(0.0f), glm::quat(1, 0, 0, 0), 0.8f}});
    const auto glb = writeSceneGlb(b.s, "taa_ghost");
    const int w = 96, h = 64, frames = 9;
    auto trail = [&](json params, bool depth) {
        auto out = runGraph(taaSceneGraph(glb, w, h, frames, params, depth));
        const Image& o = out.at("out");
        const Image& in = out.at("in");
        double energy = 0.0, box = 0.0;
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                const bool covered = in.at(x, y)[0] > 0.5f;
                if (covered)
                    box += in.at(x, y)[0] - 0.05;
                else
                    energy += std::fabs(o.at(x, y)[0] - in.at(x, y)[0]);
            }
        return box > 0.0 ? energy / box : 1e9;
    };
    // The edges of the moving square keep their history (Karis: each pixel takes the velocity of the nearest surface
    // in its 3x3, so a pixel just outside the leading edge follows the square): share of the pixels next to the
    // square (not covered, a covered 4-neighbour) whose history was accepted.
    {
        auto out = runGraph(taaSceneGraph(glb, w, h, frames, json::object(), true));
        const Image& in = out.at("in");
        int rim = 0, kept = 0;
        for (int y = 1; y < h - 1; ++y)
            for (int x = 1; x < w - 1; ++x) {
                auto covered = [&](int i, int j) { return in.at(i, j)[0] > 0.5f; };
                if (covered(x, y) || !(covered(x - 1, y) || covered(x + 1, y) || covered(x, y - 1) || covered(x, y + 1)))
                    continue;
                ++rim;
                kept += out.at("weight").at(x, y)[0] > 0.0f;
            }
        std::printf("moving square: history kept at %d of %d pixels around it\n", kept, rim);
        EXPECT_GT(rim, 20);
        EXPECT_GT(kept, 0.9 * rim);
    }
    const double defaults = trail(json::object(), true);
    const double clampOnly = trail({{"clamp", "minmax"}}, false);
    const double depthOnly = trail({{"clamp", "none"}}, true);
    const double none = trail({{"clamp", "none"}}, false);
    std::printf("ghost trail energy / object energy: defaults %.4f, min/max clamp only %.4f, depth test only %.4f, "
                "neither %.4f\n",
                defaults, clampOnly, depthOnly, none);
    EXPECT_LT(defaults, 0.02);
    EXPECT_LT(clampOnly, 0.06);
    // The depth test alone accepts a pixel whose surface was within the 3x3 window last frame (the jitter moves edges
    // by up to a pixel), so a one-pixel rim of the old position survives it; the clamp removes that.
    EXPECT_LT(depthOnly, 0.5 * none);
    EXPECT_GT(none, 0.3); // without rejection there is a trail, so the test can see one
}

// The depth test on a camera that pans and dollies (0.5 m sideways, 0.1 m forward a frame) past a square 3 m away in
// front of a wall turned 45° about the vertical (receding to the right, 5.5-12 m away), no jitter: the square moves
// ~13 px a frame on screen, the wall ~4, so the wall is uncovered in a band beside the square each frame. Every pixel's
// surface is cast on the CPU in frame 2 and its point projected into frame 1's view:
//   - where frame 1 saw the same surface there (nothing else within 2 px, and the pixel's 3x3 holds one surface now)
//     the history must be kept (weight > 0), although the dolly moved it 0.1 m nearer (under 4 % of its depth, within
//     the 5 % tolerance, but twice 0.05 m: the test is relative);
//   - where the wall point lay 2 px or more inside the square's footprint in frame 1 and the pixel's 3x3 is all wall
//     (so it keeps the wall's velocity) it was disoccluded: rejected (weight 0);
//   - a wall pixel beside the square takes the square's velocity (the nearest surface in its 3x3): its history is
//     looked up where the square was, and is kept where the square is in that 3x3 window last frame, although the
//     wall there, ~9 px of a wall sloping ~1.3 % a pixel away from this pixel's point, is not its depth. At least 60 %
//     of them (measured 100 of 134; the others' window misses the square's old texels by its rasterised coverage;
//     comparing only the window's centre texel keeps 64, ignoring the nearest surface's depth keeps none).
// The TAA input is the G-buffer's base colour.
TEST_F(Taa, DepthTestKeepsTheSameSurfaceAndRejectsDisocclusion) {
    Builder b("taa_depth");
    const double turn = 0.25 * std::numbers::pi;
    const glm::dvec3 wallCentre(0.0, 0.0, -9.0), wallNormal(std::sin(turn), 0.0, std::cos(turn));
    const uint32_t wall = b.node(b.quad(12.0f, b.material(glm::vec3(0.2f))), glm::vec3(wallCentre));
    b.s.nodes[wall].local.rotation = glm::angleAxis(float(turn), glm::vec3(0.0f, 1.0f, 0.0f));
    b.node(b.quad(0.6f, b.material(glm::vec3(0.9f))), glm::vec3(0.8f, 0.0f, -3.0f));
    const glm::dvec3 step(0.5, 0.0, -0.1); // camera motion per frame (24 fps)
    b.cameraPath({{0.0f, glm::vec3(0.0f), glm::quat(1, 0, 0, 0), 0.8f},
                  {1.0f, glm::vec3(24.0 * step), glm::quat(1, 0, 0, 0), 0.8f}});
    const auto glb = writeSceneGlb(b.s, "taa_depth");
    const int w = 96, h = 64, frames = 3;
    auto out = runGraph(taaSceneGraph(glb, w, h, frames, {{"clamp", "none"}}, true));
    const Image& weight = out.at("weight");

    const double tanHalf = std::tan(0.4), aspect = double(w) / h;
    const glm::dvec3 now = step * double(frames - 1), before = step * double(frames - 2);
    enum Surface { Wall, Square, None };
    auto trace = [&](glm::dvec3 eye, glm::dvec2 px, glm::dvec3* point = nullptr) {
        const glm::dvec2 ndc = px / glm::dvec2(w, h) * 2.0 - 1.0;
        const glm::dvec3 d(ndc.x * aspect * tanHalf, -ndc.y * tanHalf, -1.0);
        glm::dvec3 p = eye + d * (eye.z + 3.0);
        if (std::abs(p.x - 0.8) <= 0.6 && std::abs(p.y) <= 0.6) {
            if (point) *point = p;
            return Square;
        }
        p = eye + d * (glm::dot(wallCentre - eye, wallNormal) / glm::dot(d, wallNormal));
        if (point) *point = p;
        const glm::dvec3 along(std::cos(turn), 0.0, -std::sin(turn));
        return std::abs(glm::dot(p - wallCentre, along)) <= 12.0 && std::abs(p.y) <= 12.0 ? Wall : None;
    };
    auto project = [&](glm::dvec3 eye, glm::dvec3 p) {
        const glm::dvec3 c = p - eye;
        return glm::dvec2((c.x / -c.z / (tanHalf * aspect) * 0.5 + 0.5) * w, (-c.y / -c.z / tanHalf * 0.5 + 0.5) * h);
    };
    auto inside = [&](glm::dvec2 q) { return q.x >= 3.0 && q.y >= 3.0 && q.x <= w - 3.0 && q.y <= h - 3.0; };
    int same[2] = {0, 0}, kept[2] = {0, 0}, disoccluded = 0, rejected = 0, rim = 0, rimKept = 0;
    for (int y = 2; y < h - 2; ++y)
        for (int x = 2; x < w - 2; ++x) {
            glm::dvec3 X;
            const Surface s = trace(now, {x + 0.5, y + 0.5}, &X);
            if (s == None) continue;
            bool uniform = true;
            glm::dvec2 squareBefore(-1.0); // where a square pixel of the 3x3 was in frame 1
            for (int dy = -1; dy <= 1; ++dy)
                for (int dx = -1; dx <= 1; ++dx) {
                    glm::dvec3 Y;
                    const Surface t = trace(now, {x + dx + 0.5, y + dy + 0.5}, &Y);
                    uniform = uniform && t == s;
                    if (t == Square) squareBefore = project(before, Y);
                }
            const glm::dvec2 q = project(before, X);
            const bool accepted = weight.at(x, y)[0] > 0.0f;
            if (s == Wall && !uniform) {
                if (!inside(squareBefore)) continue;
                ++rim;
                rimKept += accepted;
                continue;
            }
            if (!inside(q)) continue;
            int sameBefore = 0, squareThere = 0;
            for (int dy = -2; dy <= 2; ++dy)
                for (int dx = -2; dx <= 2; ++dx) {
                    const Surface t = trace(before, q + glm::dvec2(dx, dy));
                    sameBefore += t == s;
                    squareThere += t == Square;
                }
            if (uniform && sameBefore == 25) {
                ++same[s];
                kept[s] += accepted;
            } else if (uniform && s == Wall && squareThere == 25) {
                ++disoccluded;
                rejected += !accepted;
            }
        }
    std::printf("depth test: history kept at %d of %d wall and %d of %d square pixels that saw the same surface last "
                "frame and at %d of %d wall pixels beside the square; rejected at %d of %d disoccluded wall pixels\n",
                kept[Wall], same[Wall], kept[Square], same[Square], rimKept, rim, rejected, disoccluded);
    EXPECT_GT(same[Wall], 2000);
    EXPECT_GT(same[Square], 300);
    EXPECT_GT(disoccluded, 60);
    EXPECT_GT(rim, 60);
    EXPECT_GE(kept[Wall], same[Wall] - same[Wall] / 100);
    EXPECT_GE(kept[Square], same[Square] - same[Square] / 100);
    EXPECT_GE(rimKept, 0.6 * rim);
    EXPECT_EQ(rejected, disoccluded);
}

// ---------------------------------------------------------------------------------------------
// Per-vertex jitter

class VertexJitter : public GpuTest {};

// How much of the camera's jitter moved what a set of pixels shows: reverse-Z hardware depth is affine in screen
// space on a plane, so a shift d of the image gives z'(p) = z(p - d) = z(p) - grad z . d. Only the component along
// the (constant) gradient is measurable, so the result is the least-squares ratio r of z' - z = -r grad z . jitter
// over the pixels whose 5x5 neighbourhood is covered in both images (gradient by central differences): 1 when the
// pixels moved by the jitter, 0 when they did not.
double jitterRatio(const Image& plain, const Image& jittered, glm::dvec2 jitter, bool rightHalf) {
    double num = 0.0, den = 0.0;
    int used = 0;
    for (int y = 2; y < plain.height - 2; ++y)
        for (int x = 2; x < plain.width - 2; ++x) {
            if ((x >= plain.width / 2) != rightHalf) continue;
            bool covered = true;
            for (int dy = -2; dy <= 2 && covered; ++dy)
                for (int dx = -2; dx <= 2 && covered; ++dx)
                    covered = plain.at(x + dx, y + dy)[0] > 0.0f && jittered.at(x + dx, y + dy)[0] > 0.0f;
            if (!covered) continue;
            const glm::dvec2 g(0.5 * (plain.at(x + 1, y)[0] - plain.at(x - 1, y)[0]),
                               0.5 * (plain.at(x, y + 1)[0] - plain.at(x, y - 1)[0]));
            const double predicted = -glm::dot(g, jitter);
            num += predicted * (static_cast<double>(jittered.at(x, y)[0]) - plain.at(x, y)[0]);
            den += predicted * predicted;
            ++used;
        }
    EXPECT_GT(used, 100) << (rightHalf ? "right" : "left");
    return num / den;
}

// A static tilted square on the left, one sliding down at ~4 px per frame on the right (threshold 2 px per frame):
// per-vertex jitter moves the static one by the camera's jitter and the fast one not at all; frustum jitter moves
// both.
TEST_F(VertexJitter, StaticVerticesMoveByTheJitterFastOnesDoNot) {
    Builder b("vertex_jitter");
    const glm::quat tilt = glm::angleAxis(0.5f, glm::vec3(0, 1, 0)) * glm::angleAxis(0.35f, glm::vec3(1, 0, 0));
    const uint32_t material = b.material(glm::vec3(0.5f));
    const uint32_t still = b.node(b.quad(0.8f, material), glm::vec3(-1.1f, 0.0f, -5.0f));
    const uint32_t moving = b.node(b.quad(0.8f, material), glm::vec3(1.1f, 0.0f, -5.0f));
    b.s.nodes[still].local.rotation = tilt;
    b.s.nodes[moving].local.rotation = tilt;
    b.slide(moving, glm::vec3(1.1f, 6.0f, -5.0f), glm::vec3(1.1f, -6.0f, -5.0f));
    b.cameraPath({{0.0f, glm::vec3(0.0f), glm::quat(1, 0, 0, 0), 0.8f}});
    const auto glb = writeSceneGlb(b.s, "vertex_jitter");
    const int w = 96, h = 64, frames = 3;
    const double start = 0.5 - 1.0 / 24.0; // the moving square is centred on the last frame
    auto depth = [&](const std::string& jitter, const std::string& space, double threshold = 2.0) {
        json g = graph({{"scene",
                         {{"type", "scene.gltf"},
                          {"params",
                           {{"path", glb.string()},
                            {"fps", 24.0},
                            {"start", start - 1.0 / 24.0},
                            {"jitter", jitter},
                            {"jitter_space", space},
                            {"vertex_jitter_threshold", threshold}}}}},
                        {"gbuffer", {{"type", "gbuffer.layered"}, {"in", {{"scene", "scene.scene"}}}}}},
                       {{"depth", "gbuffer.depth"}, {"velocity", "gbuffer.velocity"}}, w, h, frames);
        return runGraph(g);
    };
    auto plain = depth("off", "vertex");
    auto vertex = depth("ordered", "vertex");
    auto frustum = depth("ordered", "frustum");
    auto slow = depth("ordered", "vertex", 20.0); // the square moves at less than half of this threshold
    const glm::dvec2 jitter(sc::jitterOffset(sc::JitterPattern::Ordered, frames - 1));
    double speed = 0.0, meanSpeed = 0.0;
    int covered = 0;
    for (int y = 0; y < h; ++y)
        for (int x = w / 2; x < w; ++x) {
            if (plain.at("depth").at(x, y)[0] <= 0.0f) continue;
            const double v =
                glm::length(glm::dvec2(plain.at("velocity").at(x, y)[0], plain.at("velocity").at(x, y)[1]));
            speed = std::max(speed, v);
            meanSpeed += v;
            ++covered;
        }
    meanSpeed /= std::max(covered, 1);
    const double vStill = jitterRatio(plain.at("depth"), vertex.at("depth"), jitter, false);
    const double vMoving = jitterRatio(plain.at("depth"), vertex.at("depth"), jitter, true);
    const double fStill = jitterRatio(plain.at("depth"), frustum.at("depth"), jitter, false);
    const double fMoving = jitterRatio(plain.at("depth"), frustum.at("depth"), jitter, true);
    const double sMoving = jitterRatio(plain.at("depth"), slow.at("depth"), jitter, true);
    std::printf(
        "jitter (%.4f, %.4f); moving square %.2f px/frame; share of the jitter applied: per-vertex still %.4f, "
        "moving %.4f; frustum still %.4f, moving %.4f; threshold 20: moving %.4f (1 - mean speed / 20 = %.4f)\n",
        jitter.x, jitter.y, speed, vStill, vMoving, fStill, fMoving, sMoving, 1.0 - meanSpeed / 20.0);
    ASSERT_GT(glm::length(jitter), 0.1);
    EXPECT_GT(speed, 3.0); // well above the threshold
    EXPECT_NEAR(vStill, 1.0, 0.02);
    EXPECT_NEAR(vMoving, 0.0, 0.02);
    EXPECT_NEAR(fStill, 1.0, 0.02);
    EXPECT_NEAR(fMoving, 1.0, 0.02);
    // Below the threshold the jitter falls off linearly with the speed (which varies a little over the square).
    EXPECT_NEAR(sMoving, 1.0 - meanSpeed / 20.0, 0.05);
}

// ---------------------------------------------------------------------------------------------
// aa.accumulate

class Accumulate : public GpuTest {};

// 16 frames of a zone plate jittered over the 4 x 4 stratified cell centres, averaged by aa.accumulate, against
// pattern.zoneplate's own 4 x 4 supersampling: the same sample positions, summed in another order.
TEST_F(Accumulate, ZonePlateEqualsItsOwnSupersampling) {
    const int n = 4, frames = 20; // frames past N^2 keep the mean
    auto out = runGraph(
        graph({{"jittered",
                {{"type", "pattern.zoneplate"},
                 {"params", {{"max_frequency", 0.8}, {"jitter", "stratified"}, {"jitter_grid", n}}}}},
               {"acc",
                {{"type", "aa.accumulate"},
                 {"params", {{"grid", n}}},
                 {"in", {{"color", "jittered.color"}, {"history", "acc.color@prev"}}}}},
               {"reference", {{"type", "pattern.zoneplate"}, {"params", {{"max_frequency", 0.8}, {"supersample", n}}}}},
               {"single", {{"type", "pattern.zoneplate"}, {"params", {{"max_frequency", 0.8}}}}}},
              {{"acc", "acc.color"}, {"reference", "reference.color"}, {"single", "single.color"}}, 80, 48, frames));
    const double err = maxAbsDiff(out.at("acc"), out.at("reference"));
    const double aliased = rmse(out.at("single"), out.at("reference"));
    std::printf("accumulated vs supersampled: max |diff| %.2e (one sample per pixel: RMSE %.3f)\n", err, aliased);
    EXPECT_LT(err, 1e-5);
    EXPECT_GT(aliased, 0.1);
}

TEST_F(Accumulate, RefusesTooFewFrames) {
    json g = graph({{"p", {{"type", "pattern.zoneplate"}, {"params", {{"jitter", "stratified"}, {"jitter_grid", 4}}}}},
                    {"acc",
                     {{"type", "aa.accumulate"},
                      {"params", {{"grid", 4}}},
                      {"in", {{"color", "p.color"}, {"history", "acc.color@prev"}}}}}},
                   {{"acc", "acc.color"}}, 16, 16, 8);
    try {
        runGraph(g);
        FAIL() << "expected a UserError";
    } catch (const UserError& e) {
        EXPECT_NE(std::string(e.what()).find("/nodes/acc/params/grid"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find("16 frames"), std::string::npos) << e.what();
    }
}

TEST_F(Accumulate, RefusesACameraWithAnotherJitter) {
    Builder b("accumulate_camera");
    b.node(b.quad(2.0f, b.material(glm::vec3(0.5f))), glm::vec3(0.0f, 0.0f, -5.0f));
    b.cameraPath({{0.0f, glm::vec3(0.0f), glm::quat(1, 0, 0, 0), 0.8f}});
    const auto glb = writeSceneGlb(b.s, "accumulate_camera");
    for (const char* jitter : {"halton", "stratified"}) {
        json g = graph(
            {{"scene",
              {{"type", "scene.gltf"}, {"params", {{"path", glb.string()}, {"jitter", jitter}, {"jitter_grid", 3}}}}},
             {"gbuffer", {{"type", "gbuffer.layered"}, {"in", {{"scene", "scene.scene"}}}}},
             {"acc",
              {{"type", "aa.accumulate"},
               {"params", {{"grid", 4}}},
               {"in", {{"color", "gbuffer.base_color"}, {"history", "acc.color@prev"}, {"camera", "scene.camera"}}}}}},
            {{"acc", "acc.color"}}, 16, 16, 16);
        try {
            runGraph(g);
            FAIL() << jitter << ": expected a UserError";
        } catch (const UserError& e) {
            EXPECT_NE(std::string(e.what()).find("/nodes/acc/params/grid"), std::string::npos) << e.what();
            EXPECT_NE(std::string(e.what()).find("jitter_grid to 4"), std::string::npos) << e.what();
        }
    }
}

} // namespace
} // namespace vitrine::test
