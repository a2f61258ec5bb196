// The SSR chain against independent references: depth.hiz's min/max pyramid against a CPU reduction of every
// level's level-0 footprint (odd sizes included); color.pyramid's means likewise; ssr.hiz on a mirror floor
// against the analytic mirror image (a colour image that holds each pixel's own coordinates makes the reflected
// texel readable), its confidence against the same factors evaluated at the analytic hit, the back-face test on a
// plate seen from below, the tap limit; ssr.composite against the CPU blend with Karis' environment BRDF, and its
// weight at grazing views with ibl.capture's LUT against the lobe's directional albedo integrated here; the cone
// footprint's pyramid level (test.ssr_levels: each level holds its own index) against the lobe's footprint at each
// hit, the roughness cut-off's fade against the same rays without it, hits on a true mirror against the analytic
// mirror image to a fraction of a pixel (the refinement), and the thickness fade of rays found inside a slab whose
// depth gap is computed here (issue 26).
#include "tests/gpu/lighting_scene.hpp"

#include "core/compare/metrics.hpp"
#include "core/graph/node.hpp"
#include "core/graph/registry.hpp"
#include "core/shading/brdf.hpp"
#include "core/shading/octahedral.hpp"
#include "nodes/depth/mip_atlas.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>

namespace vitrine::test {
namespace {

using nlohmann::json;
using namespace lighting;

// --- Test-only source images --------------------------------------------------------------------------------

const char* kNoiseSource = R"(#version 460
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0) writeonly uniform image2D out_result;
uint hash(uint v) { v ^= v >> 16; v *= 0x7feb352du; v ^= v >> 15; v *= 0x846ca68bu; v ^= v >> 16; return v; }
void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(p, imageSize(out_result)))) return;
    uint h = hash(uint(p.x) * 7919u + uint(p.y) * 104729u + 17u);
    vec4 v = vec4(h & 1023u, (h >> 10) & 1023u, (h >> 20) & 1023u, 1023.0) / 1023.0;
    imageStore(out_result, p, v);
}
)";

// Each pixel's own centre in pixels: a reflection of it reads where the ray landed.
const char* kCoordsSource = R"(#version 460
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0) writeonly uniform image2D out_result;
void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(p, imageSize(out_result)))) return;
    imageStore(out_result, p, vec4(vec2(p) + 0.5, 0.0, 1.0));
}
)";

// A one-pixel checkerboard in r (every level of a pyramid above 0 averages it to exactly 0.5), coordinates in g, b.
const char* kCheckerSource = R"(#version 460
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0) writeonly uniform image2D out_result;
void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(p, imageSize(out_result)))) return;
    imageStore(out_result, p, vec4(float((p.x + p.y) & 1), vec2(p) + 0.5, 1.0));
}
)";

// One colour everywhere (every pyramid level the same): whatever a ray hits, it reads kUniformColour.
const char* kUniformSource = R"(#version 460
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0) writeonly uniform image2D out_result;
void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(p, imageSize(out_result)))) return;
    imageStore(out_result, p, vec4(400.0, 800.0, 1600.0, 1.0));
}
)";
constexpr glm::dvec3 kUniformColour(400.0, 800.0, 1600.0); // as bright as the floor's environment term

class FrameSource final : public Node {
public:
    FrameSource(const char* name, const char* source) : mName(name), mSource(source) {}
    void setup(SetupContext& ctx) override { mPipeline = ctx.computePipelineSource(mName, mSource); }
    void execute(ExecuteContext& ctx) override {
        const ImageDesc& out = ctx.output("result").desc();
        ctx.dispatch(mPipeline, nullptr, 0, out.width, out.height);
    }

private:
    const char* mName;
    const char* mSource;
    PipelineId mPipeline = 0;
};

NodeSchema frameSourceSchema(const char* type) {
    NodeSchema s;
    s.type = type;
    s.doc = "test-only node of test_gpu";
    OutputPort out;
    out.name = "result";
    out.format = VK_FORMAT_R32G32B32A32_SFLOAT;
    out.size = SizeRule::frame();
    out.doc = "test output";
    s.outputs = {out};
    return s;
}

const NodeRegistration kNoise(frameSourceSchema("test.ssr_noise"),
                              [] { return std::make_unique<FrameSource>("test/ssr_noise", kNoiseSource); });
const NodeRegistration kChecker(frameSourceSchema("test.ssr_checker"),
                                [] { return std::make_unique<FrameSource>("test/ssr_checker", kCheckerSource); });
const NodeRegistration kUniform(frameSourceSchema("test.ssr_uniform"),
                                [] { return std::make_unique<FrameSource>("test/ssr_uniform", kUniformSource); });
const NodeRegistration kCoords(frameSourceSchema("test.ssr_coords"),
                               [] { return std::make_unique<FrameSource>("test/ssr_coords", kCoordsSource); });

// test.ssr_normals: gbuffer.normal with the normal of every pixel whose view depth lies in [near, far] replaced by
// `normal` (octahedral): a surface that faces wherever a test needs it to, whatever its geometry.
const char* kNormalsSource = R"(#version 460
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0) uniform sampler2D in_normal;
layout(binding = 1) writeonly uniform image2D out_result;
layout(push_constant) uniform Push { vec4 p; } push; // near, far, octahedral normal
void main() {
    ivec2 q = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(q, imageSize(out_result)))) return;
    vec4 g = texelFetch(in_normal, q, 0);
    if (g.z >= push.p.x && g.z <= push.p.y) g.xy = push.p.zw;
    imageStore(out_result, q, g);
}
)";

class OverrideNormals final : public Node {
public:
    void setup(SetupContext& ctx) override { mPipeline = ctx.computePipelineSource("test/ssr_normals", kNormalsSource); }
    void execute(ExecuteContext& ctx) override {
        const Params& p = ctx.params();
        const glm::vec2 oct = shading::octEncode(glm::normalize(p.getVec3("normal")));
        const glm::vec4 push(p.getFloat("near"), p.getFloat("far"), oct.x, oct.y);
        const ImageDesc& out = ctx.output("result").desc();
        ctx.dispatch(mPipeline, push, out.width, out.height);
    }

private:
    PipelineId mPipeline = 0;
};

NodeSchema overrideNormalsSchema() {
    NodeSchema s;
    s.type = "test.ssr_normals";
    s.doc = "test-only node of test_gpu";
    s.inputs = {{"normal", PortKind::Texture, {}, false, Usage::Sampled, "gbuffer.normal"}};
    OutputPort out;
    out.name = "result";
    out.format = VK_FORMAT_R32G32B32A32_SFLOAT;
    out.size = SizeRule::ofInput("normal");
    out.doc = "test output";
    s.outputs = {out};
    s.params = {{"near", ParamType::Float, 0.0, {}, {}, {}, "view depth range whose normals are replaced"},
                {"far", ParamType::Float, 0.0, {}, {}, {}, "view depth range whose normals are replaced"},
                {"normal", ParamType::Vec3, json::array({0.0, 0.0, 1.0}), {}, {}, {}, "the normal they get"}};
    return s;
}
const NodeRegistration kNormals(overrideNormalsSchema(), [] { return std::make_unique<OverrideNormals>(); });

// test.ssr_levels: a colour pyramid (the mip atlas color.pyramid writes, sized like it) whose every texel of level k
// holds (k, its centre in level-0 pixels): ssr.hiz's trilinear read at lod L returns L in r (between levels k and
// k + 1 with weight L - k) and the level-0 position it read in g, b.
const char* kLevelsSource = R"(#version 460
#extension GL_GOOGLE_include_directive : require
#include "common/mip_atlas.glsl"
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0) writeonly uniform image2D out_result;
layout(push_constant) uniform Push { ivec2 size0; int levels; } pc;
void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(p, imageSize(out_result)))) return;
    vec4 v = vec4(-1.0);
    for (int k = 0; k < pc.levels; ++k) {
        ivec2 c = p - mipOffset(pc.size0, k);
        if (all(greaterThanEqual(c, ivec2(0))) && all(lessThan(c, mipSize(pc.size0, k)))) {
            v = vec4(float(k), (vec2(c) + 0.5) * float(1 << k), 1.0);
            break;
        }
    }
    imageStore(out_result, p, v);
}
)";

class LevelsSource final : public Node {
public:
    void setup(SetupContext& ctx) override {
        mWidth = ctx.frame().width;
        mHeight = ctx.frame().height;
        sizeMipAtlas(ctx.output("result"), mWidth, mHeight);
        mPipeline = ctx.computePipelineSource("test/ssr_levels", kLevelsSource);
    }
    void execute(ExecuteContext& ctx) override {
        struct {
            glm::ivec2 size0;
            int32_t levels;
        } push{{static_cast<int>(mWidth), static_cast<int>(mHeight)},
               static_cast<int32_t>(mipAtlasLevels(mWidth, mHeight))};
        const ImageDesc& out = ctx.output("result").desc();
        ctx.dispatch(mPipeline, &push, sizeof(push), out.width, out.height);
    }

private:
    uint32_t mWidth = 0, mHeight = 0;
    PipelineId mPipeline = 0;
};
const NodeRegistration kLevels(frameSourceSchema("test.ssr_levels"), [] { return std::make_unique<LevelsSource>(); });

// --- CPU mip atlas (written from the layout's description, not from the shader) --------------------------------

struct Level {
    int x0, y0, w, h; // position in the atlas and size
};

std::vector<Level> atlasLevels(int w, int h) {
    std::vector<Level> levels{{0, 0, w, h}};
    int x = 0;
    while (levels.back().w > 1 || levels.back().h > 1) {
        int lw = std::max(levels.back().w / 2, 1), lh = std::max(levels.back().h / 2, 1);
        levels.push_back({x, h, lw, lh});
        x += lw;
    }
    return levels;
}

// Level-0 pixels [lo, hi) of texel c of level k: 2^k wide, the last one reaching the image's edge.
void footprint(int size0, int k, int c, int levelSize, int& lo, int& hi) {
    lo = c << k;
    hi = c == levelSize - 1 ? size0 : (c + 1) << k;
}

class Ssr : public GpuTest {};

TEST_F(Ssr, HizTexelsAreTheMinAndMaxOfTheirFootprint) {
    for (auto [w, h] : {std::pair{37, 23}, std::pair{64, 32}, std::pair{5, 19}, std::pair{1, 1}}) {
        json nodes = {{"noise", {{"type", "test.ssr_noise"}}},
                      {"hiz", {{"type", "depth.hiz"}, {"in", {{"depth", "noise.result"}}}}}};
        auto out = runGraph(graph(nodes, {{"depth", "noise.result"}, {"hiz", "hiz.hiz"}}, w, h));
        const Image& depth = out.at("depth");
        const Image& hiz = out.at("hiz");
        auto levels = atlasLevels(w, h);
        int atlasW = w, rowW = 0;
        for (size_t k = 1; k < levels.size(); ++k) rowW += levels[k].w;
        atlasW = std::max(atlasW, rowW);
        ASSERT_EQ(hiz.width, atlasW) << w << "x" << h;
        ASSERT_EQ(hiz.height, h + (levels.size() > 1 ? levels[1].h : 0)) << w << "x" << h;
        int wrong = 0, texels = 0;
        for (size_t k = 0; k < levels.size(); ++k) {
            const Level& l = levels[k];
            for (int y = 0; y < l.h; ++y)
                for (int x = 0; x < l.w; ++x) {
                    int x0, x1, y0, y1;
                    footprint(w, static_cast<int>(k), x, l.w, x0, x1);
                    footprint(h, static_cast<int>(k), y, l.h, y0, y1);
                    float mn = std::numeric_limits<float>::infinity(), mx = -mn;
                    for (int yy = y0; yy < y1; ++yy)
                        for (int xx = x0; xx < x1; ++xx) {
                            mn = std::min(mn, depth.at(xx, yy)[0]);
                            mx = std::max(mx, depth.at(xx, yy)[0]);
                        }
                    const float* got = hiz.at(l.x0 + x, l.y0 + y);
                    ++texels;
                    if (got[0] != mn || got[1] != mx) {
                        if (++wrong < 5)
                            ADD_FAILURE() << w << "x" << h << " level " << k << " texel " << x << "," << y << ": got ("
                                          << got[0] << ", " << got[1] << "), expected (" << mn << ", " << mx << ")";
                    }
                }
        }
        EXPECT_EQ(wrong, 0) << w << "x" << h << ": " << texels << " texels in " << levels.size() << " levels";
    }
}

// color.pyramid: the first three levels are means of their level-0 footprint exactly (one dispatch reduces them
// straight from the input); later ones are means of level 2's texels, which for odd sizes weighs level-0 pixels
// slightly unevenly, so they are checked against the level-0 mean within 2% of the noise's range.
TEST_F(Ssr, ColorPyramidTexelsAreTheMeanOfTheirFootprint) {
    for (auto [w, h] : {std::pair{37, 23}, std::pair{64, 32}}) {
        json nodes = {{"noise", {{"type", "test.ssr_noise"}}},
                      {"pyramid", {{"type", "color.pyramid"}, {"in", {{"color", "noise.result"}}}}}};
        auto out = runGraph(graph(nodes, {{"color", "noise.result"}, {"pyramid", "pyramid.pyramid"}}, w, h));
        const Image& color = out.at("color");
        const Image& pyr = out.at("pyramid");
        auto levels = atlasLevels(w, h);
        double worst = 0.0;
        for (size_t k = 0; k < levels.size(); ++k) {
            const Level& l = levels[k];
            bool exact = k < 3 || (w % 8 == 0 && h % 8 == 0 && (w >> k) > 0 && (h >> k) > 0);
            for (int y = 0; y < l.h; ++y)
                for (int x = 0; x < l.w; ++x) {
                    int x0, x1, y0, y1;
                    footprint(w, static_cast<int>(k), x, l.w, x0, x1);
                    footprint(h, static_cast<int>(k), y, l.h, y0, y1);
                    for (int c = 0; c < 3; ++c) {
                        double sum = 0.0;
                        for (int yy = y0; yy < y1; ++yy)
                            for (int xx = x0; xx < x1; ++xx) sum += color.at(xx, yy)[c];
                        double mean = sum / ((x1 - x0) * (y1 - y0));
                        double err = std::abs(pyr.at(l.x0 + x, l.y0 + y)[c] - mean);
                        worst = std::max(worst, err);
                        // RGBA16F: values below 1 are stored within 2^-11 relative.
                        EXPECT_LT(err, exact ? 1e-3 : 0.02) << w << "x" << h << " level " << k << " texel " << x
                                                            << "," << y << " channel " << c;
                    }
                }
        }
        std::printf("color.pyramid %dx%d: largest difference from the footprint mean %.2g\n", w, h, worst);
    }
}

// Hi-Z, the colour pyramid of `color` and ssr.hiz with `params`, added to nodes that have the G-buffer.
void addSsrChain(json& n, const char* color, json params = json::object()) {
    n["hiz"] = {{"type", "depth.hiz"}, {"in", {{"depth", "gbuffer.depth"}}}};
    n["pyramid"] = {{"type", "color.pyramid"}, {"in", {{"color", color}}}};
    n["ssr"] = {{"type", "ssr.hiz"},
                {"in",
                 {{"normal", "gbuffer.normal"},
                  {"depth", "gbuffer.depth"},
                  {"hiz", "hiz.hiz"},
                  {"color", "pyramid.pyramid"},
                  {"camera", "scene.camera"}}},
                {"params", std::move(params)}};
}

// The SSR chain over a scene's G-buffer with a test image (each pixel's coordinates by default) as the colour the
// reflections read: scene, G-buffer, Hi-Z, colour pyramid and ssr.hiz with `params`.
json ssrNodes(const std::filesystem::path& glb, json params, const char* source = "test.ssr_coords") {
    json n = baseNodes(glb);
    n["coords"] = {{"type", source}};
    addSsrChain(n, "coords.result", std::move(params));
    return n;
}

// ssr.hiz writes premultiplied (radiance x confidence, confidence): what its rays read at a pixel is rgb / a, and its
// confidence a.
glm::dvec4 reflectionRead(const Image& ssr, int x, int y) {
    const float* p = ssr.at(x, y);
    const double a = p[3];
    return a > 0.0 ? glm::dvec4(p[0] / a, p[1] / a, p[2] / a, a) : glm::dvec4(0.0);
}

// --- A mirror floor under a wall, a pillar and a plate -------------------------------------------------------

enum class Hit { None, Floor, Wall, Pillar, Plate };

struct MirrorScene {
    static constexpr int W = 128, H = 96;
    const glm::dvec3 pillarLo{-1.35, 0.0, -0.95}, pillarHi{-1.05, 2.0, -0.65};
    const double plateY = 1.8;
    const glm::dvec2 plateLoXZ{0.4, -1.5}, plateHiXZ{1.6, -0.5};
    const double wallZ = -3.0, floorFar = -3.0, floorNear = 6.0, halfWidth = 6.0, wallTop = 4.0;
    std::filesystem::path glb;
    std::optional<Pinhole> cam;
    glm::dvec3 forward{0.0};
    double tanHalf = 0.0;

    // floorShininess 1: a mirror. aoGradient: the floor's vertex AO runs from 0.5 (far) to 1 (near).
    // slide: the camera moves by it between frame 0 and frame 1 (24 fps); cam stays frame 0's camera.
    explicit MirrorScene(float floorShininess = 1.0f, float floorCavity = 1.0f, bool aoGradient = false,
                         glm::vec3 slide = glm::vec3(0.0f)) {
        SceneBuilder b(slide == glm::vec3(0.0f) ? "ssr_mirror" : "ssr_mirror_slide");
        std::vector<Tri> floorTris, wallTris, plateTris;
        addQuad(floorTris, {0.0f, 0.0f, 1.5f}, {6.0f, 0.0f, 0.0f}, {0.0f, 0.0f, 4.5f}, {0, 1, 0});
        if (aoGradient)
            for (Tri& t : floorTris)
                for (scene::Vertex* v : {&t.a, &t.b, &t.c}) v->color.a = 0.5f + 0.5f * (v->position.z + 3.0f) / 9.0f;
        addQuad(wallTris, {0.0f, 2.0f, -3.0f}, {6.0f, 0.0f, 0.0f}, {0.0f, 2.0f, 0.0f}, {0, 0, 1});
        addQuad(plateTris, {1.0f, 1.8f, -1.0f}, {0.6f, 0.0f, 0.0f}, {0.0f, 0.0f, 0.5f}, {0, 1, 0});
        uint32_t floorMat = b.material("floor", glm::vec3(0.9f, 0.8f, 0.6f), 1.0f, floorShininess);
        b.s.materials[floorMat].layers[0].cavity = {floorCavity, 0.0f};
        b.node("floor", static_cast<int32_t>(b.mesh("floor", floorTris, floorMat)));
        uint32_t matte = b.material("matte", glm::vec3(0.6f, 0.5f, 0.4f), 0.0f, 0.5f);
        b.node("wall", static_cast<int32_t>(b.mesh("wall", wallTris, matte)));
        b.node("plate", static_cast<int32_t>(b.mesh("plate", plateTris, matte)));
        b.node("pillar", static_cast<int32_t>(b.mesh("pillar", boxTris(glm::vec3(0.15f, 1.0f, 0.15f)), matte)),
               glm::vec3(-1.2f, 1.0f, -0.8f));
        const glm::vec3 eye(0.3f, 2.6f, 4.5f);
        b.camera(eye, {0.0f, 0.5f, -1.0f}, 0.9f);
        if (slide != glm::vec3(0.0f)) {
            scene::Animation move;
            move.name = "slide";
            move.samplers = {{scene::Interpolation::Linear,
                              {0.0f, 1.0f / 24.0f},
                              {glm::vec4(eye, 0.0f), glm::vec4(eye + slide, 0.0f)}}};
            move.channels = {{static_cast<uint32_t>(b.s.nodes.size() - 1), scene::AnimationPath::Translation, 0}};
            b.s.animations.push_back(move);
        }
        b.sun({0.3f, 1.0f, 0.6f});
        glb = b.write();
        cam.emplace(b.s, W, H);
        forward = cam->orientation * glm::dvec3(0, 0, -1);
        tanHalf = std::tan(0.5 * cam->yfov);
    }

    // First surface along the unit ray (o, d) after tMin: its distance and what it is.
    std::pair<double, Hit> trace(glm::dvec3 o, glm::dvec3 d, double tMin = 1e-6) const {
        double best = std::numeric_limits<double>::infinity();
        Hit what = Hit::None;
        auto consider = [&](double t, Hit h) {
            if (t > tMin && t < best) {
                best = t;
                what = h;
            }
        };
        if (d.y != 0.0) {
            double t = -o.y / d.y;
            glm::dvec3 p = o + t * d;
            if (std::abs(p.x) <= halfWidth && p.z >= floorFar && p.z <= floorNear) consider(t, Hit::Floor);
            t = (plateY - o.y) / d.y;
            p = o + t * d;
            if (p.x >= plateLoXZ.x && p.x <= plateHiXZ.x && p.z >= plateLoXZ.y && p.z <= plateHiXZ.y)
                consider(t, Hit::Plate);
        }
        if (d.z != 0.0) {
            double t = (wallZ - o.z) / d.z;
            glm::dvec3 p = o + t * d;
            if (std::abs(p.x) <= halfWidth && p.y >= 0.0 && p.y <= wallTop) consider(t, Hit::Wall);
        }
        double t0 = 0.0, t1 = std::numeric_limits<double>::infinity();
        bool in = true;
        for (int a = 0; a < 3 && in; ++a) {
            if (std::abs(d[a]) < 1e-12) {
                in = o[a] >= pillarLo[a] && o[a] <= pillarHi[a];
                continue;
            }
            double ta = (pillarLo[a] - o[a]) / d[a], tb = (pillarHi[a] - o[a]) / d[a];
            t0 = std::max(t0, std::min(ta, tb));
            t1 = std::min(t1, std::max(ta, tb));
        }
        if (in && t0 <= t1) consider(t0, Hit::Pillar);
        return {best, what};
    }

    // Continuous pixel position of world point p (pixel centres at +0.5), and its view depth.
    glm::dvec3 project(glm::dvec3 p) const { return projectWith(*cam, p); }
    static glm::dvec3 projectWith(const Pinhole& view, glm::dvec3 p) {
        glm::dvec3 c = glm::conjugate(view.orientation) * (p - view.position);
        const double tanHalf = std::tan(0.5 * view.yfov);
        double aspect = double(W) / H;
        double nx = c.x / -c.z / (tanHalf * aspect), ny = -c.y / -c.z / tanHalf;
        return {(nx * 0.5 + 0.5) * W, (ny * 0.5 + 0.5) * H, -c.z};
    }
    glm::dvec3 rayThrough(glm::dvec2 px) const {
        double aspect = double(W) / H;
        glm::dvec2 ndc = px / glm::dvec2(W, H) * 2.0 - 1.0;
        return glm::normalize(cam->orientation * glm::dvec3(ndc.x * aspect * tanHalf, -ndc.y * tanHalf, -1.0));
    }

    // How a screen-space march may see the segment a-b: Clear when no point of it is hidden from the camera by the
    // pillar or the plate (camera and ray lie on the same side of the floor and of the wall, which hide nothing; a
    // pixel away they are merely nearer); Ambiguous when a point is hidden by less than `slab` in view depth (at its screen
    // position or within 1.5 px: a march may legitimately stop there); Behind otherwise (passing behind an
    // occluder costs fetches: the march may run out of them).
    enum class Path { Clear, Ambiguous, Behind };
    Path classify(glm::dvec3 a, glm::dvec3 b, double slab) const {
        Path path = Path::Clear;
        for (int i = 1; i < 400; ++i) {
            glm::dvec3 q = a + (b - a) * (i / 400.0);
            glm::dvec3 s = project(q);
            if (s.z <= 0.0 || s.x < 0 || s.y < 0 || s.x > W || s.y > H) continue;
            for (int oy = -1; oy <= 1; ++oy)
                for (int ox = -1; ox <= 1; ++ox) {
                    glm::dvec3 d = rayThrough(glm::dvec2(s) + 1.5 * glm::dvec2(ox, oy));
                    auto [t, what] = trace(cam->position, d);
                    if (what != Hit::Pillar && what != Hit::Plate) continue;
                    double gap = s.z - t * glm::dot(d, forward);
                    if (gap > 1e-3 && gap < slab) return Path::Ambiguous;
                    if (gap >= slab && ox == 0 && oy == 0) path = Path::Behind;
                }
        }
        return path;
    }

    json nodes(json ssrParams, const char* source = "test.ssr_coords") const { return ssrNodes(glb, ssrParams, source); }
};

constexpr double kThickness = 0.1, kMaxDistance = 6.0, kEdgeFade = 0.1;

json mirrorParams(int taps) {
    return {{"resolution_scale", 1.0}, {"max_taps", taps},        {"thickness", kThickness},
            {"max_distance", kMaxDistance}, {"edge_fade", kEdgeFade}};
}

// Every floor pixel: where the mirror ray's first hit is on screen and visible, SSR reads the texel within a
// pixel of it with the confidence of the edge and length fades there; where the ray leaves the screen, finds
// nothing, or meets the plate from below (a back face), the confidence is 0.
TEST_F(Ssr, MirrorFloorReflectsTheAnalyticMirrorTexel) {
    MirrorScene m;
    auto out = runGraph(graph(m.nodes(mirrorParams(64)), {{"ssr", "ssr.reflection"}}, MirrorScene::W, MirrorScene::H));
    const Image& ssr = out.at("ssr");
    ASSERT_EQ(ssr.width, MirrorScene::W);
    int onScreen = 0, offScreen = 0, backFaces = 0, skipped = 0, far = 0, missedBehind = 0, wrong = 0, wrongZero = 0, wrongBackFaces = 0;
    double worstPos = 0.0, worstConf = 0.0, worstZero = 0.0;
    for (int y = 0; y < MirrorScene::H; ++y)
        for (int x = 0; x < MirrorScene::W; ++x) {
            glm::dvec3 d = m.cam->ray(x, y);
            auto [t, what] = m.trace(m.cam->position, d);
            if (what != Hit::Floor) continue;
            glm::dvec3 p = m.cam->position + t * d;
            glm::dvec3 r(d.x, -d.y, d.z);
            auto [tr, hit] = m.trace(p, r);
            const glm::dvec4 got = reflectionRead(ssr, x, y);
            glm::dvec3 end = p + r * std::min(tr, kMaxDistance);
            MirrorScene::Path path = m.classify(p, end, 2.0 * kThickness + 0.05);
            if (path == MirrorScene::Path::Ambiguous) {
                ++skipped;
                continue;
            }
            // Behind an occluder the march may run out of fetches: a miss is allowed there, a wrong hit is not.
            if (path == MirrorScene::Path::Behind && got[3] == 0.0f) {
                ++missedBehind;
                continue;
            }
            glm::dvec3 h = p + r * tr;
            glm::dvec3 s = hit == Hit::None ? glm::dvec3(-1.0) : m.project(h);
            bool inside = s.x >= 0 && s.y >= 0 && s.x <= MirrorScene::W && s.y <= MirrorScene::H;
            if (hit == Hit::Plate) {
                ++backFaces;
                if (got[3] >= 0.02f) ++wrongBackFaces;
                else worstZero = std::max(worstZero, double(got[3]));
                continue;
            }
            if (hit == Hit::None || !inside || tr > kMaxDistance) {
                ++offScreen;
                if (got[3] >= 0.02f) ++wrongZero;
                else worstZero = std::max(worstZero, double(got[3]));
                continue;
            }
            // Visible from the camera (not hidden behind another surface)?
            glm::dvec3 toHit = glm::normalize(h - m.cam->position);
            if (m.trace(m.cam->position, toHit).first < glm::length(h - m.cam->position) - 1e-3) {
                ++skipped;
                continue;
            }
            // A reflection within 3 px of its pixel (the floor meeting the wall) is below what a march that starts
            // by leaving its own texel resolves.
            double reach = std::hypot(s.x - (x + 0.5), s.y - (y + 0.5));
            if (reach < 3.0) {
                ++skipped;
                continue;
            }
            ++onScreen;
            if (reach > 20.0) ++far;
            glm::dvec2 uv(s.x / MirrorScene::W, s.y / MirrorScene::H);
            double edge = std::min({uv.x, uv.y, 1.0 - uv.x, 1.0 - uv.y});
            double expected = std::clamp(edge / kEdgeFade, 0.0, 1.0) *
                              std::clamp((kMaxDistance - tr) / (0.25 * kMaxDistance), 0.0, 1.0);
            double confErr = std::abs(got[3] - expected);
            double posErr = expected > 0.1 ? std::hypot(got[0] - s.x, got[1] - s.y) : 0.0;
            if (confErr > 0.1 || posErr > 1.0) {
                ++wrong;
                if (wrong <= 10)
                    std::printf("  pixel %d,%d: confidence %.3f (expected %.3f), read %.2f,%.2f, mirror image at "
                                "%.2f,%.2f\n",
                                x, y, got[3], expected, got[0], got[1], s.x, s.y);
                continue;
            }
            worstConf = std::max(worstConf, confErr);
            worstPos = std::max(worstPos, posErr);
        }
    std::printf("mirror: %d pixels hit on screen (%d over 20 px away; %d beyond 1 px or 0.1 confidence; of the "
                "others the largest position error %.3f px, confidence error %.3f), %d leave the screen or find nothing (%d with a confidence of 0.02 or more), %d meet a back face (of these %d with a confidence of 0.02 or more; "
                "of the others the largest %.3f), %d "
                "skipped as ambiguous, %d pass behind an occluder and miss\n",
                onScreen, far, wrong, worstPos, worstConf, offScreen, wrongZero, backFaces, wrongBackFaces, worstZero, skipped,
                missedBehind);
    // Screen-space tracing is exact only up to the depth buffer's sampling: a few rays per hundred (grazing the
    // wall's foot, slipping past a texel's single depth) land a pixel or more off, or are missed.
    EXPECT_LE(wrong, onScreen / 20);
    EXPECT_LE(wrongZero, offScreen / 100);
    // The plate's top is a sliver on screen that a march can slip past; at least half the rays into its underside
    // must be caught by the back-face test.
    EXPECT_LE(2 * wrongBackFaces, backFaces);
    EXPECT_GT(onScreen, 1500);
    EXPECT_GT(far, 500);
    EXPECT_GT(offScreen, 100);
    EXPECT_GE(backFaces, 5);
}

// Refinement (issue 26): a true mirror floor (shininess 1 with gbuffer.layered's Toksvig off, which otherwise floors
// the stored roughness at sqrt(kMinGgxAlpha) = 0.045, so that the rays are GGX samples of alpha 0.002 and scatter by a
// few tenths of a pixel) under a wall turned 35° about the vertical, whose depth changes across the screen (on a wall
// facing the camera every texel holds the same depth and a hit needs no refining). Every ray is the mirror ray; where
// it meets the wall, the march stops within a pixel or two and bisects, over two pixels either side, the ray's depth
// against the depth interpolated between texel centres, which is exact on a plane: 4 steps leave the hit within 1/8
// px (along the ray's major axis) of the analytic mirror image. Measured against it: mean distance under 0.1 px and
// 99 % within 0.25 px; an unrefined hit (where the ray meets a texel's single depth), or one a third of a pixel too
// far along the ray, fails both.
TEST_F(Ssr, RefinedHitsLieOnTheMirrorImage) {
    const int W = 128, H = 96;
    const double angle = 35.0 * kPi / 180.0;
    const glm::dvec3 wallC(0.0, 2.0, -3.0), wallU(std::cos(angle), 0.0, -std::sin(angle)), wallN(std::sin(angle), 0.0, std::cos(angle));
    const double wallHalf = 6.0, wallTop = 4.0;
    SceneBuilder b("ssr_turned_wall");
    std::vector<Tri> floorTris, wallTris;
    addQuad(floorTris, {0.0f, 0.0f, -1.5f}, {7.0f, 0.0f, 0.0f}, {0.0f, 0.0f, 6.0f}, {0, 1, 0});
    addQuad(wallTris, glm::vec3(wallC), glm::vec3(wallU * wallHalf), {0.0f, 2.0f, 0.0f}, glm::vec3(wallN));
    b.node("floor", static_cast<int32_t>(b.mesh("floor", floorTris, b.material("mirror", glm::vec3(0.9f), 1.0f, 1.0f))));
    b.node("wall", static_cast<int32_t>(b.mesh("wall", wallTris, b.material("matte", glm::vec3(0.5f), 0.0f, 0.5f))));
    b.camera({0.3f, 2.6f, 4.5f}, {0.0f, 0.5f, -1.0f}, 0.9f);
    b.sun({0.3f, 1.0f, 0.6f});
    auto glb = b.write();
    Pinhole cam(b.s, W, H);
    json nodes = ssrNodes(glb, mirrorParams(64));
    nodes["gbuffer"]["params"]["toksvig"] = false;
    auto out = runGraph(graph(nodes, {{"ssr", "ssr.reflection"}}, W, H));
    const Image& ssr = out.at("ssr");
    // Distance along the unit ray (o, d) to the wall's quad, or infinity.
    auto wallHit = [&](glm::dvec3 o, glm::dvec3 d) {
        const double den = glm::dot(d, wallN);
        if (std::abs(den) < 1e-12) return std::numeric_limits<double>::infinity();
        const double t = glm::dot(wallC - o, wallN) / den;
        const glm::dvec3 q = o + t * d;
        if (t <= 1e-6 || q.y < 0.0 || q.y > wallTop || std::abs(glm::dot(q - wallC, wallU)) > wallHalf)
            return std::numeric_limits<double>::infinity();
        return t;
    };
    int hits = 0, beyond = 0, missed = 0;
    double sum = 0.0, worst = 0.0;
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            const glm::dvec3 d = cam.ray(x, y);
            if (d.y >= 0.0) continue;
            const double t = -cam.position.y / d.y;
            const glm::dvec3 p = cam.position + t * d;
            if (std::abs(p.x) > 6.5 || p.z < -7.0 || p.z > 4.0 || wallHit(cam.position, d) < t) continue; // the floor
            const glm::dvec3 r(d.x, -d.y, d.z);
            const double tr = wallHit(p, r);
            if (tr > 0.75 * kMaxDistance) continue; // the wall, before the length fade
            const glm::dvec3 s = MirrorScene::projectWith(cam, p + r * tr);
            const glm::dvec2 uv(s.x / W, s.y / H);
            if (std::min({uv.x, uv.y, 1.0 - uv.x, 1.0 - uv.y}) < kEdgeFade) continue; // before the edge fade
            if (std::hypot(s.x - (x + 0.5), s.y - (y + 0.5)) < 3.0) continue; // the wall's foot: below what the march resolves
            const glm::dvec4 got = reflectionRead(ssr, x, y);
            if (got[3] < 0.5f) {
                ++missed;
                continue;
            }
            const double err = std::hypot(got[0] - s.x, got[1] - s.y);
            ++hits;
            sum += err;
            worst = std::max(worst, err);
            if (err > 0.25) ++beyond;
        }
    const double mean = sum / std::max(hits, 1);
    std::printf("refinement: %d mirror rays onto the turned wall (%d missed): mean distance from the mirror image %.3f "
                "px, %d beyond 0.25 px, the largest %.3f px\n",
                hits, missed, mean, beyond, worst);
    EXPECT_GT(hits, 1500);
    EXPECT_LE(missed, hits / 100);
    EXPECT_LT(mean, 0.1);
    EXPECT_LE(beyond, hits / 100);
}

// The thickness fade, and the slab's thickness (issue 26): a mirror wall facing the camera 3 m away, and in front of
// it, off to the right, two cards abutting on screen: A (x 0.58..0.765, 1.7 m from the camera) and beyond its right
// edge B (x 0.9..1.4, 2.2 m). Mirror rays from the wall come back towards the camera and move outwards on screen: they
// cross A's pixels behind it, more than `thickness` (0.4 m) behind, where the march skips them, and enter B's pixels
// from A's, at a depth g behind B. Where 0 < g < thickness the march stops at B's first texel; two pixels back the
// ray was behind A, so there is no crossing to refine and the hit is g behind the surface: its confidence is the
// thickness fade, clamp(2 - 2 g / thickness, 0, 1) (B's normals are turned to face the rays, so the back-face test
// passes them; edge and length fades are 1 there). g is computed here where the ray's screen path meets the first
// column of B's pixels (A's right edge projected), and the hit must be read within a pixel of that point. Slabs twice
// as thick would stop the rays behind A; a fade that is a step would give 1 wherever g < thickness.
TEST_F(Ssr, ThicknessFadesHitsFoundBehindTheSurface) {
    const int W = 192, H = 144;
    const double mirrorZ = -3.0, aZ = -1.7, bZ = -2.2, thickness = 0.4, aLeft = 0.58, aRight = 0.765;
    SceneBuilder b("ssr_cards");
    std::vector<Tri> mirrorTris, aTris, bTris;
    addQuad(mirrorTris, {0.0f, 1.5f, -3.0f}, {4.0f, 0.0f, 0.0f}, {0.0f, 3.0f, 0.0f}, {0, 0, 1});
    addQuad(aTris, {0.6725f, 1.5f, -1.7f}, {0.0925f, 0.0f, 0.0f}, {0.0f, 0.6f, 0.0f}, {0, 0, 1});
    addQuad(bTris, {1.15f, 1.5f, -2.2f}, {0.25f, 0.0f, 0.0f}, {0.0f, 0.6f, 0.0f}, {0, 0, 1});
    b.node("mirror", static_cast<int32_t>(b.mesh("mirror", mirrorTris, b.material("mirror", glm::vec3(0.9f), 1.0f, 1.0f))));
    uint32_t matte = b.material("matte", glm::vec3(0.5f), 0.0f, 0.5f);
    b.node("a", static_cast<int32_t>(b.mesh("a", aTris, matte)));
    b.node("b", static_cast<int32_t>(b.mesh("b", bTris, matte)));
    b.camera({0.0f, 1.5f, 0.0f}, {0.0f, 1.5f, -3.0f}, 0.9f);
    b.sun({0.3f, 1.0f, 0.6f});
    auto glb = b.write();
    Pinhole cam(b.s, W, H);
    const double camZ = cam.position.z;
    json nodes = ssrNodes(glb, {{"resolution_scale", 1.0}, {"max_taps", 64}, {"thickness", thickness},
                                {"max_distance", 30.0}, {"edge_fade", 0.05}});
    nodes["gbuffer"]["params"]["toksvig"] = false; // a true mirror: every ray is the mirror ray
    nodes["normals"] = {{"type", "test.ssr_normals"},
                        {"in", {{"normal", "gbuffer.normal"}}},
                        {"params", {{"near", camZ - bZ - 0.05}, {"far", camZ - bZ + 0.05}, {"normal", {0.0, 0.0, -1.0}}}}};
    nodes["ssr"]["in"]["normal"] = "normals.result";
    auto out = runGraph(graph(nodes, {{"ssr", "ssr.reflection"}}, W, H));
    const Image& ssr = out.at("ssr");
    // Screen x (pixels) of world x at view depth `depth` (the camera looks down -z from x = 0, y = 1.5).
    const double focal = 0.5 * H / std::tan(0.5 * cam.yfov);
    auto screenX = [&](double x, double depth) { return 0.5 * W + focal * x / depth; };
    auto screenY = [&](double y, double depth) { return 0.5 * H - focal * (y - cam.position.y) / depth; };
    // B's first column: the first pixel centre right of A's projected right edge.
    const double edge = screenX(aRight, camZ - aZ), column = std::floor(edge - 0.5) + 1.0;
    int checked = 0, wrong = 0, faded = 0;
    double worst = 0.0;
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            const glm::dvec3 d = cam.ray(x, y);
            const glm::dvec3 p = cam.position + d * ((mirrorZ - camZ) / d.z);
            if (screenX(p.x, camZ - mirrorZ) > screenX(aLeft, camZ - aZ) - 2.0) continue; // the mirror left of A
            const glm::dvec3 r(d.x, d.y, -d.z);
            // Where the ray's screen path reaches x = column: bisect the ray parameter (screen x grows along it).
            double lo = 0.0, hi = (camZ - 0.3 - p.z) / r.z;
            if (screenX((p + r * hi).x, camZ - (p + r * hi).z) < column) continue;
            for (int k = 0; k < 60; ++k) {
                const double mid = 0.5 * (lo + hi);
                const glm::dvec3 q = p + r * mid;
                (screenX(q.x, camZ - q.z) < column ? lo : hi) = mid;
            }
            const glm::dvec3 q = p + r * hi;
            const double depth = camZ - q.z, g = depth - (camZ - bZ), gA = depth - (camZ - aZ);
            const double sy = screenY(q.y, depth);
            if (sy < 0.25 * H || sy > 0.75 * H) continue;      // well inside both cards' height
            // More than `thickness` behind A at its right edge (and so all the way across it: the ray gets nearer along
            // its path), inside B's slab as it enters B's pixels.
            if (gA < thickness + 0.02 || g < 0.04 || g > thickness - 0.04) continue;
            const double expected = std::clamp(2.0 - 2.0 * g / thickness, 0.0, 1.0);
            const glm::dvec4 got = reflectionRead(ssr, x, y);
            ++checked;
            if (expected < 0.95) ++faded;
            const double err = std::abs(got[3] - expected);
            const double posErr = std::hypot(got[0] - column, got[1] - sy);
            if (err > 0.1 || (expected > 0.1 && posErr > 1.0)) {
                if (++wrong <= 5)
                    std::printf("  pixel %d,%d: confidence %.3f (expected %.3f, %.3f m behind B), read at %.2f,%.2f, "
                                "B's first column met at %.2f,%.2f\n",
                                x, y, got[3], expected, g, got[0], got[1], column, sy);
                continue;
            }
            worst = std::max(worst, err);
        }
    std::printf("thickness: %d mirror rays enter B from behind A within its slab (%d with a fade below 0.95); %d off "
                "by over 0.1 in confidence or 1 px in position; of the others the largest confidence error %.3f\n",
                checked, faded, wrong, worst);
    EXPECT_GT(checked, 100);
    EXPECT_GT(faded, 50);
    EXPECT_LE(wrong, checked / 20);
}

// max_taps bounds how far a ray gets: with 3 fetches a hit is at most 1 + 3 + 1 pixels along the ray past the
// origin's texel (one level-0 cell, one level-1 cell, a fetch to confirm), whatever the mirror says.
TEST_F(Ssr, TapLimitBoundsTheMarch) {
    MirrorScene m;
    auto out = runGraph(graph(m.nodes(mirrorParams(3)), {{"ssr", "ssr.reflection"}}, MirrorScene::W, MirrorScene::H));
    const Image& ssr = out.at("ssr");
    int hits = 0;
    double farthest = 0.0;
    for (int y = 0; y < MirrorScene::H; ++y)
        for (int x = 0; x < MirrorScene::W; ++x) {
            const glm::dvec4 got = reflectionRead(ssr, x, y);
            // Premultiplied half floats: below a confidence of 1e-3 (a read that weighs < 0.1 %) rgb / a is no position
            // (at the smallest subnormal, 6e-8, it is a few pixels off).
            if (got[3] < 1e-3) continue;
            ++hits;
            farthest = std::max(farthest, std::hypot(got[0] - (x + 0.5), got[1] - (y + 0.5)));
        }
    std::printf("3 taps: %d pixels with a hit, farthest %.2f px from its pixel\n", hits, farthest);
    EXPECT_LE(farthest, 8.0);
}

// The walk spends its fetches well: where a cell's depth slab stops the ray, it moves to where the ray enters the slab
// before going one level finer, rather than descending from the cell's entry. On the mirror floor, 16 fetches (the
// Museum's budget until 2026-12) find 60 % of the confident hits (>= 0.5) that 64 find; descending from the cell's
// entry they found 41 %.
TEST_F(Ssr, TheMarchAdvancesToTheSlabBeforeDescending) {
    MirrorScene m;
    auto confident = [&](int taps) {
        auto out =
            runGraph(graph(m.nodes(mirrorParams(taps)), {{"ssr", "ssr.reflection"}}, MirrorScene::W, MirrorScene::H));
        int n = 0;
        for (int y = 0; y < MirrorScene::H; ++y)
            for (int x = 0; x < MirrorScene::W; ++x)
                if (out.at("ssr").at(x, y)[3] >= 0.5f) ++n;
        return n;
    };
    const int few = confident(16), many = confident(64);
    std::printf("march: %d confident hits with 16 taps, %d with 64 (%.2f)\n", few, many, double(few) / many);
    EXPECT_GT(many, 3000);
    EXPECT_GE(few, 0.55 * many);
}

// ssr.composite fed by lighting, the G-buffer and `reflection` (ssr.reflection or its temporal accumulation).
json compositeNode(const char* reflection) {
    return {{"type", "ssr.composite"},
            {"in",
             {{"color", "lighting.color"},
              {"specular_indirect", "lighting.specular_indirect"},
              {"reflection", reflection},
              {"normal", "gbuffer.normal"},
              {"base_color", "gbuffer.base_color"},
              {"material", "gbuffer.material"},
              {"depth", "gbuffer.depth"},
              {"camera", "scene.camera"}}}};
}

// What ssr.composite weighs SSR's radiance by at pixel (x, y), from the read-back G-buffer ("normal", "base",
// "material"): Karis' environment BRDF E from core/shading times the vertex AO and the cavity; with `multiscatter`
// (ssr.composite's) also times core/shading's ggxMultiscatter, whose factor goes to `compensation` when asked.
glm::dvec3 weightOfSsr(const std::map<std::string, Image>& out, const MirrorScene& m, int x, int y,
                       bool multiscatter = false, glm::dvec3* compensation = nullptr) {
    const float* g0 = out.at("normal").at(x, y);
    const float* g1 = out.at("base").at(x, y);
    const float* g2 = out.at("material").at(x, y);
    const glm::vec3 n = shading::octDecode({g0[0], g0[1]});
    const glm::dvec3 v = -m.cam->ray(x, y);
    const float NoV = std::clamp(float(glm::dot(glm::dvec3(n), v)), 1e-4f, 1.0f);
    const glm::vec2 ab = shading::envBrdfApprox(NoV, shading::roughnessFromShininess(g0[3]));
    const glm::vec3 f0 = shading::specularF0({g1[0], g1[1], g1[2]}, g1[3]);
    const glm::dvec3 e = glm::dvec3(f0) * double(ab.x) + double(ab.y);
    const glm::dvec3 k =
        multiscatter
            ? glm::dvec3(shading::ggxMultiscatter(f0, NoV, shading::ggxAlpha(shading::roughnessFromShininess(g0[3]))))
            : glm::dvec3(1.0);
    if (compensation) *compensation = k;
    return e * k * double(g2[2] * g2[3]);
}

// ssr.composite on a lit glossy floor (roughness 0.15, cavity 0.8, vertex AO 0.5..1) with SSR at half
// resolution: every pixel against the blend evaluated on the CPU from the read-back inputs, with Karis' environment
// BRDF from core/shading and the half-resolution (premultiplied) reflection upsampled bilinearly (clamped at the
// edges); its specular_indirect output against the blended term alone. Then a rougher floor (roughness 0.45) with the
// composite's multiscatter: the weight times core/shading's ggxMultiscatter (x1.03-1.1 there, so a composite that
// leaves it out fails the 0.4 % bound).
TEST_F(Ssr, CompositeMatchesTheCpuBlend) {
    for (const bool multiscatter : {false, true}) {
        SCOPED_TRACE(multiscatter ? "rough floor, multiscatter" : "glossy floor");
        MirrorScene m(multiscatter ? 0.55f : 0.85f, 0.8f, true);
        const int W = MirrorScene::W, H = MirrorScene::H;
        json nodes = baseNodes(m.glb);
        nodes["lighting"] = lightingNode(json::object(), false);
        addSsrChain(nodes, "lighting.color");
        nodes["composite"] = compositeNode("ssr.reflection");
        nodes["composite"]["params"] = {{"multiscatter", multiscatter}};
        auto out = runGraph(graph(nodes,
                                  {{"color", "lighting.color"},
                                   {"spec", "lighting.specular_indirect"},
                                   {"ssr", "ssr.reflection"},
                                   {"normal", "gbuffer.normal"},
                                   {"base", "gbuffer.base_color"},
                                   {"material", "gbuffer.material"},
                                   {"final", "composite.color"},
                                   {"final_specular", "composite.specular_indirect"}},
                                  W, H));
        const Image& ssr = out.at("ssr");
        ASSERT_EQ(ssr.width, W / 2);
        ASSERT_EQ(ssr.height, H / 2);
        auto fetch = [&](int x, int y) {
            const float* p = ssr.at(std::clamp(x, 0, ssr.width - 1), std::clamp(y, 0, ssr.height - 1));
            return glm::dvec4(p[0], p[1], p[2], p[3]);
        };
        int blended = 0, full = 0, seen = 0;
        double worst = 0.0, compensation = 1.0;
        for (int y = 0; y < H; ++y)
            for (int x = 0; x < W; ++x) {
                glm::dvec3 color = rgb(out.at("color"), x, y), spec = rgb(out.at("spec"), x, y);
                glm::dvec3 got = rgb(out.at("final"), x, y);
                const float* g0 = out.at("normal").at(x, y);
                if (g0[2] <= 0.0f) continue; // sky
                // Half-resolution texel q stands for pixel 2q: pixel p reads p / 2, between two texels when odd.
                int x0 = x / 2, y0 = y / 2, x1 = (x + 1) / 2, y1 = (y + 1) / 2;
                glm::dvec4 r = 0.25 * (fetch(x0, y0) + fetch(x1, y0) + fetch(x0, y1) + fetch(x1, y1));
                // r is premultiplied (c L_ssr, c): the bilinear mix of the four texels is c L_ssr of the mix.
                glm::dvec3 k;
                glm::dvec3 reflectedTimesC = weightOfSsr(out, m, x, y, multiscatter, &k) * glm::dvec3(r);
                double c = std::clamp(r.w, 0.0, 1.0);
                if (multiscatter && c > 0.5) {
                    compensation = std::max(compensation, k.r);
                    ++seen;
                }
                glm::dvec3 expected = glm::max(color - spec + spec * (1.0 - c) + reflectedTimesC, glm::dvec3(0.0));
                // Its specular_indirect output: the blended term alone (what reference.reflections is compared with).
                const glm::dvec3 term = spec * (1.0 - c) + reflectedTimesC,
                                 gotTerm = rgb(out.at("final_specular"), x, y);
                for (int k = 0; k < 3; ++k)
                    EXPECT_LT(std::abs(gotTerm[k] - term[k]),
                              4e-3 * std::abs(term[k]) + 1e-3 * std::abs(color[k]) + 1e-6)
                        << "specular_indirect, pixel " << x << "," << y << " channel " << k;
                if (c > 0.05 && c < 0.95) ++blended;
                if (c >= 0.95) ++full;
                for (int k = 0; k < 3; ++k) {
                    double err =
                        std::abs(got[k] - expected[k]) / (std::abs(expected[k]) + 1e-3 * std::abs(color[k]) + 1e-6);
                    worst = std::max(worst, err);
                    EXPECT_LT(err, 4e-3) << "pixel " << x << "," << y << " channel " << k << ": got " << got[k]
                                         << ", expected " << expected[k] << " (confidence " << c << ")";
                }
            }
        std::printf("composite%s: %d pixels blended partly, %d fully by SSR; largest relative error %.2g\n",
                    multiscatter ? " (rough floor, multiscatter)" : "", blended, full, worst);
        if (multiscatter) {
            std::printf("composite multiscatter: %d pixels at confidence above 0.5, compensation up to x%.3f\n", seen,
                        compensation);
            EXPECT_GT(seen, 300);
            EXPECT_GT(compensation, 1.03);
        } else {
            EXPECT_GT(full, 500);
            EXPECT_GT(blended, 100);
        }
    }
}

// The weight of SSR's radiance at grazing views, where the Museum's floor is seen (NoV 0.1-0.45). A glossy dielectric
// floor (roughness 0.1, KHR_materials_specular strength 0.5: F0 0.02, F90 0.5) before an emissive wall of radiance L
// (black, no specular: it only emits), camera 0.5 m above the floor: every floor pixel's mirror ray meets the wall on
// screen, and the lobe (GGX alpha 0.01) lies on it whole. Where SSR is fully confident the term is E L vertexAO
// cavity, E the lobe's directional albedo, integrated here from core/shading's BRDF (lobeAlbedo, per pixel's NoV
// and roughness). With brdf_lut (ibl.capture's split-sum LUT, which
// ibl.localized weighs the probes with) each pixel within 2 % of it; without, ssr.composite weighs by Karis' fit,
// which is 12-17 % low there (measured here; issue 26: the Museum's floor reflected the colonnade too dark), and
// the test says how far it is.
// The specular lobe's directional albedo at NoV: the integral of core/shading's brdfCosineF0F90 (no diffuse) over
// the hemisphere, in the half-vector domain (a lobe of GGX alpha 0.01 is far narrower than any grid over l): a
// 256 x 128 midpoint rule over the GGX distribution's CDF in theta_h (tan^2 theta_h = alpha^2 u / (1 - u)) and
// uniform phi, l = reflect(-v, h), each cell weighed by brdfCosine / pdf(l), pdf(l) = D(h) NoH / (4 VoH).
double lobeAlbedo(double NoV, float roughness, float f0, float f90) {
    const float alpha = shading::ggxAlpha(roughness);
    const glm::vec3 n(0.0f, 0.0f, 1.0f), v(float(std::sqrt(1.0 - NoV * NoV)), 0.0f, float(NoV));
    const int nu = 256, nphi = 128;
    double sum = 0.0;
    for (int i = 0; i < nu; ++i) {
        const double u = (i + 0.5) / nu;
        const double tanTheta = alpha * std::sqrt(u / (1.0 - u));
        const double cosTheta = 1.0 / std::sqrt(1.0 + tanTheta * tanTheta), sinTheta = tanTheta * cosTheta;
        for (int j = 0; j < nphi; ++j) {
            const double phi = 2.0 * kPi * (j + 0.5) / nphi;
            const glm::vec3 h(float(sinTheta * std::cos(phi)), float(sinTheta * std::sin(phi)), float(cosTheta));
            const float VoH = glm::dot(v, h);
            if (VoH <= 0.0f) continue;
            const glm::vec3 l = 2.0f * VoH * h - v;
            if (l.z <= 0.0f) continue;
            const double pdf = shading::ggxD(float(cosTheta), alpha) * cosTheta / (4.0 * VoH);
            sum += shading::brdfCosineF0F90(n, v, l, glm::vec3(0.0f), glm::vec3(f0), f90, roughness).g / pdf;
        }
    }
    return sum / (double(nu) * nphi);
}

TEST_F(Ssr, CompositeWeighsReflectionsByTheLobesAlbedoAtGrazingViews) {
    const int W = 96, H = 64;
    SceneBuilder b("ssr_grazing_albedo");
    std::vector<Tri> floorTris, wallTris;
    addQuad(floorTris, {0.0f, 0.0f, 1.5f}, {10.0f, 0.0f, 0.0f}, {0.0f, 0.0f, 4.5f}, {0, 1, 0});
    addQuad(wallTris, {0.0f, 4.0f, -3.0f}, {10.0f, 0.0f, 0.0f}, {0.0f, 4.0f, 0.0f}, {0, 0, 1});
    const uint32_t floorMat = b.material("floor", glm::vec3(0.5f), 0.0f, 0.9f);
    b.s.materials[floorMat].specular = 0.5f;
    const uint32_t wallMat = b.material("emitter", glm::vec3(0.0f), 0.0f, 0.5f);
    b.s.materials[wallMat].specular = 0.0f;
    b.s.materials[wallMat].emissiveFactor = glm::vec3(800.0f, 500.0f, 300.0f);
    b.node("floor", static_cast<int32_t>(b.mesh("floor", floorTris, floorMat)));
    b.node("wall", static_cast<int32_t>(b.mesh("wall", wallTris, wallMat)));
    b.camera({0.0f, 0.5f, 4.0f}, {0.0f, 0.3f, -1.0f}, 0.9f);
    b.sun({0.3f, 1.0f, 0.6f});
    const auto glb = b.write();
    const Pinhole cam(b.s, W, H);

    auto run = [&](bool lut) {
        json nodes = ssrNodes(glb, {{"resolution_scale", 1.0}});
        nodes.erase("coords");
        nodes["lighting"] = lightingNode(json::object(), false);
        nodes["pyramid"]["in"]["color"] = "lighting.color";
        nodes["composite"] = compositeNode("ssr.reflection");
        if (lut) {
            nodes["capture"] = {{"type", "ibl.capture"},
                                {"in", {{"scene", "scene.scene"}, {"sky", "sky.cubemap"}, {"sky_sh", "sky.sh"}}},
                                {"params", {{"lut_samples", 4096}}}};
            nodes["composite"]["in"]["brdf_lut"] = "capture.brdf_lut";
        }
        json outputs = {{"lit", "lighting.color"},        {"ssr", "ssr.reflection"},
                        {"normal", "gbuffer.normal"},     {"base", "gbuffer.base_color"},
                        {"material", "gbuffer.material"}, {"term", "composite.specular_indirect"}};
        return runGraph(graph(nodes, outputs, W, H));
    };
    struct Stats {
        int n = 0;
        double sum = 0.0, worst = 0.0, minNoV = 1.0, maxNoV = 0.0;
    };
    auto measure = [&](const std::map<std::string, Image>& out) {
        // The wall's radiance as lighting.deferred wrote it: a pixel near the top centre.
        const glm::dvec3 wall = rgb(out.at("lit"), W / 2, 2);
        EXPECT_GT(wall.b, 1.0);
        std::map<std::pair<int, int>, double> albedo; // by (NoV, roughness) in 1/512 steps
        Stats st;
        for (int y = 0; y < H; ++y)
            for (int x = 4; x < W - 4; ++x) {
                const float* g0 = out.at("normal").at(x, y);
                const glm::vec3 n = shading::octDecode({g0[0], g0[1]});
                // The floor, where SSR is sure and read the wall (not, a pixel or two from the wall's foot, the floor
                // beside its hit: where a hit lands is other tests' business).
                const float* r = out.at("ssr").at(x, y);
                if (g0[2] <= 0.0f || n.y < 0.999f || r[3] < 0.999f || std::abs(r[1] / r[3] / wall.g - 1.0) > 0.01)
                    continue;
                const glm::dvec3 d = cam.ray(x, y);
                const float* g1 = out.at("base").at(x, y);
                const float* g2 = out.at("material").at(x, y);
                const float NoV = std::clamp(float(glm::dot(glm::dvec3(n), -d)), 1e-4f, 1.0f);
                const float roughness = shading::roughnessFromShininess(g0[3]);
                const glm::vec4 dielectric =
                    shading::dielectricSpecular(0.04f, glm::vec4(glm::vec3(1.0f), 1.0f - g2[1]));
                const glm::vec3 f0 = shading::specularF0With({g1[0], g1[1], g1[2]}, g1[3], 0.04f, dielectric);
                const float f90 = shading::specularF90(g1[3], dielectric);
                const auto key = std::make_pair(int(std::lround(NoV * 512.0f)), int(std::lround(roughness * 512.0f)));
                auto it = albedo.find(key);
                if (it == albedo.end())
                    it = albedo.emplace(key, lobeAlbedo(key.first / 512.0, key.second / 512.0f, f0.g, f90)).first;
                const double expected = it->second * wall.g * double(g2[2] * g2[3]);
                const double ratio = rgb(out.at("term"), x, y).g / expected;
                st.sum += ratio;
                st.worst = std::max(st.worst, std::abs(ratio - 1.0));
                st.minNoV = std::min(st.minNoV, double(NoV));
                st.maxNoV = std::max(st.maxNoV, double(NoV));
                ++st.n;
            }
        return st;
    };
    const Stats withLut = measure(run(true)), karis = measure(run(false));
    std::printf("SSR term / (lobe albedo x wall radiance) over %d floor pixels, NoV %.2f-%.2f: with the LUT mean "
                "%.4f, worst %.4f off; with Karis' fit (%d pixels) mean %.4f, worst %.4f off\n",
                withLut.n, withLut.minNoV, withLut.maxNoV, withLut.sum / std::max(withLut.n, 1), withLut.worst, karis.n,
                karis.sum / std::max(karis.n, 1), karis.worst);
    ASSERT_GT(withLut.n, 2000);
    EXPECT_LT(withLut.minNoV, 0.15);
    EXPECT_GT(withLut.maxNoV, 0.35);
    EXPECT_NEAR(withLut.sum / withLut.n, 1.0, 0.01);
    EXPECT_LT(withLut.worst, 0.02);
    // Karis' fit: what the composite did before, and still does without the LUT (a sky- or volume-lit I).
    ASSERT_GT(karis.n, 2000);
    EXPECT_LT(karis.sum / karis.n, 0.92);
}

// Pixels that found nothing must not darken the reflection of those that did. A glossy floor (roughness 0.15: one
// GGX ray per pixel, a new one each frame) reflects a world of one colour C (the pyramid is uniform), so every hit
// reads C and the rays that leave the screen or the wall find nothing: hits and misses mix at half resolution, in
// the temporal mean of 4 frames and in the composite's bilinear upsampling. Whatever that mix's confidence c, the
// reflection it blends in is C: every floor pixel's specular_indirect must be I (1 - c) + E C vertexAO cavity c, with
// c the bilinear mix of the accumulated confidences and E Karis' environment BRDF from core/shading. (Filtering
// radiance and confidence apart, as before 2026-12-05, gave C times the share of hits in the mix: up to 100 % too
// dark at the border of a miss, and "+"-shaped dark rings across the Museum's floor.)
TEST_F(Ssr, MissesDoNotDarkenTheReflectionOfTheHits) {
    MirrorScene m(0.85f, 0.8f, true);
    const int W = MirrorScene::W, H = MirrorScene::H;
    json nodes = m.nodes({{"resolution_scale", 0.5},
                          {"max_taps", 64},
                          {"thickness", kThickness},
                          {"max_distance", kMaxDistance},
                          {"edge_fade", kEdgeFade}},
                         "test.ssr_uniform");
    nodes["lighting"] = lightingNode(json::object(), false);
    nodes["accumulate"] = {{"type", "temporal.accumulate"},
                           {"in",
                            {{"color", "ssr.reflection"},
                             {"history", "accumulate.color@prev"},
                             {"history_samples", "accumulate.samples@prev"}}}};
    nodes["composite"] = compositeNode("accumulate.color");
    json g = graph(nodes,
                   {{"color", "lighting.color"},
                    {"spec", "lighting.specular_indirect"},
                    {"ssr", "accumulate.color"},
                    {"normal", "gbuffer.normal"},
                    {"base", "gbuffer.base_color"},
                    {"material", "gbuffer.material"},
                    {"term", "composite.specular_indirect"}},
                   W, H);
    g["frame"]["frames"] = 4;
    auto out = runGraph(g);
    const Image& ssr = out.at("ssr");
    ASSERT_EQ(ssr.width, W / 2);
    auto confidence = [&](int x, int y) {
        return double(ssr.at(std::clamp(x, 0, ssr.width - 1), std::clamp(y, 0, ssr.height - 1))[3]);
    };
    int checked = 0, beside = 0, wrong = 0;
    double worst = 0.0, darkest = 1.0;
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            const float* g0 = out.at("normal").at(x, y);
            if (g0[2] <= 0.0f || m.trace(m.cam->position, m.cam->ray(x, y)).second != Hit::Floor) continue;
            // Half-resolution texel q stands for pixel 2q: pixel p reads p / 2, between two texels when odd.
            const int x0 = x / 2, y0 = y / 2, x1 = (x + 1) / 2, y1 = (y + 1) / 2;
            const double taps[4] = {confidence(x0, y0), confidence(x1, y0), confidence(x0, y1), confidence(x1, y1)};
            const double c = std::clamp(0.25 * (taps[0] + taps[1] + taps[2] + taps[3]), 0.0, 1.0);
            if (c < 0.05) continue;
            const bool besideAMiss = *std::min_element(taps, taps + 4) < 0.02;
            const glm::dvec3 spec = rgb(out.at("spec"), x, y), got = rgb(out.at("term"), x, y);
            const glm::dvec3 ssrPart = weightOfSsr(out, m, x, y) * kUniformColour * c;
            const glm::dvec3 expected = spec * (1.0 - c) + ssrPart;
            ++checked;
            if (besideAMiss) ++beside;
            bool bad = false;
            for (int k = 0; k < 3; ++k) {
                const double err = std::abs(got[k] - expected[k]) / (std::abs(expected[k]) + 1e-6);
                worst = std::max(worst, err);
                bad = bad || err > 1e-2;
            }
            // The reflected colour this pixel blended in, in units of C (1 when right), where it is most of the term.
            if (glm::dot(ssrPart, glm::dvec3(1.0)) > glm::dot(spec * (1.0 - c), glm::dvec3(1.0)))
                darkest = std::min(darkest, glm::dot(got - spec * (1.0 - c), glm::dvec3(1.0)) /
                                                glm::dot(ssrPart, glm::dvec3(1.0)));
            if (bad && ++wrong <= 5)
                ADD_FAILURE() << "pixel " << x << "," << y << " (confidence " << c
                              << (besideAMiss ? ", beside a miss" : "") << "): specular_indirect " << got.x << ","
                              << got.y << "," << got.z << ", expected " << expected.x << "," << expected.y << ","
                              << expected.z;
        }
    std::printf("misses: %d floor pixels with confidence, %d of them beside a miss; %d wrong; largest relative error "
                "%.2g; darkest reflection %.3f of C\n",
                checked, beside, wrong, worst, darkest);
    EXPECT_EQ(wrong, 0);
    EXPECT_GT(checked, 1000);
    EXPECT_GT(beside, 100) << "the floor must mix hits with misses for this test to mean anything";
}

// Cone tracing: on a rough floor (roughness 0.4: two rays, cones of tan 1.29 alpha / sqrt 2 = 0.15) every hit's
// footprint is several pixels wide (2 x distance x 0.15 over a pixel's ~2.4 cm at 6 m: > 2 px beyond 0.25 m), so the
// pyramid is read at level 1 or coarser, where a one-pixel checkerboard is exactly 0.5; read at level 0 it is not.
TEST_F(Ssr, ConeFootprintSelectsACoarsePyramidLevel) {
    MirrorScene m(0.6f);
    json params = mirrorParams(64);
    params["max_roughness"] = 1.0;
    auto out = runGraph(graph(m.nodes(params, "test.ssr_checker"), {{"ssr", "ssr.reflection"}, {"normal", "gbuffer.normal"}},
                              MirrorScene::W, MirrorScene::H));
    const Image& ssr = out.at("ssr");
    int hits = 0;
    double meanDev = 0.0, worstDev = 0.0;
    for (int y = 0; y < MirrorScene::H; ++y)
        for (int x = 0; x < MirrorScene::W; ++x) {
            const glm::dvec4 got = reflectionRead(ssr, x, y);
            glm::dvec3 d = m.cam->ray(x, y);
            if (m.trace(m.cam->position, d).second != Hit::Floor || got[3] < 0.2f) continue;
            // Hits within 8 px of their pixel may be short enough for a sub-2-px cone: not counted.
            if (std::hypot(got[1] - (x + 0.5), got[2] - (y + 0.5)) < 8.0) continue;
            ++hits;
            double dev = std::abs(got[0] - 0.5);
            meanDev += dev;
            worstDev = std::max(worstDev, dev);
        }
    meanDev /= std::max(hits, 1);
    std::printf("cone: %d floor pixels with hits; checker read as 0.5 +- %.4f on average, %.4f at worst\n", hits,
                meanDev, worstDev);
    // The rays are GGX samples, not the mirror direction: the mean hit strays from the mirror image by pixels.
    double spread = 0.0;
    int counted = 0;
    for (int y = 0; y < MirrorScene::H; ++y)
        for (int x = 0; x < MirrorScene::W; ++x) {
            const glm::dvec4 got = reflectionRead(ssr, x, y);
            glm::dvec3 d = m.cam->ray(x, y);
            auto [t, what] = m.trace(m.cam->position, d);
            if (what != Hit::Floor || got[3] < 0.5f) continue;
            glm::dvec3 p = m.cam->position + t * d, r(d.x, -d.y, d.z);
            auto [tr, hit] = m.trace(p, r);
            if (hit != Hit::Wall) continue;
            glm::dvec3 sc = m.project(p + r * tr);
            spread += std::hypot(got[1] - sc.x, got[2] - sc.y);
            ++counted;
        }
    spread /= std::max(counted, 1);
    std::printf("cone: the mean hit of %d pixels lies %.2f px from the mirror image on average\n", counted, spread);
    EXPECT_GT(counted, 500);
    EXPECT_GT(spread, 1.5);
    EXPECT_GT(hits, 1000);
    EXPECT_LT(meanDev, 0.02);
}

// Where reflections matter: a glossy metal floor (roughness 0.25, two rays a pixel) under a sunlit wall, tone
// mapped alike, against render.pathtrace of the same scene, camera, sky and sun (64 samples a pixel). Without SSR
// the floor reflects the sky (lighting.deferred's indirect specular); with it, the wall, as the path tracer does.
// LDR-FLIP over the whole image must drop with SSR by at least 0.04 and stay under 0.42 (measured 0.404 with
// SSR, 0.471 without: most of what remains is the deferred path's missing global illumination, which the path
// tracer has and this graph, without bake.lightmap, does not).
TEST_F(Ssr, ReducesTheFlipErrorAgainstThePathTracedReference) {
    MirrorScene m(0.75f);
    const int W = MirrorScene::W, H = MirrorScene::H;
    json nodes = baseNodes(m.glb);
    nodes["lighting"] = lightingNode({{"sky_ambient", 1.0}}, false);
    addSsrChain(nodes, "lighting.color");
    nodes["composite"] = compositeNode("ssr.reflection");
    nodes["env_cdf"] = {{"type", "sky.env_cdf"}, {"in", {{"sky", "sky.cubemap"}}}};
    nodes["pt"] = {{"type", "render.pathtrace"},
                   {"in",
                    {{"scene", "scene.scene"},
                     {"camera", "scene.camera"},
                     {"sky", "sky.cubemap"},
                     {"sky_sh", "sky.sh"},
                     {"env_cdf", "env_cdf.cdf"}}},
                   {"params", {{"spp", 64}, {"max_bounces", 4}}}};
    auto tonemap = [](const char* input) {
        return json{{"type", "post.tonemap"},
                    {"in", {{"color", input}}},
                    {"params", {{"operator", "aces_fit"}, {"exposure", -14.0}}}};
    };
    nodes["tm_ssr"] = tonemap("composite.color");
    nodes["tm_no_ssr"] = tonemap("lighting.color");
    nodes["tm_ref"] = tonemap("pt.color");
    auto out = runGraph(graph(nodes, {{"ssr", "tm_ssr.color"}, {"no_ssr", "tm_no_ssr.color"}, {"ref", "tm_ref.color"}},
                              W, H));
    double with = compare::ldrFlip(out.at("ref"), out.at("ssr")).mean;
    double without = compare::ldrFlip(out.at("ref"), out.at("no_ssr")).mean;
    std::printf("FLIP against the path tracer: %.4f with SSR, %.4f without\n", with, without);
    EXPECT_LT(with, without - 0.04);
    EXPECT_LT(with, 0.42);
}

// Back faces: a mirror floor in front of a shelf (a single-sided plane at 1 m, its top facing the camera above
// it). Mirror rays from the floor in front rise into the shelf's underside; on screen they meet the shelf's top at
// the same depth, whose normal faces along the ray: the back-face test gives them no confidence.
TEST_F(Ssr, RaysIntoABackFaceHaveNoConfidence) {
    const int W = 128, H = 96;
    const double shelfY = 1.0, shelfNear = -1.0, shelfFar = -3.0;
    SceneBuilder b("ssr_shelf");
    std::vector<Tri> floorTris, shelfTris;
    addQuad(floorTris, {0.0f, 0.0f, 1.5f}, {6.0f, 0.0f, 0.0f}, {0.0f, 0.0f, 4.5f}, {0, 1, 0});
    addQuad(shelfTris, {0.0f, 1.0f, -2.0f}, {6.0f, 0.0f, 0.0f}, {0.0f, 0.0f, 1.0f}, {0, 1, 0});
    b.node("floor", static_cast<int32_t>(b.mesh("floor", floorTris, b.material("mirror", glm::vec3(0.9f), 1.0f, 1.0f))));
    b.node("shelf", static_cast<int32_t>(b.mesh("shelf", shelfTris, b.material("matte", glm::vec3(0.5f), 0.0f, 0.5f))));
    b.camera({0.3f, 2.6f, 4.5f}, {0.0f, 0.5f, -1.0f}, 0.9f);
    b.sun({0.3f, 1.0f, 0.6f});
    auto glb = b.write();
    Pinhole cam(b.s, W, H);
    json nodes = ssrNodes(glb, mirrorParams(64));
    auto out = runGraph(graph(nodes, {{"ssr", "ssr.reflection"}}, W, H));
    const Image& ssr = out.at("ssr");
    int intoBack = 0, confident = 0;
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            glm::dvec3 d = cam.ray(x, y);
            if (d.y >= 0.0) continue;
            glm::dvec3 p = cam.position + (-cam.position.y / d.y) * d;
            // The floor, seen in front of the shelf (which hides what lies behind its near edge), 0.2 m clear of it.
            double tShelf = (shelfY - cam.position.y) / d.y;
            glm::dvec3 q = cam.position + tShelf * d;
            if (std::abs(q.x) < 6.0 && q.z < shelfNear + 0.2) continue;
            if (std::abs(p.x) > 5.0) continue;
            glm::dvec3 r(d.x, -d.y, d.z);
            glm::dvec3 h = p + r * (shelfY / r.y);
            if (std::abs(h.x) > 5.5 || h.z > shelfNear - 0.2 || h.z < shelfFar + 0.2 || glm::length(h - p) > 4.0)
                continue;
            ++intoBack;
            if (ssr.at(x, y)[3] >= 0.02f) ++confident;
        }
    std::printf("back faces: %d floor pixels reflect into the shelf's underside, %d of them with confidence >= "
                "0.02\n",
                intoBack, confident);
    EXPECT_GT(intoBack, 200);
    EXPECT_LE(confident, intoBack / 20);
}

// Reprojection: with gbuffer.velocity connected, from the second frame on a hit is read where it was last frame
// (the colour pyramid holds last frame's colour). The camera slides 0.4 m sideways between frames 0 and 1 and the
// pyramid holds every pixel's own coordinates, so on frame 1 a mirror reflection must read the analytic hit's
// position in frame 0's view (within 1 px), which lies pixels away from its position in frame 1's.
TEST_F(Ssr, VelocityReprojectsHitsIntoLastFrame) {
    MirrorScene m(1.0f, 1.0f, false, glm::vec3(0.4f, 0.0f, 0.0f));
    json nodes = m.nodes(mirrorParams(64));
    nodes["ssr"]["in"]["velocity"] = "gbuffer.velocity";
    json g = graph(nodes, {{"ssr", "ssr.reflection"}}, MirrorScene::W, MirrorScene::H);
    g["frame"]["frames"] = 2;
    auto out = runGraph(g);
    const Image& ssr = out.at("ssr");
    const Pinhole cam0 = *m.cam;
    m.cam->position += glm::dvec3(0.4, 0.0, 0.0); // frame 1's camera: classify() and project() use it
    int checked = 0, wrong = 0;
    double moved = 0.0, worst = 0.0;
    for (int y = 0; y < MirrorScene::H; ++y)
        for (int x = 0; x < MirrorScene::W; ++x) {
            glm::dvec3 d = m.cam->ray(x, y);
            auto [t, what] = m.trace(m.cam->position, d);
            if (what != Hit::Floor) continue;
            glm::dvec3 p = m.cam->position + t * d;
            glm::dvec3 r(d.x, -d.y, d.z);
            auto [tr, hit] = m.trace(p, r);
            if (hit != Hit::Wall || tr > 0.75 * kMaxDistance) continue;
            if (m.classify(p, p + r * tr, 2.0 * kThickness + 0.05) != MirrorScene::Path::Clear) continue;
            glm::dvec3 h = p + r * tr;
            glm::dvec3 now = m.project(h), before = MirrorScene::projectWith(cam0, h);
            auto inside = [](glm::dvec3 s) {
                return s.x >= 8 && s.y >= 8 && s.x <= MirrorScene::W - 8 && s.y <= MirrorScene::H - 8;
            };
            if (!inside(now) || !inside(before) || std::hypot(now.x - (x + 0.5), now.y - (y + 0.5)) < 3.0) continue;
            const glm::dvec4 got = reflectionRead(ssr, x, y);
            if (got[3] < 0.5f) {
                ++wrong;
                continue;
            }
            ++checked;
            moved += std::hypot(now.x - before.x, now.y - before.y);
            double err = std::hypot(got[0] - before.x, got[1] - before.y);
            if (err > 1.0) ++wrong;
            else worst = std::max(worst, err);
        }
    moved /= std::max(checked, 1);
    std::printf("reprojection: %d mirror hits checked, mean motion of the hit %.2f px, %d off by over 1 px from its "
                "last-frame position (or without confidence); of the others the largest error %.3f px\n",
                checked, moved, wrong, worst);
    EXPECT_GT(checked, 500);
    EXPECT_GT(moved, 3.0);
    EXPECT_LE(wrong, checked / 20);
}

// Ray directions: GGX visible normals [Heitz18]. A rough metal floor (roughness 0.5: 3 rays per pixel) in front of a
// large wall; every ray that leaves the floor upwards and meets the wall on screen is a hit whose confidence is the
// edge and length fades there, a ray reflected below the horizon none. The mean confidence over the floor must equal
// the integral of those fades over the visible-normal distribution D_v(h) = G1(v) max(0, v.h) D(h) / (n.v), evaluated
// here on a grid of half vectors. Sampling the plain NDF around the normal instead (ignoring the view) sends far more
// rays below the horizon at grazing angles and reads a different part of the wall. Also the mean over the floor of
// confidence x the position each ray read (the pyramid holds pixel coordinates) against the same integral.
TEST_F(Ssr, RoughRaysFollowTheVisibleNormalDistribution) {
    const int W = 128, H = 96;
    const double wallZ = -5.0, halfWidth = 8.0, wallTop = 10.0, maxDistance = 30.0, edgeFade = 0.05;
    SceneBuilder b("ssr_rough");
    std::vector<Tri> floorTris, wallTris;
    addQuad(floorTris, {0.0f, 0.0f, 0.0f}, {8.0f, 0.0f, 0.0f}, {0.0f, 0.0f, 5.0f}, {0, 1, 0});
    addQuad(wallTris, {0.0f, 5.0f, -5.0f}, {8.0f, 0.0f, 0.0f}, {0.0f, 5.0f, 0.0f}, {0, 0, 1});
    b.node("floor", static_cast<int32_t>(b.mesh("floor", floorTris, b.material("rough", glm::vec3(0.9f), 1.0f, 0.5f))));
    b.node("wall", static_cast<int32_t>(b.mesh("wall", wallTris, b.material("matte", glm::vec3(0.5f), 0.0f, 0.5f))));
    b.camera({0.0f, 1.2f, 4.0f}, {0.0f, 0.9f, -1.0f}, 1.2f);
    b.sun({0.3f, 1.0f, 0.6f});
    auto glb = b.write();
    Pinhole cam(b.s, W, H);
    json nodes = ssrNodes(glb, {{"resolution_scale", 1.0},
                                {"max_taps", 64},
                                {"thickness", 0.2},
                                {"max_distance", maxDistance},
                                {"edge_fade", edgeFade},
                                {"max_roughness", 1.0}});
    auto out = runGraph(graph(nodes, {{"ssr", "ssr.reflection"}, {"normal", "gbuffer.normal"}}, W, H));
    const Image& ssr = out.at("ssr");
    const Image& normal = out.at("normal");
    const double tanHalf = std::tan(0.5 * cam.yfov), aspect = double(W) / H;
    // The confidence of a ray from p along r (the edge and length fades where it meets the wall on screen) and the
    // pixel position of that hit (what the coordinates pyramid returns there).
    auto fades = [&](glm::dvec3 p, glm::dvec3 r, glm::dvec2& pixel) {
        if (r.y <= 0.0 || r.z >= 0.0) return 0.0;
        double t = (wallZ - p.z) / r.z;
        glm::dvec3 h = p + t * r;
        if (std::abs(h.x) > halfWidth || h.y > wallTop) return 0.0;
        glm::dvec3 c = glm::conjugate(cam.orientation) * (h - cam.position);
        glm::dvec2 uv((c.x / -c.z / (tanHalf * aspect)) * 0.5 + 0.5, (-c.y / -c.z / tanHalf) * 0.5 + 0.5);
        double edge = std::min({uv.x, uv.y, 1.0 - uv.x, 1.0 - uv.y});
        if (c.z >= 0.0 || edge <= 0.0) return 0.0;
        pixel = uv * glm::dvec2(W, H);
        return std::clamp(edge / edgeFade, 0.0, 1.0) * std::clamp((maxDistance - t) / (0.25 * maxDistance), 0.0, 1.0);
    };
    const int nTheta = 96, nPhi = 192;
    double sumGot = 0.0, sumExpected = 0.0, sumBelow = 0.0;
    glm::dvec2 sumGotPixel(0.0), sumExpectedPixel(0.0); // confidence x hit position
    int pixels = 0;
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            glm::dvec3 d = cam.ray(x, y);
            if (d.y >= 0.0) continue;
            glm::dvec3 p = cam.position + (-cam.position.y / d.y) * d;
            if (std::abs(p.x) > 6.0 || p.z < -3.5 || p.z > 3.0) continue;
            // The roughness the G-buffer stored (shininess in UNORM8 or half precision).
            const double roughness = 1.0 - normal.at(x, y)[3];
            const double alpha = std::max(roughness * roughness, 1e-3), a2 = alpha * alpha;
            const glm::dvec3 v = -d;
            const double nv = v.y;
            const double g1 = 2.0 * nv / (nv + std::sqrt(a2 + (1.0 - a2) * nv * nv));
            double expected = 0.0, below = 0.0, total = 0.0;
            glm::dvec2 expectedPixel(0.0);
            for (int i = 0; i < nTheta; ++i) {
                double theta = (i + 0.5) / nTheta * 0.5 * kPi, ct = std::cos(theta), st = std::sin(theta);
                double den = ct * ct * (a2 - 1.0) + 1.0;
                double D = a2 / (kPi * den * den);
                for (int j = 0; j < nPhi; ++j) {
                    double phi = (j + 0.5) / nPhi * 2.0 * kPi;
                    glm::dvec3 h(st * std::cos(phi), ct, st * std::sin(phi));
                    double vh = glm::dot(v, h);
                    if (vh <= 0.0) continue;
                    double w = g1 * vh * D / nv * st * (0.5 * kPi / nTheta) * (2.0 * kPi / nPhi);
                    glm::dvec3 r = 2.0 * vh * h - v;
                    total += w;
                    if (r.y <= 0.0) below += w;
                    else {
                        glm::dvec2 pixel(0.0);
                        double c = fades(p, r, pixel);
                        expected += w * c;
                        expectedPixel += w * c * pixel;
                    }
                }
            }
            ASSERT_NEAR(total, 1.0, 0.02) << "the visible-normal density integrates to 1";
            sumExpected += expected / total;
            sumBelow += below / total;
            sumGot += ssr.at(x, y)[3];
            sumExpectedPixel += expectedPixel / total;
            // rgb is premultiplied: the confidence-weighted mean of the rays' reads times the mean confidence, i.e.
            // the mean over the rays of confidence x position, an unbiased estimate of expectedPixel.
            sumGotPixel += glm::dvec2(ssr.at(x, y)[0], ssr.at(x, y)[1]);
            ++pixels;
        }
    const double got = sumGot / pixels, expected = sumExpected / pixels;
    const glm::dvec2 gotPixel = sumGotPixel / double(pixels), expectedPixel = sumExpectedPixel / double(pixels);
    std::printf("rough floor: mean confidence x hit position (%.2f, %.2f) px, expected (%.2f, %.2f)\n", gotPixel.x,
                gotPixel.y, expectedPixel.x, expectedPixel.y);
    std::printf("rough floor: %d pixels, mean confidence %.4f, expected from the visible-normal distribution %.4f (of "
                "which below the horizon %.4f)\n",
                pixels, got, expected, sumBelow / pixels);
    EXPECT_GT(pixels, 2000);
    EXPECT_NEAR(got, expected, 0.02);
    // Where the rays land: sampling the plain NDF around the normal reads the wall 1.3 px lower on average here.
    EXPECT_NEAR(gotPixel.x, expectedPixel.x, 1.0);
    EXPECT_NEAR(gotPixel.y, expectedPixel.y, 0.5);
}

// Thickness: a mirror wall facing the camera 7 m away and a card 1.5 m in front of it, off to the right. Mirror rays
// from the wall just left of the card come back towards the camera and outwards, and meet the card's back, which the
// camera cannot see: on screen they reach the card's pixels from behind and are found only at the back of its slab
// (`thickness` behind its depth). The card's normals are turned to face those rays (test.ssr_normals), so the
// back-face test passes them: the thickness fade alone must leave them without confidence.
TEST_F(Ssr, RaysFoundAtTheBackOfASlabHaveNoConfidence) {
    const int W = 192, H = 144;
    const double mirrorZ = -3.0, cardZ = -1.5;
    const glm::dvec2 cardLo(0.8, 1.0), cardHi(1.8, 2.0);
    SceneBuilder b("ssr_slab");
    std::vector<Tri> mirrorTris, cardTris;
    addQuad(mirrorTris, {0.0f, 1.5f, -3.0f}, {4.0f, 0.0f, 0.0f}, {0.0f, 3.0f, 0.0f}, {0, 0, 1});
    addQuad(cardTris, {1.3f, 1.5f, -1.5f}, {0.5f, 0.0f, 0.0f}, {0.0f, 0.5f, 0.0f}, {0, 0, 1});
    b.node("mirror", static_cast<int32_t>(b.mesh("mirror", mirrorTris, b.material("mirror", glm::vec3(0.9f), 1.0f, 1.0f))));
    b.node("card", static_cast<int32_t>(b.mesh("card", cardTris, b.material("matte", glm::vec3(0.5f), 0.0f, 0.5f))));
    b.camera({0.0f, 1.5f, 4.0f}, {0.0f, 1.5f, -3.0f}, 0.9f);
    b.sun({0.3f, 1.0f, 0.6f});
    auto glb = b.write();
    Pinhole cam(b.s, W, H);
    json nodes = ssrNodes(glb, mirrorParams(64));
    nodes["normals"] = {{"type", "test.ssr_normals"},
                        {"in", {{"normal", "gbuffer.normal"}}},
                        {"params", {{"near", 5.0}, {"far", 6.0}, {"normal", {0.0, 0.0, -1.0}}}}};
    nodes["ssr"]["in"]["normal"] = "normals.result";
    auto out = runGraph(graph(nodes, {{"ssr", "ssr.reflection"}}, W, H));
    const Image& ssr = out.at("ssr");
    auto inCard = [&](glm::dvec3 p) { return p.x >= cardLo.x && p.x <= cardHi.x && p.y >= cardLo.y && p.y <= cardHi.y; };
    int intoBack = 0, confident = 0, elsewhere = 0, confidentElsewhere = 0;
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            glm::dvec3 d = cam.ray(x, y);
            if (d.z >= 0.0) continue;
            if (inCard(cam.position + d * ((cardZ - cam.position.z) / d.z))) continue; // the card hides the mirror
            glm::dvec3 p = cam.position + d * ((mirrorZ - cam.position.z) / d.z);
            if (std::abs(p.x) > 3.8 || std::abs(p.y - 1.5) > 2.8) continue;
            glm::dvec3 r(d.x, d.y, -d.z);
            glm::dvec3 q = p + r * ((cardZ - p.z) / r.z);
            // Clear of the card's edges by 0.1 m, where a march may legitimately slip past or catch its silhouette.
            const glm::dvec2 margin(0.1);
            if (q.x >= cardLo.x + margin.x && q.x <= cardHi.x - margin.x && q.y >= cardLo.y + margin.y &&
                q.y <= cardHi.y - margin.y) {
                ++intoBack;
                if (ssr.at(x, y)[3] >= 0.1f) ++confident;
            } else if (q.x < cardLo.x - 0.3 || q.y < cardLo.y - 0.3 || q.y > cardHi.y + 0.3) {
                // Rays that pass the card well clear of it come back towards the camera and leave the screen or
                // reach the near plane: nothing to find.
                ++elsewhere;
                if (ssr.at(x, y)[3] >= 0.1f) ++confidentElsewhere;
            }
        }
    std::printf("slab: %d mirror rays meet the card's hidden back, %d of them with confidence >= 0.1 (%d rays "
                "clear of the card, %d with confidence)\n",
                intoBack, confident, elsewhere, confidentElsewhere);
    EXPECT_GE(intoBack, 60);
    EXPECT_LE(confident, intoBack / 10);
}

// Back faces within the slab: a low step (a single-sided plane 0.2 m above a mirror floor, its top facing the camera)
// in front of a wall, and surfaces 0.5 m thick. Mirror rays from the floor in front rise into the step's underside
// and are within its slab as they pass under its front edge on screen, where they cross its top: found there, whose
// normal faces along the ray, they must get no confidence — neither from the back-face test being skipped nor by
// marching on under the step (as a grazing self-hit would) to the wall behind it.
TEST_F(Ssr, RaysMeetingABackFaceWithinItsSlabStopThere) {
    const int W = 128, H = 96;
    const double stepY = 0.2, stepNear = -1.0, stepFar = -2.5;
    SceneBuilder b("ssr_step");
    std::vector<Tri> floorTris, stepTris, wallTris;
    addQuad(floorTris, {0.0f, 0.0f, 1.5f}, {6.0f, 0.0f, 0.0f}, {0.0f, 0.0f, 4.5f}, {0, 1, 0});
    addQuad(stepTris, {0.0f, 0.2f, -1.75f}, {6.0f, 0.0f, 0.0f}, {0.0f, 0.0f, 0.75f}, {0, 1, 0});
    addQuad(wallTris, {0.0f, 2.0f, -3.0f}, {6.0f, 0.0f, 0.0f}, {0.0f, 2.0f, 0.0f}, {0, 0, 1});
    b.node("floor", static_cast<int32_t>(b.mesh("floor", floorTris, b.material("mirror", glm::vec3(0.9f), 1.0f, 1.0f))));
    uint32_t matte = b.material("matte", glm::vec3(0.5f), 0.0f, 0.5f);
    b.node("step", static_cast<int32_t>(b.mesh("step", stepTris, matte)));
    b.node("wall", static_cast<int32_t>(b.mesh("wall", wallTris, matte)));
    b.camera({0.3f, 1.2f, 4.5f}, {0.0f, 0.3f, -1.0f}, 0.9f);
    b.sun({0.3f, 1.0f, 0.6f});
    auto glb = b.write();
    Pinhole cam(b.s, W, H);
    json params = mirrorParams(64);
    params["thickness"] = 0.5;
    json nodes = ssrNodes(glb, params);
    auto out = runGraph(graph(nodes, {{"ssr", "ssr.reflection"}}, W, H));
    const Image& ssr = out.at("ssr");
    int intoBack = 0, confident = 0;
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            glm::dvec3 d = cam.ray(x, y);
            if (d.y >= 0.0) continue;
            glm::dvec3 p = cam.position + (-cam.position.y / d.y) * d;
            if (std::abs(p.x) > 5.0 || p.z < stepNear + 0.3) continue; // the floor in front of the step
            glm::dvec3 r(d.x, -d.y, d.z);
            glm::dvec3 h = p + r * (stepY / r.y);
            if (std::abs(h.x) > 5.5 || h.z > stepNear - 0.2 || h.z < stepFar + 0.2) continue;
            ++intoBack;
            if (ssr.at(x, y)[3] >= 0.02f) ++confident;
        }
    std::printf("low step: %d floor pixels reflect into its underside, %d of them with confidence >= 0.02\n", intoBack,
                confident);
    EXPECT_GT(intoBack, 150);
    EXPECT_LE(confident, intoBack / 20);
}

// A glossy floor in front of a large wall, ssr.hiz reading test.ssr_levels (each pyramid level holds its own index, so
// r is the lod the march read at, g, b where it read). Cone tracing [Uludag14]: the lod is log2 of the footprint in
// pixels of a cone of half-angle tan 1.29 alpha / sqrt(rays) (alpha = roughness², one ray below roughness 0.2, two up
// to 0.4) at the hit: 2 x hit distance x tan over the pixel size at the hit's view depth, times cone_scale (1, and
// 0.5 on the rougher floor: one level finer wherever the footprint exceeds two pixels). Recomputed here for every
// floor pixel whose rays all met the wall, from the hit the ray read (g, b) cast back onto the wall and the floor point
// under the pixel; with two rays r and g, b are their means, and the lod at the mean hit differs from the mean lod by
// far less than the tolerance (the footprint changes slowly along the wall).
json levelNodes(const std::filesystem::path& glb, json params) {
    json nodes = ssrNodes(glb, params);
    nodes.erase("coords");
    nodes["pyramid"] = {{"type", "test.ssr_levels"}};
    nodes["ssr"]["in"]["color"] = "pyramid.result";
    return nodes;
}

struct GlossyWall {
    static constexpr int W = 128, H = 96;
    static constexpr double wallZ = -5.0;
    std::filesystem::path glb;
    std::optional<Pinhole> cam;
    explicit GlossyWall(float roughness) {
        SceneBuilder b("ssr_cone_" + std::to_string(int(roughness * 100.0f + 0.5f)));
        std::vector<Tri> floorTris, wallTris;
        addQuad(floorTris, {0.0f, 0.0f, 0.0f}, {8.0f, 0.0f, 0.0f}, {0.0f, 0.0f, 5.0f}, {0, 1, 0});
        addQuad(wallTris, {0.0f, 5.0f, -5.0f}, {8.0f, 0.0f, 0.0f}, {0.0f, 5.0f, 0.0f}, {0, 0, 1});
        b.node("floor", static_cast<int32_t>(b.mesh("floor", floorTris, b.material("gloss", glm::vec3(0.9f), 1.0f,
                                                                                     1.0f - roughness))));
        b.node("wall", static_cast<int32_t>(b.mesh("wall", wallTris, b.material("matte", glm::vec3(0.5f), 0.0f, 0.5f))));
        b.camera({0.0f, 1.2f, 4.0f}, {0.0f, 0.9f, -1.0f}, 1.0f);
        b.sun({0.3f, 1.0f, 0.6f});
        glb = b.write();
        cam.emplace(b.s, W, H);
    }
    // The camera ray through continuous pixel position px (pixel centres at +0.5).
    glm::dvec3 rayAt(glm::dvec2 px) const {
        const double tanHalf = std::tan(0.5 * cam->yfov), aspect = double(W) / H;
        glm::dvec2 ndc = px / glm::dvec2(W, H) * 2.0 - 1.0;
        return glm::normalize(cam->orientation * glm::dvec3(ndc.x * aspect * tanHalf, -ndc.y * tanHalf, -1.0));
    }
};

TEST_F(Ssr, ConeFootprintMatchesTheLobeAtTheHit) {
    const int W = GlossyWall::W, H = GlossyWall::H;
    const int levels = static_cast<int>(mipAtlasLevels(W, H));
    for (auto [roughness, scale] : {std::pair{0.15f, 1.0f}, std::pair{0.3f, 1.0f}, std::pair{0.3f, 0.5f}}) {
        SCOPED_TRACE("cone_scale " + std::to_string(scale));
        GlossyWall scene(roughness);
        const Pinhole& cam = *scene.cam;
        json params = {{"resolution_scale", 1.0}, {"max_taps", 64},       {"thickness", 0.2},   {"max_distance", 30.0},
                       {"edge_fade", 0.05},       {"max_roughness", 1.0}, {"cone_scale", scale}};
        auto out = runGraph(graph(levelNodes(scene.glb, params), {{"ssr", "ssr.reflection"}, {"normal", "gbuffer.normal"}},
                                  W, H));
        const Image& ssr = out.at("ssr");
        const glm::dvec3 forward = cam.orientation * glm::dvec3(0, 0, -1);
        const double focal = 0.5 * H / std::tan(0.5 * cam.yfov); // pixels per unit of tan at unit depth
        int checked = 0, wrong = 0;
        double worst = 0.0, meanLod = 0.0;
        for (int y = 0; y < H; ++y)
            for (int x = 0; x < W; ++x) {
                const glm::dvec4 got = reflectionRead(ssr, x, y);
                const glm::dvec3 d = cam.ray(x, y);
                if (d.y >= 0.0 || got[3] < 0.9f) continue; // every ray hit, away from the fades
                const glm::dvec3 p = cam.position + (-cam.position.y / d.y) * d;
                if (std::abs(p.x) > 6.0 || p.z > 3.0) continue;
                const glm::dvec3 e = scene.rayAt({got[1], got[2]});
                if (e.z >= 0.0) continue;
                const glm::dvec3 hit = cam.position + e * ((GlossyWall::wallZ - cam.position.z) / e.z);
                if (hit.y < 0.2 || std::abs(hit.x) > 7.0) continue; // on the wall, clear of the floor
                const double r = 1.0 - out.at("normal").at(x, y)[3]; // the roughness the G-buffer stored
                const int rays = std::clamp(int(std::ceil(r * 5.0)), 1, 4);
                const double alpha = std::max(r * r, double(shading::kMinGgxAlpha));
                const double coneTan = 1.29 * alpha / std::sqrt(double(rays));
                const double hitDepth = glm::dot(hit - cam.position, forward);
                const double pixels = scale * 2.0 * glm::length(hit - p) * coneTan * focal / hitDepth;
                const double expected = std::clamp(std::log2(std::max(pixels, 1.0)), 0.0, double(levels - 1));
                const double err = std::abs(got[0] - expected);
                ++checked;
                meanLod += expected;
                if (err > 0.15) {
                    if (++wrong <= 5)
                        std::printf("  pixel %d,%d: lod %.3f, expected %.3f (%d rays, hit %.1f m away)\n", x, y, got[0],
                                    expected, rays, glm::length(hit - p));
                } else {
                    worst = std::max(worst, err);
                }
            }
        meanLod /= std::max(checked, 1);
        std::printf("cone, roughness %.2f, cone_scale %.1f: %d floor pixels, mean expected lod %.2f, %d off by over "
                    "0.15; of the others the largest error %.3f\n",
                    roughness, scale, checked, meanLod, wrong, worst);
        EXPECT_GT(checked, 1500) << "roughness " << roughness;
        EXPECT_GT(meanLod, scale < 1.0f ? 0.5 : 1.0) << "the footprints must be wider than a pixel for the lod to show";
        EXPECT_LE(wrong, checked / 50) << "roughness " << roughness;
    }
}

// The roughness cut-off: max_roughness m fades the confidence linearly from 1 at 0.75 m to 0 at m. The same floor
// (roughness 0.3) with m = 0.35 and with m = 1 (no fade) marches the same rays (the seed is the pixel's), so their
// confidences differ by the fade alone: (m - r) / (m / 4) = 4/7 here. With m = 0.25 the floor has no reflection.
TEST_F(Ssr, RoughnessCutOffFadesTheConfidence) {
    const int W = GlossyWall::W, H = GlossyWall::H;
    GlossyWall scene(0.3f);
    json nodes = levelNodes(scene.glb, {{"resolution_scale", 1.0}, {"max_taps", 64}, {"thickness", 0.2},
                                        {"max_distance", 30.0}, {"edge_fade", 0.05}, {"max_roughness", 1.0}});
    nodes["ssr_cut"] = nodes["ssr"];
    nodes["ssr_cut"]["params"]["max_roughness"] = 0.35;
    nodes["ssr_off"] = nodes["ssr"];
    nodes["ssr_off"]["params"]["max_roughness"] = 0.25;
    auto out = runGraph(graph(nodes,
                              {{"full", "ssr.reflection"},
                               {"cut", "ssr_cut.reflection"},
                               {"off", "ssr_off.reflection"},
                               {"normal", "gbuffer.normal"}},
                              W, H));
    int checked = 0, lit = 0;
    double worst = 0.0, worstOff = 0.0, meanFade = 0.0;
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            const float* g0 = out.at("normal").at(x, y);
            if (g0[2] <= 0.0f || g0[3] > 0.8f) continue; // the floor (the wall is rougher than every cut-off)
            const double r = 1.0 - g0[3];
            if (std::abs(r - 0.3) > 0.01) continue;
            const double full = out.at("full").at(x, y)[3], cut = out.at("cut").at(x, y)[3];
            const double fade = std::clamp((0.35 - r) / (0.25 * 0.35), 0.0, 1.0);
            ++checked;
            meanFade += fade;
            if (full > 0.5) ++lit;
            worst = std::max(worst, std::abs(cut - full * fade));
            worstOff = std::max(worstOff, double(out.at("off").at(x, y)[3]));
        }
    meanFade /= std::max(checked, 1);
    std::printf("roughness cut-off: %d floor pixels (%d with confidence > 0.5 uncut), fade %.3f, largest |cut - full x "
                "fade| %.2e, largest confidence beyond the cut-off %.2e\n",
                checked, lit, meanFade, worst, worstOff);
    EXPECT_GT(checked, 2000);
    EXPECT_GT(lit, 1000);
    EXPECT_NEAR(meanFade, 4.0 / 7.0, 0.05);
    EXPECT_LT(worst, 2e-3);
    EXPECT_EQ(worstOff, 0.0);
}

} // namespace
} // namespace vitrine::test
