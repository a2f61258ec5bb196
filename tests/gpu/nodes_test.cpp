// Each node against an independent CPU evaluation of the same maths, on the Vulkan device the
// machine has (lavapipe in CI), with validation on.
#include "tests/gpu/gpu_test.hpp"

#include "core/base/error.hpp"
#include "core/image/color.hpp"
#include "core/image/io.hpp"
#include "tests/gpu/cli.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>

namespace vitrine::test {
namespace {

using nlohmann::json;

json checkerNode() {
    // Supersampled edges give a spread of values between the two HDR colours.
    return {{"type", "pattern.checker"},
            {"params",
             {{"cell_size", 5.0}, {"angle", 13.0}, {"supersample", 3},
              {"color_a", {0.02, 0.1, 0.3, 1.0}}, {"color_b", {6.0, 2.5, 0.7, 1.0}}}}};
}

json graph(json nodes, json outputs, int w = 96, int h = 64) {
    return {{"format", "vitrine-graph/1"}, {"frame", {{"width", w}, {"height", h}}}, {"nodes", nodes}, {"outputs", outputs}};
}

float cpuTonemap(float x, const std::string& op, float maxChannel) {
    if (op == "reinhard") return x / (1.0f + x);
    if (op == "reinhard_max") return x / (1.0f + maxChannel);
    if (op == "aces_fit") return std::clamp((x * (2.51f * x + 0.03f)) / (x * (2.43f * x + 0.59f) + 0.14f), 0.0f, 1.0f);
    return x;
}

class Nodes : public GpuTest {};

TEST_F(Nodes, TonemapMatchesCpuFormula) {
    for (std::string op : {"linear", "reinhard", "reinhard_max", "aces_fit"}) {
        const float exposure = 0.7f;
        auto out = runGraph(graph({{"src", checkerNode()},
                                   {"tm", {{"type", "post.tonemap"},
                                           {"params", {{"operator", op}, {"exposure", exposure}}},
                                           {"in", {{"color", "src.color"}}}}}},
                                  {{"in", "src.color"}, {"out", "tm.color"}}));
        const Image& in = out.at("in");
        const Image& tm = out.at("out");
        double worst = 0.0;
        for (int y = 0; y < in.height; ++y)
            for (int x = 0; x < in.width; ++x) {
                const float* p = in.at(x, y);
                float scaled[3], m = 0.0f;
                for (int c = 0; c < 3; ++c) m = std::max(m, scaled[c] = p[c] * std::exp2(exposure));
                for (int c = 0; c < 3; ++c) {
                    double expected = cpuTonemap(scaled[c], op, m);
                    worst = std::max(worst, std::fabs(expected - tm.at(x, y)[c]) / std::max(1.0, std::fabs(expected)));
                }
            }
        EXPECT_LT(worst, 1e-5) << op;
    }
}

// Khronos PBR Neutral from the published formula (KhronosGroup/ToneMapping, PBR_Neutral), in double precision:
// offset (toe below 0.08, else the 0.04 of a dielectric's reflection), then above the compression start 0.76 the
// largest channel goes to 1 - (1 - start)^2 / (peak + 1 - 2 start) and the colour towards grey by
// 1 - 1 / (0.15 (peak - newPeak) + 1).
glm::dvec3 specPbrNeutral(glm::dvec3 c) {
    const double start = 0.76, desaturation = 0.15;
    const double low = std::min({c.r, c.g, c.b});
    c -= low < 0.08 ? low - 6.25 * low * low : 0.04;
    const double peak = std::max({c.r, c.g, c.b});
    if (peak < start) return c;
    const double newPeak = 1.0 - (1.0 - start) * (1.0 - start) / (peak + (1.0 - start) - start);
    const double g = 1.0 - 1.0 / (desaturation * (peak - newPeak) + 1.0);
    glm::dvec3 out;
    for (int i = 0; i < 3; ++i) out[i] = (1.0 - g) * c[i] * (newPeak / peak) + g * newPeak;
    return out;
}

// One pixel per colour of `colors` (a row), written as a float EXR and tone mapped by post.tonemap.
Image tonemapColors(const std::vector<glm::dvec3>& colors, const std::string& op, double exposure, const std::string& name) {
    const int w = static_cast<int>(colors.size());
    Image img(w, 1);
    for (int x = 0; x < w; ++x) {
        for (int c = 0; c < 3; ++c) img.at(x, 0)[c] = static_cast<float>(colors[x][c]);
        img.at(x, 0)[3] = 1.0f;
    }
    const std::filesystem::path dir = freshDir(name);
    writeExr(dir / "colors.exr", img, ExrPixelType::Float);
    return runGraph(graph({{"img", {{"type", "image.load"}, {"params", {{"path", (dir / "colors.exr").string()}}}}},
                           {"tm", {{"type", "post.tonemap"},
                                   {"params", {{"operator", op}, {"exposure", exposure}}},
                                   {"in", {{"color", "img.color"}}}}}},
                          {{"out", "tm.color"}}, w, 1))
        .at("out");
}

// HSV hue in degrees.
double hueDegrees(glm::dvec3 c) {
    const double hi = std::max({c.r, c.g, c.b}), lo = std::min({c.r, c.g, c.b}), d = hi - lo;
    if (d <= 0.0) return 0.0;
    double h = hi == c.r ? std::fmod((c.g - c.b) / d + 6.0, 6.0) : hi == c.g ? (c.b - c.r) / d + 2.0 : (c.r - c.g) / d + 4.0;
    return 60.0 * h;
}

TEST_F(Nodes, PbrNeutralMatchesTheSpecFormulaOnAnHdrRamp) {
    // Greys and hues from black to 64 in 1/8 stops, both sides of the toe (0.08), of the compression start (0.76)
    // and far into the shoulder; exposure 0.5 EV so the scale is applied before the curve.
    const std::vector<glm::dvec3> hues = {{1, 1, 1}, {1, 0.218, 0}, {0.05, 0.3, 1}, {0.2, 1, 0.4}, {1, 0.6, 0.9}, {1, 0.02, 0.3}};
    std::vector<glm::dvec3> colors;
    for (const glm::dvec3& hue : hues)
        for (int step = -80; step <= 48; ++step) colors.push_back(hue * std::exp2(step / 8.0));
    colors.push_back(glm::dvec3(0.0));
    const double exposure = 0.5;
    const Image out = tonemapColors(colors, "pbr_neutral", exposure, "pbr_neutral_ramp");
    double worst = 0.0;
    int below = 0, toe = 0, above = 0;
    for (size_t i = 0; i < colors.size(); ++i) {
        const glm::dvec3 in = colors[i] * std::exp2(exposure);
        const glm::dvec3 expected = specPbrNeutral(in);
        const double low = std::min({in.r, in.g, in.b}), peak = std::max({in.r, in.g, in.b});
        if (low < 0.08) ++toe;
        if (peak > 0.9) ++above;
        else ++below;
        for (int c = 0; c < 3; ++c) {
            const float got = out.at(static_cast<int>(i), 0)[c];
            worst = std::max(worst, std::fabs(expected[c] - got));
            ASSERT_LE(got, 1.0f + 1e-6f) << "colour " << i;
            ASSERT_GE(got, -1e-6f) << "colour " << i;
        }
    }
    EXPECT_LT(worst, 1e-5);
    EXPECT_GT(toe, 50);
    EXPECT_GT(below, 100);
    EXPECT_GT(above, 100);
}

TEST_F(Nodes, PbrNeutralKeepsBaseColoursAndHues) {
    // The spec's promise: a base colour whose channels lie below the compression start comes out as itself at
    // exposure 1 (scale 1), lit (base + the 0.04 of a dielectric's reflection, every channel then >= 0.08) or
    // unlit (a channel at 0: no offset).
    std::vector<glm::dvec3> bases;
    for (double r : {0.04, 0.2, 0.5, 0.75})
        for (double g : {0.04, 0.35, 0.7})
            for (double b : {0.04, 0.1, 0.6}) bases.push_back({r, g, b});
    std::vector<glm::dvec3> colors;
    for (const glm::dvec3& b : bases) colors.push_back(b + 0.04);
    for (const glm::dvec3& b : bases) colors.push_back({b.r, 0.0, b.b});
    const Image out = tonemapColors(colors, "pbr_neutral", 0.0, "pbr_neutral_bases");
    for (size_t i = 0; i < colors.size(); ++i) {
        const glm::dvec3 want = i < bases.size() ? bases[i] : colors[i];
        for (int c = 0; c < 3; ++c)
            EXPECT_NEAR(out.at(static_cast<int>(i), 0)[c], want[c], 1.0 / 255.0) << "colour " << i << " channel " << c;
    }
    // Above the compression start the hue stays: UnlitTest's orange (1, 0.218, 0) stays orange (hue 13 degrees)
    // under PBR Neutral, where the ACES fit turns it amber (24 degrees) and a saturated blue cyan-ward.
    const std::vector<glm::dvec3> unlit = {{1.0, 0.218, 0.0}, {0.0, 0.218, 1.0}};
    const Image neutral = tonemapColors(unlit, "pbr_neutral", 0.0, "pbr_neutral_unlit");
    const Image aces = tonemapColors(unlit, "aces_fit", 0.0, "aces_unlit");
    for (int i = 0; i < 2; ++i) {
        auto px = [&](const Image& img) { return glm::dvec3(img.at(i, 0)[0], img.at(i, 0)[1], img.at(i, 0)[2]); };
        const double want = hueDegrees(unlit[i]);
        EXPECT_NEAR(hueDegrees(px(neutral)), want, 1.0) << "colour " << i;
        EXPECT_GT(std::fabs(hueDegrees(px(aces)) - want), 5.0) << "colour " << i << ": ACES was expected to shift it";
        EXPECT_NEAR(px(neutral)[i == 0 ? 0 : 2], specPbrNeutral(unlit[i])[i == 0 ? 0 : 2], 1e-5);
    }
}

TEST_F(Nodes, InvertibleCurvesRoundTrip) {
    for (std::string op : {"reinhard", "reinhard_max"}) {
        auto out = runGraph(graph(
            {{"src", checkerNode()},
             {"fwd", {{"type", "post.tonemap"}, {"params", {{"operator", op}, {"exposure", 1.5}}}, {"in", {{"color", "src.color"}}}}},
             {"inv",
              {{"type", "post.tonemap"},
               {"params", {{"operator", op}, {"exposure", 1.5}, {"inverse", true}}},
               {"in", {{"color", "fwd.color"}}}}}},
            {{"in", "src.color"}, {"round", "inv.color"}}));
        const Image& in = out.at("in");
        const Image& round = out.at("round");
        double worst = 0.0;
        for (size_t i = 0; i < in.pixels.size(); ++i)
            if (i % 4 != 3) worst = std::max(worst, static_cast<double>(std::fabs(in.pixels[i] - round.pixels[i]) / std::max(1e-3f, in.pixels[i])));
        EXPECT_LT(worst, 1e-4) << op;
    }
}

TEST_F(Nodes, AcesInverseIsAUserError) {
    json g = graph({{"src", checkerNode()},
                    {"tm", {{"type", "post.tonemap"}, {"params", {{"inverse", true}}}, {"in", {{"color", "src.color"}}}}}},
                   {{"out", "tm.color"}});
    try {
        runGraph(g);
        FAIL() << "expected a UserError";
    } catch (const UserError& e) {
        EXPECT_NE(std::string(e.what()).find("/nodes/tm/params/inverse"), std::string::npos) << e.what();
    }
}

TEST_F(Nodes, ZoneplateAndCheckerMatchCpuAtPixelCentres) {
    const int w = 80, h = 48;
    auto out = runGraph(graph({{"zs", {{"type", "pattern.zoneplate"}, {"params", {{"mode", "sine"}, {"max_frequency", 0.9}}}}},
                               {"zb", {{"type", "pattern.zoneplate"}, {"params", {{"mode", "binary"}, {"max_frequency", 0.4}}}}},
                               {"ck", {{"type", "pattern.checker"}, {"params", {{"cell_size", 7.0}, {"angle", 30.0}}}}}},
                              {{"sine", "zs.color"}, {"binary", "zb.color"}, {"checker", "ck.color"}}, w, h));
    const double cx = w * 0.5, cy = h * 0.5, radius = std::sqrt(cx * cx + cy * cy), pi = 3.14159265358979;
    int binaryMismatches = 0, checkerMismatches = 0;
    double sineWorst = 0.0;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            double dx = x + 0.5 - cx, dy = y + 0.5 - cy;
            double r2 = dx * dx + dy * dy;
            sineWorst = std::max(sineWorst, std::fabs(0.5 + 0.5 * std::cos(pi * 0.9 * r2 / radius) - out["sine"].at(x, y)[0]));
            double b = std::cos(pi * 0.4 * r2 / radius) >= 0.0 ? 1.0 : 0.0;
            binaryMismatches += std::fabs(b - out["binary"].at(x, y)[0]) > 1e-6;
            double a = 30.0 * pi / 180.0, u = (std::cos(a) * dx + std::sin(a) * dy) / 7.0,
                   v = (-std::sin(a) * dx + std::cos(a) * dy) / 7.0;
            bool odd = ((static_cast<long>(std::floor(u)) + static_cast<long>(std::floor(v))) & 1) != 0;
            checkerMismatches += std::fabs((odd ? 0.9 : 0.05) - out["checker"].at(x, y)[0]) > 1e-6;
        }
    EXPECT_LT(sineWorst, 2e-3); // GPU cos of a large argument in fp32
    // Pixels whose centre sits on an edge may round either way in fp32.
    EXPECT_LE(binaryMismatches, w * h / 200);
    EXPECT_LE(checkerMismatches, w * h / 200);
}

TEST_F(Nodes, FxaaReducesZoneplateErrorAgainstSupersampledReference) {
    const std::string dir = VITRINE_SOURCE_DIR "/graphs/";
    std::vector<std::string> size = {"frame.width=320", "frame.height=180"};
    Image fxaa = runGraphFile(dir + "fxaa_zoneplate.json", size).at("final");
    Image none = runGraphFile(dir + "variants/no_fxaa.json", size).at("final");
    Image truth = runGraphFile(dir + "variants/supersampled.json", size).at("final");
    double eFxaa = rmse(fxaa, truth), eNone = rmse(none, truth);
    RecordProperty("rmse_fxaa", std::to_string(eFxaa));
    RecordProperty("rmse_no_aa", std::to_string(eNone));
    std::printf("zone plate RMSE vs 16x16 supersampled: no AA %.4f, FXAA %.4f (%.1f%% lower)\n", eNone, eFxaa,
                100.0 * (1.0 - eFxaa / eNone));
    // The stated margin: FXAA removes at least 15 % of the aliasing error.
    EXPECT_LT(eFxaa, 0.85 * eNone);
}

TEST_F(Nodes, FxaaLeavesFlatImagesAlone) {
    auto out = runGraph(graph({{"flat", {{"type", "pattern.checker"},
                                         {"params", {{"color_a", {0.4, 0.4, 0.4, 1.0}}, {"color_b", {0.4, 0.4, 0.4, 1.0}}}}}},
                               {"fxaa", {{"type", "aa.fxaa"}, {"in", {{"color", "flat.color"}}}}}},
                              {{"in", "flat.color"}, {"out", "fxaa.color"}}));
    EXPECT_LT(maxAbsDiff(out["in"], out["out"]), 1e-6);
}

// FXAA 3.11 quality, evaluated on the CPU from Lottes' whitepaper (the same steps the node documents: local contrast
// test, sub-pixel blend from the 3x3 low-pass, edge orientation from second differences, a search along the edge for
// both ends, a bilinear re-sample across the edge by the distance to the nearer end), sampling the input as the GPU's
// sampler does (bilinear, clamped to the edge, texel centres at (i + 0.5) / size).
struct CpuFxaa {
    const Image& in;
    float subpix = 0.75f, edgeThreshold = 0.166f, edgeThresholdMin = 0.0833f;
    int searchSteps = 12;

    glm::vec4 texel(int x, int y) const {
        x = std::clamp(x, 0, in.width - 1);
        y = std::clamp(y, 0, in.height - 1);
        const float* p = in.at(x, y);
        return {p[0], p[1], p[2], p[3]};
    }
    glm::vec4 bilinear(glm::vec2 uv) const {
        const glm::vec2 t = uv * glm::vec2(in.width, in.height) - 0.5f;
        const glm::vec2 f = glm::floor(t), w = t - f;
        const int x = static_cast<int>(f.x), y = static_cast<int>(f.y);
        return glm::mix(glm::mix(texel(x, y), texel(x + 1, y), w.x),
                        glm::mix(texel(x, y + 1), texel(x + 1, y + 1), w.x), w.y);
    }
    static float luma(glm::vec4 c) {
        // Perceptual luma: the square root of Rec. 709 luminance.
        return std::sqrt(std::max(0.2126f * c.r + 0.7152f * c.g + 0.0722f * c.b, 0.0f));
    }

    glm::vec4 pixel(int px, int py) const {
        const glm::vec2 inv(1.0f / static_cast<float>(in.width), 1.0f / static_cast<float>(in.height));
        const glm::vec2 uv = (glm::vec2(px, py) + 0.5f) * inv;
        auto L = [&](float dx, float dy) { return luma(bilinear(uv + glm::vec2(dx, dy) * inv)); };
        const glm::vec4 centre = bilinear(uv);
        const float m = luma(centre), n = L(0, -1), s = L(0, 1), w = L(-1, 0), e = L(1, 0);
        const float hi = std::max({n, s, w, e, m}), lo = std::min({n, s, w, e, m});
        const float range = hi - lo;
        if (range < std::max(edgeThresholdMin, hi * edgeThreshold)) return centre;
        const float nw = L(-1, -1), ne = L(1, -1), sw = L(-1, 1), se = L(1, 1);

        // Sub-pixel: the centre against the 3x3 tent average, through a smoothstep, squared, scaled.
        const float average = (2.0f * (n + s + w + e) + (nw + ne + sw + se)) / 12.0f;
        const float x = std::clamp(std::fabs(average - m) / range, 0.0f, 1.0f);
        const float smooth = x * x * (3.0f - 2.0f * x);
        const float subpixBlend = smooth * smooth * subpix;

        // Orientation: the larger sum of second differences across rows (a horizontal edge) or columns.
        const float acrossColumns =
            std::fabs(nw - 2 * w + sw) / 4 + std::fabs(n - 2 * m + s) / 2 + std::fabs(ne - 2 * e + se) / 4;
        const float acrossRows =
            std::fabs(nw - 2 * n + ne) / 4 + std::fabs(w - 2 * m + e) / 2 + std::fabs(sw - 2 * s + se) / 4;
        const bool horizontal = acrossRows >= acrossColumns;
        // The edge lies towards the neighbour (above/left or below/right) with the steeper gradient.
        const float before = horizontal ? n : w, after = horizontal ? s : e;
        const bool towardsBefore = std::fabs(before - m) >= std::fabs(after - m);
        const float pixelStep = (towardsBefore ? -1.0f : 1.0f) * (horizontal ? inv.y : inv.x);
        const float edgeLuma = 0.5f * ((towardsBefore ? before : after) + m);
        const float endThreshold = std::max(std::fabs(before - m), std::fabs(after - m)) / 4.0f;

        // Walk both ways along the edge, half a pixel across it, until the luma leaves the edge's.
        glm::vec2 onEdge = uv;
        (horizontal ? onEdge.y : onEdge.x) += pixelStep / 2.0f;
        const glm::vec2 along = horizontal ? glm::vec2(inv.x, 0.0f) : glm::vec2(0.0f, inv.y);
        static constexpr float kStep[12] = {1, 1, 1, 1, 1, 1.5f, 2, 2, 2, 2, 4, 8};
        glm::vec2 endA = onEdge - along, endB = onEdge + along;
        float deltaA = luma(bilinear(endA)) - edgeLuma, deltaB = luma(bilinear(endB)) - edgeLuma;
        bool foundA = std::fabs(deltaA) >= endThreshold, foundB = std::fabs(deltaB) >= endThreshold;
        for (int i = 1; i < std::min(searchSteps, 12) && !(foundA && foundB); ++i) {
            if (!foundA) {
                endA -= along * kStep[i];
                deltaA = luma(bilinear(endA)) - edgeLuma;
                foundA = std::fabs(deltaA) >= endThreshold;
            }
            if (!foundB) {
                endB += along * kStep[i];
                deltaB = luma(bilinear(endB)) - edgeLuma;
                foundB = std::fabs(deltaB) >= endThreshold;
            }
        }
        const float toA = horizontal ? uv.x - endA.x : uv.y - endA.y;
        const float toB = horizontal ? endB.x - uv.x : endB.y - uv.y;
        const bool nearerA = toA < toB;
        // Blend only where the nearer end moves away from the centre's side of the edge luma.
        const bool staircase = ((nearerA ? deltaA : deltaB) < 0.0f) != (m < edgeLuma);
        const float edgeBlend = staircase ? 0.5f - std::min(toA, toB) / (toA + toB) : 0.0f;
        const float blend = std::max(edgeBlend, subpixBlend);
        glm::vec2 at = uv;
        (horizontal ? at.y : at.x) += blend * pixelStep;
        return {glm::vec3(bilinear(at)), centre.a};
    }
};

TEST_F(Nodes, FxaaMatchesACpuEvaluationPixelByPixel) {
    // Hard slanted edges (long staircases: the edge search and its ends) and a binary zone plate (edges of every
    // orientation and sub-pixel detail), each with non-default params so that every param reaches the shader.
    struct Case {
        const char* name;
        json pattern;
        json params;
        CpuFxaa settings;
    };
    Image none;
    const Case cases[] = {
        {"slanted checker",
         {{"type", "pattern.checker"},
          {"params",
           {{"cell_size", 9.0},
            {"angle", 7.3},
            {"supersample", 2},
            {"color_a", {0.05, 0.3, 0.6, 1.0}},
            {"color_b", {0.9, 0.7, 0.2, 1.0}}}}},
         json::object(),
         {none}},
        {"zone plate",
         {{"type", "pattern.zoneplate"}, {"params", {{"max_frequency", 0.3}}}},
         {{"subpix", 0.5}, {"edge_threshold", 0.125}, {"edge_threshold_min", 0.05}, {"search_steps", 8}},
         {none, 0.5f, 0.125f, 0.05f, 8}},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(c.name);
        auto out =
            runGraph(graph({{"src", c.pattern},
                            {"fxaa", {{"type", "aa.fxaa"}, {"params", c.params}, {"in", {{"color", "src.color"}}}}}},
                           {{"in", "src.color"}, {"out", "fxaa.color"}}, 160, 96));
        const Image& in = out["in"];
        const Image& gpu = out["out"];
        CpuFxaa cpu{in, c.settings.subpix, c.settings.edgeThreshold, c.settings.edgeThresholdMin,
                    c.settings.searchSteps};
        int changed = 0, off = 0;
        double sumDiff = 0.0;
        for (int y = 0; y < in.height; ++y)
            for (int x = 0; x < in.width; ++x) {
                const glm::vec4 want = cpu.pixel(x, y);
                const float* got = gpu.at(x, y);
                const float* was = in.at(x, y);
                float worst = 0.0f, moved = 0.0f;
                for (int k = 0; k < 4; ++k) {
                    worst = std::max(worst, std::fabs(got[k] - want[k]));
                    moved = std::max(moved, std::fabs(want[k] - was[k]));
                }
                if (moved > 0.01f) ++changed;
                sumDiff += worst;
                // The sampler's fixed-point filter weights (lavapipe: 8 bits) move a re-sample by up to about
                // contrast / 256; a comparison on a threshold may flip where the two evaluations differ in rounding.
                if (worst > 0.008f && off < 4)
                    std::printf("  off (%d, %d): gpu %.4f %.4f %.4f cpu %.4f %.4f %.4f in %.4f %.4f %.4f\n", x, y,
                                got[0], got[1], got[2], want[0], want[1], want[2], was[0], was[1], was[2]);
                if (worst > 0.008f) ++off;
            }
        const int pixels = in.width * in.height;
        std::printf("%s: %d of %d pixels changed by FXAA, %d off the CPU evaluation by more than 0.008, mean %.5f\n",
                    c.name, changed, pixels, off, sumDiff / pixels);
        EXPECT_GT(changed, pixels / 50); // the case exercises FXAA
        EXPECT_LE(off, pixels / 800);
        EXPECT_LT(sumDiff / pixels, 3e-4);
    }
}

TEST_F(Nodes, OcioDisplayOnGpuMatchesOcioCpuProcessor) {
    auto out = runGraph(graph({{"src", checkerNode()},
                               {"disp", {{"type", "color.display"}, {"in", {{"color", "src.color"}}}}}},
                              {{"in", "src.color"}, {"display", "disp.color"}}));
    Image cpu = ColorConfig::builtin().toDisplay(out["in"]);
    double worst = 0.0;
    for (size_t i = 0; i < cpu.pixels.size(); ++i)
        if (i % 4 != 3) worst = std::max(worst, std::fabs(static_cast<double>(cpu.pixels[i] - out["display"].pixels[i])) /
                                                    std::max(1.0, std::fabs(static_cast<double>(cpu.pixels[i]))));
    EXPECT_LT(worst, 1e-4);
}

TEST_F(Nodes, DebugViewSelectsChannelAndRange) {
    auto out = runGraph(graph({{"src", checkerNode()},
                               {"view", {{"type", "debug.view"},
                                         {"params", {{"channel", "g"}, {"range", {0.5, 2.5}}}},
                                         {"in", {{"texture", "src.color"}}}}}},
                              {{"in", "src.color"}, {"view", "view.color"}}));
    double worst = 0.0;
    for (int y = 0; y < out["in"].height; ++y)
        for (int x = 0; x < out["in"].width; ++x) {
            double expected = std::clamp((out["in"].at(x, y)[1] - 0.5) / 2.0, 0.0, 1.0);
            for (int c = 0; c < 3; ++c) worst = std::max(worst, std::fabs(expected - out["view"].at(x, y)[c]));
        }
    EXPECT_LT(worst, 1e-3); // rgba16f output
}

TEST_F(Nodes, ImageLoadUploadsTheFileExactly) {
    Image img(17, 9);
    for (size_t i = 0; i < img.pixels.size(); ++i) img.pixels[i] = 0.001f * static_cast<float>(i * 37 % 1000) + 0.25f;
    auto path = std::filesystem::temp_directory_path() / "vitrine_gpu_load_test.exr";
    writeExr(path, img, ExrPixelType::Float);
    auto out = runGraph(graph({{"load", {{"type", "image.load"}, {"params", {{"path", path.string()}}}}}},
                              {{"img", "load.color"}}));
    std::filesystem::remove(path);
    ASSERT_EQ(out["img"].width, 17);
    ASSERT_EQ(out["img"].height, 9);
    EXPECT_EQ(maxAbsDiff(out["img"], img), 0.0);
}

} // namespace
} // namespace vitrine::test
