// post.motion_blur against references that do not come from its code:
//   - analytic: a step edge under a constant velocity v (pixels per frame) and blur scale s becomes the linear ramp
//     clamp((x + 0.5 - e) / (s |v|) + 0.5, 0, 1) (the edge sweeps s |v| pixels while the shutter is open), for the
//     scale param, the shutter-driven length from the `shutter` param and from a camera state; a moving near layer
//     over a still far one gives the same ramp (depth-aware weights); a still near layer over a moving far one
//     stays sharp (no background smeared over it);
//   - ground truth by accumulation: a scene of moving cards rendered at 16 sub-frame times spread evenly over the
//     shutter interval and averaged (aa.accumulate), against post.motion_blur of the single frame at the interval's
//     centre: LDR-FLIP mean.
#include "tests/gpu/lighting_scene.hpp"
#include "tests/gpu/post_test_util.hpp"

#include "core/compare/metrics.hpp"
#include "core/image/io.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace vitrine::test {
namespace {

using nlohmann::json;
using post::graph;
using post::loadNode;
using post::writeInput;

class MotionBlur : public GpuTest {};

constexpr int kW = 128, kH = 24, kEdge = 60; // the edge on a tile border (tile_size 20)

struct Layers {
    Image color, velocity, depth;
};

// Left of the edge: colour 1, depth zl, velocity vl; right: colour 0, depth zr, velocity vr.
Layers stepEdge(float zl, float vl, float zr, float vr) {
    Layers l{Image(kW, kH), Image(kW, kH), Image(kW, kH)};
    for (int y = 0; y < kH; ++y)
        for (int x = 0; x < kW; ++x) {
            bool left = x < kEdge;
            float c = left ? 1.0f : 0.0f;
            float* px = l.color.at(x, y);
            px[0] = px[1] = px[2] = c;
            px[3] = 1.0f;
            l.velocity.at(x, y)[0] = left ? vl : vr;
            l.depth.at(x, y)[2] = left ? zl : zr;
        }
    return l;
}

json blurGraph(const Layers& l, const std::string& name, json params, bool cameraState = false, double shutter = 0.0) {
    json nodes = {{"color", loadNode(writeInput(l.color, name + "_color"))},
                  {"velocity", loadNode(writeInput(l.velocity, name + "_velocity"))},
                  {"depth", loadNode(writeInput(l.depth, name + "_depth"))},
                  {"blur",
                   {{"type", "post.motion_blur"},
                    {"params", params},
                    {"in", {{"color", "color.color"}, {"velocity", "velocity.color"}, {"depth", "depth.color"}}}}}};
    if (cameraState) {
        nodes["camera"] = {{"type", "test.camera_state"}, {"params", {{"shutter", shutter}}}};
        nodes["blur"]["in"]["camera_state"] = "camera.state";
    }
    return graph(nodes, {{"out", "blur.color"}}, kW, kH);
}

struct RampError {
    double worst = 0.0, mean = 0.0;
};

// Against the bright-left edge swept over `length` pixels (the image's left half is 1).
RampError rampError(const Image& out, double length) {
    RampError e;
    int n = 0;
    for (int y = 0; y < kH; ++y)
        for (int x = 0; x < kW; ++x) {
            double expected = std::clamp((kEdge - (x + 0.5)) / length + 0.5, 0.0, 1.0);
            for (int c = 0; c < 3; ++c) {
                double d = std::fabs(out.at(x, y)[c] - expected);
                e.worst = std::max(e.worst, d);
                e.mean += d;
                ++n;
            }
        }
    e.mean /= n;
    return e;
}

// 15 taps over a ramp put a tap every L/15 pixels, each rounded to a pixel: the staircase departs from the ramp by
// at most one tap's share (1/15); on average its steps straddle the ramp, so the mean error stays far below that.
double rampBound(double) {
    return 1.0 / 15.0 + 1e-3;
}
constexpr double kMeanBound = 0.004;

TEST_F(MotionBlur, ConstantVelocityTurnsAStepIntoALinearRamp) {
    const json exact = {{"dither", false}, {"samples", 15}, {"tile_size", 20}};
    Layers uniform = stepEdge(5.0f, 12.0f, 5.0f, 12.0f);
    struct Case {
        const char* what;
        json params;
        bool cameraState;
        double shutter, length;
    };
    std::vector<Case> cases = {
        {"scale 1", {{"scale", 1.0}}, false, 0.0, 12.0},
        {"scale 0.5", {{"scale", 0.5}}, false, 0.0, 6.0},
        // Half-lengths are clamped to the tile size: 4 px tiles make any ramp 8 px long.
        {"scale 1, clamped by 4 px tiles", {{"scale", 1.0}, {"tile_size", 4}}, false, 0.0, 8.0},
        {"shutter param 1/32 s at 24 fps",
         {{"shutter_driven", true}, {"shutter", 1.0 / 32.0}, {"fps", 24.0}},
         false,
         0.0,
         9.0},
        {"camera state 1/24 s at 24 fps",
         {{"shutter_driven", true}, {"fps", 24.0}, {"shutter", 1.0}},
         true,
         1.0 / 24.0,
         12.0},
    };
    for (const Case& c : cases) {
        json params = exact;
        params.update(c.params);
        auto out = runGraph(blurGraph(uniform, "uniform", params, c.cameraState, c.shutter));
        RampError e = rampError(out.at("out"), c.length);
        std::printf("%s: ramp of %.0f px, worst %.4f, mean %.4f (bound %.4f)\n", c.what, c.length, e.worst, e.mean,
                    rampBound(c.length));
        EXPECT_LT(e.worst, rampBound(c.length)) << c.what;
        EXPECT_LT(e.mean, kMeanBound) << c.what;
    }
    // Dithered taps: noise instead of a staircase, the same ramp on average.
    json dithered = exact;
    dithered["dither"] = true;
    dithered["scale"] = 1.0;
    Image noisy = runGraph(blurGraph(uniform, "uniform", dithered)).at("out");
    RampError e = rampError(noisy, 12.0);
    // Rows are identical without the dither; with it they differ inside the ramp.
    double rowSpread = 0.0;
    for (int x = kEdge - 5; x < kEdge + 5; ++x) {
        double lo = 1.0, hi = 0.0;
        for (int y = 0; y < kH; ++y) {
            lo = std::min(lo, double(noisy.at(x, y)[0]));
            hi = std::max(hi, double(noisy.at(x, y)[0]));
        }
        rowSpread = std::max(rowSpread, hi - lo);
    }
    // Where the ramp lies: the dither moves each pixel's taps by up to half a tap's spacing either way, evenly, so
    // the ramp's position on average over the rows is the exact one. Shift (px): the sum over columns of the
    // row-mean output minus the expected ramp (a unit step moved by s adds s). A dither that is not centred (its hash
    // not spread over [0, 1)) moves it by a fraction of a tap's spacing: 0.8 px with 15 taps, 2.4 px with 5, where
    // it shows best (measured on lavapipe: -0.014 px; with the hash spread over [0, 2/3) instead: 0.19 px).
    auto shift = [&](const Image& img) {
        double sum = 0.0;
        for (int x = 0; x < kW; ++x) {
            double mean = 0.0;
            for (int y = 0; y < kH; ++y)
                mean += img.at(x, y)[0];
            sum += mean / kH - std::clamp((kEdge - (x + 0.5)) / 12.0 + 0.5, 0.0, 1.0);
        }
        return sum;
    };
    json sparse = dithered;
    sparse["samples"] = 5;
    const double noisyShift = shift(noisy),
                 sparseShift = shift(runGraph(blurGraph(uniform, "uniform", sparse)).at("out"));
    std::printf("5 dithered taps: the ramp moved by %.3f px\n", sparseShift);
    std::printf("dithered: worst %.4f, mean %.4f, largest spread across rows %.4f, the ramp moved by %.3f px\n",
                e.worst, e.mean, rowSpread, noisyShift);
    EXPECT_LT(e.worst, 0.15);
    EXPECT_LT(e.mean, 0.03);
    EXPECT_GT(rowSpread, 0.05);
    EXPECT_LT(std::fabs(noisyShift), 0.05);
    EXPECT_LT(std::fabs(sparseShift), 0.07);
}

// A moving near layer (left, depth 2 m) over a still far one (right, 10 m): the far pixels next to the edge are
// covered for the part of the shutter the near layer's sweep reaches them, the near pixels reveal the far layer the
// same way: the same ramp as a uniform motion.
TEST_F(MotionBlur, MovingForegroundOverStillBackgroundMakesTheSameRamp) {
    Layers l = stepEdge(2.0f, 12.0f, 10.0f, 0.0f);
    auto out = runGraph(blurGraph(l, "fg_moving", {{"dither", false}, {"samples", 15}, {"scale", 1.0}}));
    RampError e = rampError(out.at("out"), 12.0);
    std::printf("moving foreground: worst %.4f, mean %.4f (bound %.4f)\n", e.worst, e.mean, rampBound(12.0));
    EXPECT_LT(e.worst, rampBound(12.0));
    EXPECT_LT(e.mean, kMeanBound);
}

// A still near layer (left, 2 m) over a far layer moving fast (right, 10 m): nothing of the far layer may be smeared
// over the near one, and the far layer (one colour) stays that colour: the output is the input.
TEST_F(MotionBlur, StillForegroundStaysSharpOverAMovingBackground) {
    Layers l = stepEdge(2.0f, 0.0f, 10.0f, 24.0f);
    auto out = runGraph(blurGraph(l, "fg_still", {{"dither", true}, {"samples", 15}, {"scale", 1.0}}));
    double worst = maxAbsDiff(out.at("out"), l.color);
    std::printf("still foreground: worst change %.5f\n", worst);
    EXPECT_LT(worst, 1e-3);
}

// ---------------------------------------------------------------------------------------------------------------
// Ground truth by accumulation.

using namespace lighting;
constexpr int kSW = 192, kSH = 108;
constexpr double kT = 0.5, kFps = 24.0;
constexpr int kSubFrames = 16; // aa.accumulate's 4 x 4

// Unlit-free and light-free: the test compares gbuffer.base_color (albedo x vertex colour), so neither lighting nor
// shadows enter. A wall of checker tiles 10 m away, a striped card 4 m away moving right at 12 m/s (16 px a frame),
// a smaller card 3 m away moving down at 4 m/s (7 px a frame), partly in front of the first.
std::filesystem::path movingCardsScene() {
    SceneBuilder b("motion_blur_cards");
    const uint32_t white = b.material("white", glm::vec3(1.0f), 0.0f, 0.5f);
    auto colored = [](std::vector<Tri> tris, glm::vec3 c) {
        for (Tri& t : tris)
            for (scene::Vertex* v : {&t.a, &t.b, &t.c})
                v->color = glm::vec4(c, 1.0f);
        return tris;
    };
    std::vector<Tri> wall;
    for (int i = -8; i < 8; ++i)
        for (int j = -5; j < 5; ++j) {
            std::vector<Tri> q;
            addQuad(q, glm::vec3(i + 0.5f, j + 0.5f, -10.0f), glm::vec3(0.5f, 0, 0), glm::vec3(0, 0.5f, 0),
                    glm::vec3(0, 0, 1));
            glm::vec3 c = (i + j) % 2 == 0 ? glm::vec3(0.2f, 0.25f, 0.3f) : glm::vec3(0.45f, 0.4f, 0.35f);
            for (const Tri& t : colored(q, c))
                wall.push_back(t);
        }
    b.node("wall", static_cast<int32_t>(b.mesh("wall", wall, white)));
    std::vector<Tri> card;
    for (int k = 0; k < 8; ++k) {
        std::vector<Tri> q;
        addQuad(q, glm::vec3(-1.05f + 0.3f * k, 0.0f, 0.0f), glm::vec3(0.15f, 0, 0), glm::vec3(0, 0.6f, 0),
                glm::vec3(0, 0, 1));
        for (const Tri& t : colored(q, k % 2 ? glm::vec3(0.95f, 0.55f, 0.1f) : glm::vec3(0.1f, 0.3f, 0.9f)))
            card.push_back(t);
    }
    b.node("card", static_cast<int32_t>(b.mesh("card", card, white)), glm::vec3(0.0f, 0.0f, -4.0f));
    const uint32_t cardNode = static_cast<uint32_t>(b.s.nodes.size() - 1);
    std::vector<Tri> small;
    addQuad(small, glm::vec3(0.0f), glm::vec3(0.35f, 0, 0), glm::vec3(0, 0.25f, 0), glm::vec3(0, 0, 1));
    b.node("small", static_cast<int32_t>(b.mesh("small", colored(small, glm::vec3(0.9f, 0.9f, 0.85f)), white)),
           glm::vec3(-0.9f, 0.0f, -3.0f));
    const uint32_t smallNode = static_cast<uint32_t>(b.s.nodes.size() - 1);
    auto slide = [&](uint32_t node, glm::vec3 from, glm::vec3 to) {
        scene::Animation a;
        a.name = "slide" + std::to_string(node);
        a.samplers = {{scene::Interpolation::Linear, {0.0f, 1.0f}, {glm::vec4(from, 0.0f), glm::vec4(to, 0.0f)}}};
        a.channels = {{node, scene::AnimationPath::Translation, 0}};
        b.s.animations.push_back(a);
    };
    slide(cardNode, glm::vec3(-6.0f, 0.0f, -4.0f), glm::vec3(6.0f, 0.0f, -4.0f));
    slide(smallNode, glm::vec3(-0.9f, 2.0f, -3.0f), glm::vec3(-0.9f, -2.0f, -3.0f));
    b.camera(glm::vec3(0.0f), glm::vec3(0.0f, 0.0f, -1.0f), 0.8f);
    return b.write();
}

json sceneNodes(const std::filesystem::path& glb, double fps, double start) {
    return {{"scene", {{"type", "scene.gltf"}, {"params", {{"path", glb.string()}, {"fps", fps}, {"start", start}}}}},
            {"gbuffer", {{"type", "gbuffer.layered"}, {"in", {{"scene", "scene.scene"}}}}}};
}

TEST_F(MotionBlur, MatchesSubFrameAccumulation) {
    auto glb = movingCardsScene();
    // Shutter open for `scale` of the frame interval, centred on kT: sub-frames at its 16 stratum centres.
    const double scale = 1.0, open = scale / kFps;
    json ref = sceneNodes(glb, kSubFrames / open, kT - 0.5 * open + 0.5 * open / kSubFrames);
    ref["accumulate"] = {{"type", "aa.accumulate"},
                         {"in", {{"color", "gbuffer.base_color"}, {"history", "accumulate.color@prev"}}}};
    auto reference = runGraph(graph(ref, {{"ref", "accumulate.color"}}, kSW, kSH, kSubFrames)).at("ref");

    json blur = sceneNodes(glb, kFps, kT);
    blur["blur"] = {
        {"type", "post.motion_blur"},
        {"params", {{"scale", scale}}},
        {"in", {{"color", "gbuffer.base_color"}, {"velocity", "gbuffer.velocity"}, {"depth", "gbuffer.normal"}}}};
    auto out = runGraph(graph(
        blur, {{"blur", "blur.color"}, {"sharp", "gbuffer.base_color"}, {"velocity", "gbuffer.velocity"}}, kSW, kSH));
    double maxSpeed = 0.0;
    for (int i = 0; i < kSW * kSH; ++i)
        maxSpeed = std::max(maxSpeed,
                            double(std::hypot(out.at("velocity").pixels[4 * i], out.at("velocity").pixels[4 * i + 1])));
    const double flipBlur = compare::ldrFlip(reference, out.at("blur")).mean;
    const double flipSharp = compare::ldrFlip(reference, out.at("sharp")).mean;
    std::printf("moving cards: max speed %.1f px/frame; LDR-FLIP mean vs the 16-sub-frame accumulation: motion blur "
                "%.4f, no blur %.4f\n",
                maxSpeed, flipBlur, flipSharp);
    if (const char* dir = std::getenv("VITRINE_TEST_IMAGES")) {
        // Side by side: reference, motion blur, no blur (alpha is the G-buffer's metallic: made opaque).
        Image strip(3 * kSW, kSH);
        const Image* parts[3] = {&reference, &out.at("blur"), &out.at("sharp")};
        for (int k = 0; k < 3; ++k)
            for (int y = 0; y < kSH; ++y)
                for (int x = 0; x < kSW; ++x) {
                    for (int c = 0; c < 3; ++c)
                        strip.at(k * kSW + x, y)[c] = parts[k]->at(x, y)[c];
                    strip.at(k * kSW + x, y)[3] = 1.0f;
                }
        writePng(std::filesystem::path(dir) / "motion_blur_ref_blur_sharp.png", strip);
    }
    EXPECT_GT(maxSpeed, 14.0); // the test means something
    EXPECT_LT(flipBlur, 0.5 * flipSharp);
    EXPECT_LT(flipBlur, 0.05);
}

} // namespace
} // namespace vitrine::test
