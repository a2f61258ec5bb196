// temporal.accumulate and gbuffer.temporal_filter (MUSEUM_SPEC §5) against independent expectations: the running mean
// of per-pixel noise recomputed on the CPU, one blend step with velocity / depth / luminance rejection written out from
// the node's documented formulas, the ghost trail of a moving object (scene.gltf + gbuffer.layered, full and half
// resolution input), the restart of the sample count where the background is disoccluded, the history of a bilinear
// footprint partly rejected by depth renormalised over the taps kept; the normal filter's running
// blend and Toksvig shininess against core/shading, and on the Museum's dolly shot shininess never increases.
#include "tests/gpu/lighting_scene.hpp"

#include "core/graph/node.hpp"
#include "core/graph/registry.hpp"
#include "core/shading/brdf.hpp"
#include "core/shading/octahedral.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace vitrine::test {
namespace {

using nlohmann::json;
using namespace lighting;

// test.frames: a uniform RGBA32F image of `a` on frame 0 and `b` afterwards (with `alternate`: a on even frames, b on
// odd ones), plus `odd_columns` in the odd columns and `odd_rows` in the odd rows, or with `noise` a per-pixel,
// per-frame PCG hash in [0, 1) in every channel (noiseValue below).
const char* kFramesSource = R"(#version 460
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0) writeonly uniform image2D out_color;
layout(push_constant) uniform Push { vec4 value; vec4 oddColumns; vec4 oddRows; uint frame; uint noise; uint pad0; uint pad1; } pc;
uint pcg(uint v) {
    uint state = v * 747796405u + 2891336453u;
    uint word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}
void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(p, imageSize(out_color)))) return;
    vec4 c = pc.value + ((p.x & 1) != 0 ? pc.oddColumns : vec4(0.0)) + ((p.y & 1) != 0 ? pc.oddRows : vec4(0.0));
    if (pc.noise != 0u)
        for (int i = 0; i < 4; ++i)
            c[i] = float(pcg(uint(p.x) * 7919u + uint(p.y) * 104729u + pc.frame * 1299709u + uint(i) * 15485863u) >> 8u) / 16777216.0;
    imageStore(out_color, p, c);
}
)";

uint32_t pcg(uint32_t v) {
    const uint32_t state = v * 747796405u + 2891336453u;
    const uint32_t word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}
double noiseValue(int x, int y, uint32_t frame, int channel) {
    return (pcg(uint32_t(x) * 7919u + uint32_t(y) * 104729u + frame * 1299709u + uint32_t(channel) * 15485863u) >> 8u) /
           16777216.0;
}

class Frames final : public Node {
public:
    void setup(SetupContext& ctx) override {
        if (ctx.params().getBool("half")) {
            ImageDesc& out = ctx.output("color");
            out.width = (ctx.frame().width + 1) / 2;
            out.height = (ctx.frame().height + 1) / 2;
        }
        mPipeline = ctx.computePipelineSource("test/frames", kFramesSource);
    }
    void execute(ExecuteContext& ctx) override {
        const Params& p = ctx.params();
        const uint32_t f = ctx.frameIndex();
        struct {
            glm::vec4 value, oddColumns, oddRows;
            uint32_t frame, noise, pad0, pad1;
        } push{};
        const bool second = p.getBool("alternate") ? f % 2 == 1 : f > 0;
        push.value = second ? p.getVec4("b") : p.getVec4("a");
        push.oddColumns = p.getVec4("odd_columns");
        push.oddRows = p.getVec4("odd_rows");
        push.frame = f;
        push.noise = p.getBool("noise") ? 1u : 0u;
        const ImageDesc& out = ctx.output("color").desc();
        ctx.dispatch(mPipeline, &push, sizeof(push), out.width, out.height);
    }

private:
    PipelineId mPipeline = 0;
};

NodeSchema framesSchema() {
    NodeSchema s;
    s.type = "test.frames";
    s.doc = "test-only node of test_gpu";
    OutputPort out;
    out.name = "color";
    out.format = VK_FORMAT_R32G32B32A32_SFLOAT;
    out.doc = "test output";
    s.outputs = {out};
    s.params = {{"a", ParamType::Vec4, json::array({0.0, 0.0, 0.0, 0.0}), {}, {}, {}, "frame 0"},
                {"b", ParamType::Vec4, json::array({0.0, 0.0, 0.0, 0.0}), {}, {}, {}, "later frames"},
                {"alternate", ParamType::Bool, false, {}, {}, {}, "a on even frames, b on odd ones"},
                {"odd_columns", ParamType::Vec4, json::array({0.0, 0.0, 0.0, 0.0}), {}, {}, {}, "added in odd columns"},
                {"odd_rows", ParamType::Vec4, json::array({0.0, 0.0, 0.0, 0.0}), {}, {}, {}, "added in odd rows"},
                {"noise", ParamType::Bool, false, {}, {}, {}, "per-pixel per-frame hash instead"},
                {"half", ParamType::Bool, false, {}, {}, {}, "half the frame's size (rounded up)"}};
    return s;
}
const NodeRegistration kFrames(framesSchema(), [] { return std::make_unique<Frames>(); });

// test.downsample: half the input's size, each pixel the input texel under its centre (as temporal.accumulate reads the
// G-buffer for a half-resolution input).
const char* kDownsampleSource = R"(#version 460
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0) uniform sampler2D in_color;
layout(binding = 1) writeonly uniform image2D out_color;
void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = imageSize(out_color);
    if (any(greaterThanEqual(p, size))) return;
    ivec2 full = textureSize(in_color, 0);
    imageStore(out_color, p, texelFetch(in_color, min(ivec2((vec2(p) + 0.5) * vec2(full) / vec2(size)), full - 1), 0));
}
)";

class Downsample final : public Node {
public:
    void setup(SetupContext& ctx) override {
        mPipeline = ctx.computePipelineSource("test/downsample", kDownsampleSource);
    }
    void execute(ExecuteContext& ctx) override {
        const ImageDesc& out = ctx.output("color").desc();
        ctx.dispatch(mPipeline, nullptr, 0, out.width, out.height);
    }

private:
    PipelineId mPipeline = 0;
};

NodeSchema downsampleSchema() {
    NodeSchema s;
    s.type = "test.downsample";
    s.doc = "test-only node of test_gpu";
    s.inputs = {{"color", PortKind::Texture, {}, false, Usage::Sampled, "input"}};
    OutputPort out;
    out.name = "color";
    out.format = VK_FORMAT_R32G32B32A32_SFLOAT;
    out.size = SizeRule::ofInput("color", 0.5f);
    out.doc = "test output";
    s.outputs = {out};
    return s;
}
const NodeRegistration kDownsample(downsampleSchema(), [] { return std::make_unique<Downsample>(); });

json framesNode(glm::vec4 a, glm::vec4 b, bool half = false) {
    return {{"type", "test.frames"}, {"params", {{"a", {a.x, a.y, a.z, a.w}}, {"b", {b.x, b.y, b.z, b.w}}, {"half", half}}}};
}

json accumulateNode(json params, json in) {
    in["history"] = "acc.color@prev";
    in["history_samples"] = "acc.samples@prev";
    return {{"type", "temporal.accumulate"}, {"params", params}, {"in", in}};
}

class Temporal : public GpuTest {};

// Per-pixel noise, different every frame (the jittered inputs of a static shot): after N frames with max_samples N the
// output is their mean, and later the running blend (N - 1) / N of the history, both recomputed here from the same
// hash. The sample count is min(frame + 1, N).
TEST_F(Temporal, StaticInputConvergesToTheMeanOfTheFrames) {
    const int w = 24, h = 16, n = 8;
    for (int frames : {n, 3 * n}) {
        json nodes = {{"src", {{"type", "test.frames"}, {"params", {{"noise", true}}}}},
                      {"acc", accumulateNode({{"max_samples", n}}, {{"color", "src.color"}})}};
        json g = graph(nodes, {{"out", "acc.color"}, {"samples", "acc.samples"}}, w, h);
        g["frame"]["frames"] = frames;
        auto out = runGraph(g);
        double worst = 0.0, spread = 0.0;
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                for (int c = 0; c < 4; ++c) {
                    double mean = 0.0;
                    for (int f = 0; f < frames; ++f) {
                        const double k = std::min(f, n - 1);
                        mean = f == 0 ? noiseValue(x, y, 0, c) : (noiseValue(x, y, f, c) + k * mean) / (k + 1.0);
                    }
                    worst = std::max(worst, std::fabs(out.at("out").at(x, y)[c] - mean));
                    spread = std::max(spread, std::fabs(noiseValue(x, y, frames - 1, c) - mean));
                }
                EXPECT_EQ(out.at("samples").at(x, y)[0], float(std::min(frames, n)));
            }
        std::printf("%d frames, max_samples %d: worst |output - CPU running mean| %.2e (last frame's input is up to %.2f "
                    "from it)\n",
                    frames, n, worst, spread);
        EXPECT_LT(worst, 4e-3); // RGBA16F history, rounded every frame
        EXPECT_GT(spread, 0.3);
    }
}

// One blend step, frame 0 uniform a then frame 1 uniform b, with uniform velocity and depth images from test.frames:
// the history holds one sample, cut by Sousa13's velocity difference and the luminance difference, restarted by a
// depth change beyond the tolerance; the output is mix(b, a, n / (n + 1)) and the count n + 1, as the node documents.
// The input is at half the velocity's resolution (the velocity is scaled to its pixels).
TEST_F(Temporal, OneStepWeightsMatchTheirFormulas) {
    const glm::vec4 a(0.1f, 0.2f, 0.6f, 1.0f), b(0.9f, 0.3f, 0.05f, 0.5f);
    const double la = 0.2126 * a.x + 0.7152 * a.y + 0.0722 * a.z, lb = 0.2126 * b.x + 0.7152 * b.y + 0.0722 * b.z;
    struct Case {
        const char* name;
        glm::vec2 v0, v1;
        float d0, d1;
        double velocityWeight, luminanceWeight;
        double expectedN;
    };
    const double dv = glm::length(glm::vec2(1.0f, -2.0f) - glm::vec2(3.0f, 0.0f));
    const Case cases[] = {
        {"plain", {0, 0}, {0, 0}, 5.0f, 5.0f, 0.0, 0.0, 1.0},
        {"velocity difference", {1, -2}, {3, 0}, 5.0f, 5.0f, 0.2, 0.0, 1.0 - 0.2 * dv},
        {"velocity weight 0", {1, -2}, {3, 0}, 5.0f, 5.0f, 0.0, 0.0, 1.0},
        {"large velocity difference", {1, -2}, {-6, 4}, 5.0f, 5.0f, 0.5, 0.0, 0.0},
        {"luminance", {0, 0}, {0, 0}, 5.0f, 5.0f, 0.0, 0.6, 1.0 - 0.6 * std::fabs(lb - la) / std::max(la, lb)},
        {"depth within tolerance", {0, 0}, {0, 0}, 5.0f, 5.2f, 0.0, 0.0, 1.0},
        {"disocclusion", {0, 0}, {0, 0}, 5.0f, 5.4f, 0.0, 0.0, 0.0},
    };
    const int w = 32, h = 24;
    for (const Case& k : cases) {
        json nodes = {{"src", framesNode(a, b, true)},
                      {"vel", framesNode(glm::vec4(k.v0, 0.0f, 0.0f), glm::vec4(k.v1, 0.0f, 0.0f))},
                      {"depth", framesNode(glm::vec4(0.0f, 0.0f, k.d0, 0.0f), glm::vec4(0.0f, 0.0f, k.d1, 0.0f))},
                      {"acc",
                       accumulateNode({{"velocity_weight", k.velocityWeight},
                                       {"luminance_weight", k.luminanceWeight},
                                       {"depth_tolerance", 0.05}},
                                      {{"color", "src.color"},
                                       {"velocity", "vel.color"},
                                       {"history_velocity", "vel.color@prev"},
                                       {"depth", "depth.color"},
                                       {"history_depth", "depth.color@prev"}})}};
        json g = graph(nodes, {{"out", "acc.color"}, {"samples", "acc.samples"}}, w, h);
        g["frame"]["frames"] = 2;
        auto out = runGraph(g);
        ASSERT_EQ(out.at("out").width, w / 2);
        const double wHistory = k.expectedN / (k.expectedN + 1.0);
        const glm::dvec4 expected = glm::mix(glm::dvec4(b), glm::dvec4(a), wHistory);
        double worst = 0.0, worstN = 0.0;
        for (int y = 4; y < h / 2 - 4; ++y) // away from the border, where the reprojected point may leave the screen
            for (int x = 4; x < w / 2 - 4; ++x) {
                for (int c = 0; c < 4; ++c) worst = std::max(worst, std::fabs(out.at("out").at(x, y)[c] - expected[c]));
                worstN = std::max(worstN, std::fabs(out.at("samples").at(x, y)[0] - (k.expectedN + 1.0)));
            }
        std::printf("%s: history samples %.3f, worst |output - expected| %.2e, |samples - expected| %.2e\n", k.name,
                    k.expectedN, worst, worstN);
        EXPECT_LT(worst, 2e-3) << k.name;
        EXPECT_LT(worstN, 2e-3) << k.name;
    }
}

// A partial disocclusion inside the history's bilinear footprint: per-pixel noise as colour and as view depth (both
// frames differ everywhere), a uniform velocity of (0.6, -0.25) px so that every pixel's history is a 2x2 bilinear
// fetch with weights (0.4 x 0.25 .. 0.6 x 0.75), and a depth tolerance of 30 % that rejects some of the four taps at
// most pixels. The history is then the mean of the accepted taps' last outputs with their bilinear weights, divided
// by the sum of those weights (renormalised), recomputed here from the same hash; the output is its running blend
// with this frame, n = 1: mix(current, history, 1/2); all four taps rejected: current alone. The whole frame is
// checked: the first column's points came from outside it (no history), the last row's taps below the frame read
// its edge.
TEST_F(Temporal, PartlyRejectedBilinearHistoryIsRenormalised) {
    const int w = 32, h = 24;
    const double tolerance = 0.3;
    const glm::vec2 velocity(0.6f, -0.25f);
    json nodes = {{"src", {{"type", "test.frames"}, {"params", {{"noise", true}}}}},
                  {"depth", {{"type", "test.frames"}, {"params", {{"noise", true}}}}},
                  {"vel", framesNode(glm::vec4(velocity, 0.0f, 0.0f), glm::vec4(velocity, 0.0f, 0.0f))},
                  {"acc",
                   accumulateNode({{"velocity_weight", 0.0}, {"luminance_weight", 0.0}, {"depth_tolerance", tolerance}},
                                  {{"color", "src.color"},
                                   {"velocity", "vel.color"},
                                   {"depth", "depth.color"},
                                   {"history_depth", "depth.color@prev"}})}};
    json g = graph(nodes, {{"out", "acc.color"}, {"samples", "acc.samples"}}, w, h);
    g["frame"]["frames"] = 2;
    auto out = runGraph(g);
    int partial = 0, all = 0, none = 0, ambiguous = 0, outside = 0, edge = 0;
    double worst = 0.0;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const double here = noiseValue(x, y, 1, 2);
            // The reprojected point (x + 0.5, y + 0.5) - velocity, between texels b and b + 1 at offset f; none
            // outside the frame, and taps past its edge read the edge.
            const glm::dvec2 prev = glm::dvec2(x, y) + 0.5 - glm::dvec2(velocity);
            const bool inside = prev.x >= 0.0 && prev.y >= 0.0 && prev.x <= w && prev.y <= h;
            const glm::dvec2 b = glm::floor(prev - 0.5), f = prev - 0.5 - b;
            glm::dvec4 sum(0.0);
            double total = 0.0;
            int accepted = 0;
            bool nearThreshold = false;
            for (int j = 0; j < 2 && inside; ++j)
                for (int i = 0; i < 2; ++i) {
                    const int qx = std::clamp(int(b.x) + i, 0, w - 1), qy = std::clamp(int(b.y) + j, 0, h - 1);
                    edge += qx != int(b.x) + i || qy != int(b.y) + j;
                    const double before = noiseValue(qx, qy, 0, 2);
                    const double rel = std::fabs(before - here) / std::max(before, here);
                    nearThreshold = nearThreshold || std::fabs(rel - tolerance) < 1e-3;
                    if (rel > tolerance) continue;
                    const double wt = (i == 0 ? 1.0 - f.x : f.x) * (j == 0 ? 1.0 - f.y : f.y);
                    for (int c = 0; c < 4; ++c) sum[c] += wt * noiseValue(qx, qy, 0, c);
                    total += wt;
                    ++accepted;
                }
            if (nearThreshold) {
                ++ambiguous;
                continue;
            }
            glm::dvec4 current;
            for (int c = 0; c < 4; ++c) current[c] = noiseValue(x, y, 1, c);
            const glm::dvec4 expected = accepted > 0 ? glm::mix(current, sum / total, 0.5) : current;
            const double expectedSamples = accepted > 0 ? 2.0 : 1.0;
            if (!inside)
                ++outside;
            else if (accepted == 4)
                ++all;
            else if (accepted == 0) ++none;
            else ++partial;
            for (int c = 0; c < 4; ++c) {
                const double err = std::fabs(out.at("out").at(x, y)[c] - expected[c]);
                worst = std::max(worst, err);
                EXPECT_LT(err, 2e-3) << "pixel " << x << "," << y << " channel " << c << ", " << accepted
                                     << " taps accepted";
            }
            EXPECT_EQ(out.at("samples").at(x, y)[0], float(expectedSamples)) << "pixel " << x << "," << y;
        }
    std::printf("partial rejection: %d pixels with 1-3 of 4 taps accepted, %d with all, %d with none (%d near the "
                "tolerance skipped), %d from outside the frame, %d taps past its edge; worst |output - CPU| %.2e\n",
                partial, all, none, ambiguous, outside, edge, worst);
    EXPECT_GT(partial, 200);
    EXPECT_GT(none, 10);
    EXPECT_GT(outside, 20);
    EXPECT_GT(edge, 20);
}

// A bright square sliding over a dark wall at ~4 px per frame, accumulated from the G-buffer's base colour (full
// resolution, and half resolution through test.downsample). Trail: the summed |output - input| over the pixels the
// square does not cover (nor covered on frame 0, see below), relative to the square's own energy (area x contrast),
// after 9 frames. Bound: 1 % with the
// velocity difference alone, the depth test alone, or both; without either the trail is the history's (> 20 %).
// Where the square was last frame and is no longer (disoccluded background) the sample count restarts at 1.
TEST_F(Temporal, MovingObjectLeavesNoGhostAndDisocclusionRestartsTheCount) {
    SceneBuilder b("temporal_ghost");
    std::vector<Tri> wall, square;
    addQuad(wall, {0.0f, 0.0f, 0.0f}, {12.0f, 0.0f, 0.0f}, {0.0f, 12.0f, 0.0f}, {0.0f, 0.0f, 1.0f});
    addQuad(square, {0.0f, 0.0f, 0.0f}, {0.5f, 0.0f, 0.0f}, {0.0f, 0.5f, 0.0f}, {0.0f, 0.0f, 1.0f});
    b.node("wall", static_cast<int32_t>(b.mesh("wall", wall, b.material("dark", glm::vec3(0.05f), 0.0f, 0.3f))),
           {0.0f, 0.0f, -5.0f});
    b.node("square", static_cast<int32_t>(b.mesh("square", square, b.material("white", glm::vec3(1.0f), 0.0f, 0.3f))),
           {-1.5f, 0.0f, -4.0f});
    scene::Animation slide;
    slide.name = "slide";
    slide.samplers = {{scene::Interpolation::Linear, {0.0f, 1.0f},
                       {glm::vec4(-1.5f, 0.0f, -4.0f, 0.0f), glm::vec4(3.5f, 0.0f, -4.0f, 0.0f)}}};
    slide.channels = {{static_cast<uint32_t>(b.s.nodes.size() - 1), scene::AnimationPath::Translation, 0}};
    b.s.animations.push_back(slide);
    b.camera({0.0f, 0.0f, 0.0f}, {0.0f, 0.0f, -1.0f}, 0.8f);
    const auto glb = b.write();
    const int w = 96, h = 64;

    auto run = [&](bool half, bool velocity, bool depth, int frames) {
        json in = {{"color", half ? "down.color" : "gbuffer.base_color"}, {"velocity", "gbuffer.velocity"}};
        if (velocity) in["history_velocity"] = "gbuffer.velocity@prev";
        if (depth) {
            in["depth"] = "gbuffer.normal";
            in["history_depth"] = "gbuffer.normal@prev";
        }
        json nodes = {{"scene", {{"type", "scene.gltf"}, {"params", {{"path", glb.string()}, {"fps", 24.0}}}}},
                      {"gbuffer", {{"type", "gbuffer.layered"}, {"in", {{"scene", "scene.scene"}}}}},
                      {"acc", accumulateNode({{"max_samples", 8}}, in)}};
        json outputs = {{"out", "acc.color"}, {"samples", "acc.samples"}, {"in", "gbuffer.base_color"}};
        if (half) {
            nodes["down"] = {{"type", "test.downsample"}, {"in", {{"color", "gbuffer.base_color"}}}};
            outputs["in"] = "down.color";
        }
        json g = graph(nodes, outputs, w, h);
        g["frame"]["frames"] = frames;
        return runGraph(g);
    };
    // Also the square's own pixels: their history must follow it (reprojected by its velocity), so the mean
    // |output - input| over them stays small (returned in `inside`).
    double inside = 0.0, insideSamples = 0.0; // and the mean sample count there
    // Frame 0's velocity buffer has no motion yet (zero everywhere), so what the square covered on frame 0 is not
    // rejected by the velocity difference on frame 1: those pixels are left out of the trail (`first`, per resolution).
    Image first;
    auto trail = [&inside, &insideSamples, &first](const std::map<std::string, Image>& out) {
        const Image& o = out.at("out");
        const Image& in = out.at("in");
        double energy = 0.0, box = 0.0;
        int covered = 0;
        inside = insideSamples = 0.0;
        for (int y = 0; y < in.height; ++y)
            for (int x = 0; x < in.width; ++x) {
                if (in.at(x, y)[0] > 0.5f) {
                    box += in.at(x, y)[0] - 0.05;
                    inside += std::fabs(o.at(x, y)[0] - in.at(x, y)[0]);
                    insideSamples += out.at("samples").at(x, y)[0];
                    ++covered;
                } else if (first.at(x, y)[0] <= 0.5f) {
                    energy += std::fabs(o.at(x, y)[0] - in.at(x, y)[0]);
                }
            }
        inside /= std::max(covered, 1);
        insideSamples /= std::max(covered, 1);
        return box > 0.0 ? energy / box : 1e9;
    };
    const int frames = 9;
    for (bool half : {false, true}) {
        first = run(half, true, true, 1).at("in");
        const double both = trail(run(half, true, true, frames));
        const double insideBoth = inside, samplesBoth = insideSamples;
        const double velocityOnly = trail(run(half, true, false, frames));
        const double depthOnly = trail(run(half, false, true, frames));
        const double none = trail(run(half, false, false, frames));
        std::printf("%s resolution: trail after %d frames: velocity + depth %.4f, velocity difference only %.4f, depth "
                    "only %.4f, no rejection %.4f; on the square: mean |output - input| %.4f, mean samples %.2f\n",
                    half ? "half" : "full", frames, both, velocityOnly, depthOnly, none, insideBoth, samplesBoth);
        EXPECT_LT(insideBoth, 0.05);
        // The square's history follows it (reprojected by its velocity, scaled to the input's pixels): its pixels keep
        // their samples; without reprojection its leading band (a fifth of it) would restart every frame.
        EXPECT_GT(samplesBoth, 7.5);
        EXPECT_LT(both, 0.01);
        EXPECT_LT(velocityOnly, 0.01);
        EXPECT_LT(depthOnly, 0.01);
        EXPECT_GT(none, 0.2);
    }

    // Disocclusion: frame 7 against frame 8 (a second run one frame shorter gives the square's last position).
    auto before = run(false, true, true, frames - 1);
    auto now = run(false, true, true, frames);
    int disoccluded = 0, restarted = 0, background = 0, full = 0;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const bool was = before.at("in").at(x, y)[0] > 0.5f, is = now.at("in").at(x, y)[0] > 0.5f;
            const float n = now.at("samples").at(x, y)[0];
            if (was && !is) {
                ++disoccluded;
                restarted += n == 1.0f;
            }
            if (!was && !is && (y < 16 || y >= h - 16)) { // rows the square never crosses
                ++background;
                full += n == 8.0f;
            }
        }
    std::printf("disocclusion: count restarted at %d of %d pixels; static background at 8 samples: %d of %d\n",
                restarted, disoccluded, full, background);
    EXPECT_GT(disoccluded, 20);
    EXPECT_EQ(restarted, disoccluded);
    EXPECT_EQ(full, background);
}

// gbuffer.temporal_filter on a G-buffer normal target alternating between two normals (static, no velocity; the depth
// alternates by column): the history is the running blend avg_k = mix(n_k, avg_k-1, feedback), the output's normal is
// avg / |avg| and its shininess 1 - toksvigRoughness(1 - s, |avg|) of core/shading (the G-buffer's own Toksvig
// formula). A depth change beyond the tolerance restarts the blend (the raw normal and shininess come back).
TEST_F(Temporal, GbufferFilterBlendsNormalsAndReducesShininessLikeToksvig) {
    const glm::vec3 na = glm::normalize(glm::vec3(0.3f, 1.0f, 0.1f)), nb = glm::normalize(glm::vec3(-0.4f, 1.0f, 0.5f));
    const glm::vec2 ea = shading::octEncode(na), eb = shading::octEncode(nb);
    // The depth alternates by column (6 m, 9 m: beyond the tolerance), so a history tap one texel off is another
    // surface's and left out.
    const float shininess = 0.85f, depth = 6.0f, oddDepth = 3.0f;
    const double feedback = 0.6;
    const int w = 24, h = 16;
    for (int frames : {1, 2, 5}) {
        json nodes = {{"src",
                       {{"type", "test.frames"},
                        {"params",
                         {{"a", {ea.x, ea.y, depth, shininess}},
                          {"b", {eb.x, eb.y, depth, shininess}},
                          {"odd_columns", {0.0, 0.0, oddDepth, 0.0}},
                          {"alternate", true}}}}},
                      {"filter",
                       {{"type", "gbuffer.temporal_filter"},
                        {"params", {{"feedback", feedback}}},
                        {"in", {{"normal", "src.color"}, {"history", "filter.history@prev"}}}}}};
        json g = graph(nodes, {{"out", "filter.normal"}, {"history", "filter.history"}}, w, h);
        g["frame"]["frames"] = frames;
        auto out = runGraph(g);
        glm::dvec3 avg(na);
        for (int f = 1; f < frames; ++f) avg = glm::mix(glm::dvec3(f % 2 ? nb : na), avg, feedback);
        const double len = glm::length(avg);
        const double expectedShininess = 1.0 - shading::toksvigRoughness(1.0f - shininess, static_cast<float>(len));
        const glm::dvec3 expectedNormal = avg / len;
        double worstN = 0.0, worstS = 0.0, worstH = 0.0;
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                const float* o = out.at("out").at(x, y);
                worstN = std::max(worstN, glm::length(glm::dvec3(shading::octDecode({o[0], o[1]})) - expectedNormal));
                worstS = std::max(worstS, std::fabs(o[3] - expectedShininess));
                EXPECT_EQ(o[2], depth + (x % 2 ? oddDepth : 0.0f));
                const float* hh = out.at("history").at(x, y);
                worstH = std::max(worstH, glm::length(glm::dvec3(hh[0], hh[1], hh[2]) - avg));
            }
        std::printf("%d frames: |avg| %.4f, shininess %.4f -> %.4f; worst normal error %.2e, shininess %.2e, history "
                    "%.2e\n",
                    frames, len, shininess, expectedShininess, worstN, worstS, worstH);
        EXPECT_LT(worstN, 3e-3);
        EXPECT_LT(worstS, 2e-3);
        EXPECT_LT(worstH, 2e-3);
        if (frames > 1) {
            EXPECT_LT(expectedShininess, shininess - 0.05); // the reduction is visible to the test
        }
    }
    // Depth 6 then 7 (17 % apart): another surface, so frame 1 is nb and the authored shininess.
    json nodes = {{"src", framesNode(glm::vec4(ea, depth, shininess), glm::vec4(eb, 7.0f, shininess))},
                  {"filter",
                   {{"type", "gbuffer.temporal_filter"},
                    {"params", {{"feedback", feedback}}},
                    {"in", {{"normal", "src.color"}, {"history", "filter.history@prev"}}}}}};
    json g = graph(nodes, {{"out", "filter.normal"}}, w, h);
    g["frame"]["frames"] = 2;
    auto out = runGraph(g);
    const float* o = out.at("out").at(5, 5);
    EXPECT_LT(glm::length(shading::octDecode({o[0], o[1]}) - nb), 2e-3f);
    EXPECT_NEAR(o[3], shininess, 1e-3);
}

// gbuffer.temporal_filter under sub-pixel motion: a velocity input moves everything by v = (0.3, 0.7) px a frame, so
// each pixel's history is the bilinear blend of four history texels around p + 0.5 - v (taps clamped to the frame; none
// where that point is outside it, the first row here). The normal target changes by column and by row, so each axis'
// weights show. Expected, written out here from the filter's description: history_0 = n_0; avg = mix(n_1, h / w,
// feedback), h the weighted sum of the taps of the same surface (view depth within the tolerance) and w their
// weights; output normal avg / |avg| and shininess 1 - toksvigRoughness(1 - s, |avg|). Two targets: one depth
// everywhere (both axes' weights, the frame's edges), and the depth alternating by row (the other rows' taps left
// out, so the kept weights sum to 0.3 or 0.7 and must be renormalised).
TEST_F(Temporal, GbufferFilterFetchesItsHistoryBilinearlyAlongTheVelocity) {
    const glm::vec2 ea = shading::octEncode(glm::normalize(glm::vec3(0.2f, 1.0f, -0.1f)));
    const glm::vec2 eb = shading::octEncode(glm::normalize(glm::vec3(-0.3f, 1.0f, 0.4f)));
    const glm::vec2 oddColumn(0.10f, -0.04f), oddRow(-0.03f, 0.12f);
    const glm::vec2 v(0.3f, 0.7f);
    const float shininess = 0.9f, depth = 6.0f, tolerance = 0.1f;
    const double feedback = 0.7;
    const int w = 20, h = 12;
    for (const bool rowsApart : {false, true}) {
        const float oddRowDepth = rowsApart ? 3.0f : 0.0f; // 9 m against 6 m: another surface
        json nodes = {
            {"src",
             {{"type", "test.frames"},
              {"params",
               {{"a", {ea.x, ea.y, depth, shininess}},
                {"b", {eb.x, eb.y, depth, shininess}},
                {"odd_columns", {oddColumn.x, oddColumn.y, 0.0, 0.0}},
                {"odd_rows", {oddRow.x, oddRow.y, oddRowDepth, 0.0}}}}}},
            {"motion", framesNode(glm::vec4(v, 0.0f, 0.0f), glm::vec4(v, 0.0f, 0.0f))},
            {"filter",
             {{"type", "gbuffer.temporal_filter"},
              {"params", {{"feedback", feedback}, {"depth_tolerance", tolerance}}},
              {"in", {{"normal", "src.color"}, {"velocity", "motion.color"}, {"history", "filter.history@prev"}}}}}};
        json g = graph(nodes, {{"out", "filter.normal"}, {"history", "filter.history"}}, w, h);
        g["frame"]["frames"] = 2;
        auto out = runGraph(g);
        auto at = [&](glm::vec2 e, int x, int y) {
            return glm::dvec3(
                shading::octDecode(e + (x % 2 ? oddColumn : glm::vec2(0.0f)) + (y % 2 ? oddRow : glm::vec2(0.0f))));
        };
        auto depthAt = [&](int y) { return depth + (y % 2 ? oddRowDepth : 0.0f); };
        double worstN = 0.0, worstS = 0.0, worstH = 0.0, moved = 0.0;
        int partial = 0;
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                const glm::dvec3 n1 = at(eb, x, y);
                const glm::dvec2 prev = glm::dvec2(x, y) + 0.5 - glm::dvec2(v);
                glm::dvec3 sum(0.0);
                double weight = 0.0;
                if (prev.x >= 0.0 && prev.y >= 0.0 && prev.x <= w && prev.y <= h) {
                    const glm::dvec2 s = prev - 0.5, b = glm::floor(s), f = s - b;
                    for (int j = 0; j < 2; ++j)
                        for (int i = 0; i < 2; ++i) {
                            const int tx = std::clamp(int(b.x) + i, 0, w - 1), ty = std::clamp(int(b.y) + j, 0, h - 1);
                            const double d = depthAt(ty), here = depthAt(y);
                            if (std::abs(d - here) > tolerance * std::max(d, here)) continue;
                            const double wt = (i ? f.x : 1.0 - f.x) * (j ? f.y : 1.0 - f.y);
                            sum += wt * at(ea, tx, ty);
                            weight += wt;
                        }
                }
                partial += weight > 1e-3 && weight < 0.99;
                const glm::dvec3 avg = weight > 1e-3 ? glm::mix(n1, sum / weight, feedback) : n1;
                const double len = glm::length(avg);
                const double s = std::min<double>(
                    shininess, 1.0 - shading::toksvigRoughness(1.0f - shininess, float(std::min(len, 1.0))));
                const float* o = out.at("out").at(x, y);
                worstN = std::max(worstN, glm::length(glm::dvec3(shading::octDecode({o[0], o[1]})) - avg / len));
                worstS = std::max(worstS, std::fabs(o[3] - s));
                const float* hh = out.at("history").at(x, y);
                worstH = std::max(worstH, glm::length(glm::dvec3(hh[0], hh[1], hh[2]) - avg));
                moved = std::max(moved, glm::length(avg / len - n1));
            }
        std::printf("%s: worst normal error %.2e, shininess %.2e, history %.2e; the history moves the normal by up to "
                    "%.3f; %d pixels renormalise partial weights\n",
                    rowsApart ? "rows 3 m apart" : "one depth", worstN, worstS, worstH, moved, partial);
        EXPECT_LT(worstN, 3e-3);
        EXPECT_LT(worstS, 2e-3);
        EXPECT_LT(worstH, 2e-3);
        EXPECT_GT(moved, 0.05);
        EXPECT_EQ(partial > 0, rowsApart);
    }
}

// The Museum's dolly shot (museum.json, 6 frames at 128x72): the filtered G-buffer's shininess is never above the
// G-buffer's, somewhere clearly below it (the camera's motion changes what thin and normal-mapped geometry a pixel
// sees), and depth passes through.
TEST_F(Temporal, MuseumDollyFilterNeverIncreasesShininess) {
    auto out = runGraphFile(std::string(VITRINE_SOURCE_DIR) + "/graphs/museum.json",
                            {"frame.width=128", "frame.height=72", "frame.frames=6", "frame.write=[5]",
                             "scene.params.camera=dolly", "outputs.raw=gbuffer.normal", "outputs.filtered=gfilter.normal"});
    const Image& raw = out.at("raw");
    const Image& filtered = out.at("filtered");
    double increase = 0.0, decrease = 0.0;
    int reduced = 0;
    for (int y = 0; y < raw.height; ++y)
        for (int x = 0; x < raw.width; ++x) {
            increase = std::max(increase, double(filtered.at(x, y)[3] - raw.at(x, y)[3]));
            decrease = std::max(decrease, double(raw.at(x, y)[3] - filtered.at(x, y)[3]));
            reduced += raw.at(x, y)[3] - filtered.at(x, y)[3] > 0.01f;
            EXPECT_EQ(filtered.at(x, y)[2], raw.at(x, y)[2]);
        }
    std::printf("museum dolly: shininess increased by at most %.2e, reduced by up to %.3f, by > 0.01 at %d of %d "
                "pixels\n",
                increase, decrease, reduced, raw.width * raw.height);
    EXPECT_LE(increase, 0.0);
    EXPECT_GT(reduced, 20);
}

} // namespace
} // namespace vitrine::test
