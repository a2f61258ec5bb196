// post.lens, post.flare and post.streaks against analytic models written out here:
//   - distortion: Gaussian dots on a grid land where r_d = r (1 + k1 r^2 + k2 r^4) (r normalised to the
//     half-diagonal) puts them: centroids within 0.1 px, barrel and pincushion;
//   - lateral CA: a dot's red / blue centroids at the radial scales ca_red / ca_blue of its green one;
//   - vignetting: a flat white input becomes cos^4(atan(r_mm / f)); mechanical vignetting is the share of the pupil
//     disc inside the barrel's opening, counted here on a fine grid of the pupil (not from the closed form);
//   - flare: a bright dot's ghosts are centred at c + s_i (q - c), on the line through the centre, each carrying
//     ghost_intensity x tint_i of the bright energy, the ring ghost halo_intensity of it; the bright pass against a
//     CPU bright pass; the composite adds the flare's energy x downsample^2;
//   - streaks: 6 blades give 6 spikes and 7 give 14 (runs above half the maximum on a circle around the dot), and
//     the spike's extent scales with the f-number (f/16 vs f/4: x4).
#include "tests/gpu/post_test_util.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>

namespace vitrine::test {
namespace {

using nlohmann::json;
using post::Blob;
using post::centroid;
using post::graph;
using post::loadNode;
using post::writeInput;

constexpr double kPi = std::numbers::pi;

class Lens : public GpuTest {};

void addDot(Image& img, double cx, double cy, double sigma, glm::vec3 value) {
    int r = static_cast<int>(std::ceil(4 * sigma));
    for (int y = std::max(0, int(cy) - r); y <= std::min(img.height - 1, int(cy) + r); ++y)
        for (int x = std::max(0, int(cx) - r); x <= std::min(img.width - 1, int(cx) + r); ++x) {
            double dx = x + 0.5 - cx, dy = y + 0.5 - cy;
            double g = std::exp(-(dx * dx + dy * dy) / (2 * sigma * sigma));
            for (int c = 0; c < 3; ++c)
                img.at(x, y)[c] += static_cast<float>(value[c] * g);
        }
}

Image blank(int w, int h, float value = 0.0f) {
    Image img(w, h);
    for (size_t i = 0; i < img.pixels.size(); ++i)
        img.pixels[i] = (i % 4 == 3) ? 1.0f : value;
    return img;
}

std::map<std::string, Image> runLens(const Image& input, const std::string& name, json params) {
    json nodes = {{"in", loadNode(writeInput(input, name))},
                  {"lens", {{"type", "post.lens"}, {"params", params}, {"in", {{"color", "in.color"}}}}}};
    return runGraph(graph(nodes, {{"out", "lens.color"}}, input.width, input.height));
}

constexpr int kW = 320, kH = 180;

TEST_F(Lens, DistortionMovesGridDotsToTheRadialModel) {
    const double cx = kW / 2.0, cy = kH / 2.0, hd = 0.5 * std::hypot(kW, kH);
    Image grid = blank(kW, kH);
    std::vector<glm::dvec2> dots;
    for (int j = 0; j < 9; ++j)
        for (int i = 0; i < 15; ++i) {
            glm::dvec2 p(10.0 + 20.0 * i + 0.3, 10.0 + 20.0 * j + 0.2);
            dots.push_back(p);
            addDot(grid, p.x, p.y, 1.5, glm::vec3(1.0f));
        }
    for (auto [k1, k2] : {std::pair{-0.2, 0.05}, std::pair{0.15, 0.0}}) {
        json params = {{"distortion", true},
                       {"k1", k1},
                       {"k2", k2},
                       {"chromatic_aberration", false},
                       {"vignetting", false},
                       {"mechanical_vignetting", 0.0}};
        Image out = runLens(grid, "grid", params).at("out");
        double worst = 0.0;
        int measured = 0;
        for (glm::dvec2 p : dots) {
            glm::dvec2 d = (p - glm::dvec2(cx, cy)) / hd;
            double r2 = glm::dot(d, d);
            glm::dvec2 q = glm::dvec2(cx, cy) + d * (1.0 + k1 * r2 + k2 * r2 * r2) * hd;
            if (q.x < 8 || q.y < 8 || q.x > kW - 8 || q.y > kH - 8) continue; // the whole dot in the frame
            Blob b = centroid(out, q.x, q.y, 6.0, 1);
            worst = std::max(worst, std::hypot(b.x - q.x, b.y - q.y));
            ++measured;
        }
        std::printf("distortion k1 %.2f k2 %.2f: %d dots, worst centroid error %.4f px\n", k1, k2, measured, worst);
        EXPECT_GT(measured, 80);
        EXPECT_LT(worst, 0.1);
    }
}

TEST_F(Lens, ChromaticAberrationScalesRedAndBlueRadially) {
    const double cx = kW / 2.0, cy = kH / 2.0;
    const double red = 1.01, blue = 0.985;
    Image img = blank(kW, kH);
    std::vector<glm::dvec2> dots = {{40.3, 30.2}, {280.6, 150.1}, {100.0, 160.0}, {250.0, 40.0}, {160.0, 90.0}};
    for (glm::dvec2 p : dots)
        addDot(img, p.x, p.y, 1.5, glm::vec3(1.0f));
    json params = {{"distortion", false}, {"chromatic_aberration", true}, {"ca_red", red},
                   {"ca_blue", blue},     {"vignetting", false},          {"mechanical_vignetting", 0.0}};
    Image out = runLens(img, "ca", params).at("out");
    double worst = 0.0, largest = 0.0;
    for (glm::dvec2 p : dots) {
        glm::dvec2 c(cx, cy);
        for (auto [channel, scale] : {std::pair{0, red}, std::pair{1, 1.0}, std::pair{2, blue}}) {
            glm::dvec2 q = c + (p - c) * scale;
            Blob b = centroid(out, q.x, q.y, 6.0, channel);
            worst = std::max(worst, std::hypot(b.x - q.x, b.y - q.y));
            largest = std::max(largest, glm::length(q - p));
        }
    }
    std::printf("lateral CA: largest offset %.2f px, worst centroid error %.4f px\n", largest, worst);
    EXPECT_GT(largest, 1.5);
    EXPECT_LT(worst, 0.1);
}

// Share of a disc of radius `pupil` centred at offset d that lies inside the unit disc, by counting a fine grid.
double pupilInsideOpening(double pupil, double d) {
    const int n = 600;
    int inside = 0, total = 0;
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
            double x = (2.0 * (i + 0.5) / n - 1.0) * pupil, y = (2.0 * (j + 0.5) / n - 1.0) * pupil;
            if (x * x + y * y > pupil * pupil) continue;
            ++total;
            if ((x + d) * (x + d) + y * y <= 1.0) ++inside;
        }
    return static_cast<double>(inside) / total;
}

TEST_F(Lens, VignettingFollowsCos4AndThePupilClippedByTheBarrel) {
    const double focal = 20.0, sensor = 36.0, hd = 0.5 * std::hypot(kW, kH);
    Image white = blank(kW, kH, 1.0f);
    json natural = {{"distortion", false},   {"chromatic_aberration", false}, {"vignetting", true},
                    {"focal_length", focal}, {"sensor_width", sensor},        {"mechanical_vignetting", 0.0}};
    Image out = runLens(white, "white", natural).at("out");
    double worst = 0.0, corner = 1.0;
    for (int y = 0; y < kH; ++y)
        for (int x = 0; x < kW; ++x) {
            double r = std::hypot(x + 0.5 - kW / 2.0, y + 0.5 - kH / 2.0) * sensor / kW;
            double expected = std::pow(std::cos(std::atan(r / focal)), 4.0);
            corner = std::min(corner, expected);
            for (int c = 0; c < 3; ++c)
                worst = std::max(worst, std::fabs(out.at(x, y)[c] - expected));
        }
    std::printf("natural vignetting (f %.0f mm): corner %.3f, worst error %.2e\n", focal, corner, worst);
    EXPECT_LT(corner, 0.5);
    EXPECT_LT(worst, 1e-4);

    // The same from a camera state (focal length 20 mm, 36 mm sensor, no residual distortion or CA, no mechanical
    // vignetting): it replaces the params, whose defaults (barrel distortion, CA, 35 mm, mechanical 0.6) would differ.
    json fromState = {
        {"in", loadNode(writeInput(white, "white_state"))},
        {"camera", {{"type", "test.camera_state"}, {"params", {{"focal_length", focal}}}}},
        {"lens", {{"type", "post.lens"}, {"in", {{"color", "in.color"}, {"camera_state", "camera.state"}}}}}};
    EXPECT_LT(maxAbsDiff(runGraph(graph(fromState, {{"out", "lens.color"}}, kW, kH)).at("out"), out), 1e-6);

    // Mechanical: wide open (pupil 1) and one stop down (pupil 1/sqrt 2), the opening offset 0.8 radii at the corner.
    for (double fNumber : {2.0, 2.0 * std::sqrt(2.0)}) {
        json mech = {{"distortion", false},          {"chromatic_aberration", false}, {"vignetting", false},
                     {"mechanical_vignetting", 0.8}, {"f_number", fNumber},           {"wide_open", 2.0}};
        Image m = runLens(white, "white", mech).at("out");
        double err = 0.0, darkest = 1.0;
        for (int y = 0; y < kH; y += 6)
            for (int x = 0; x < kW; x += 6) {
                double d = 0.8 * std::hypot(x + 0.5 - kW / 2.0, y + 0.5 - kH / 2.0) / hd;
                double expected = pupilInsideOpening(2.0 / fNumber, d);
                darkest = std::min(darkest, expected);
                err = std::max(err, std::fabs(m.at(x, y)[1] - expected));
            }
        std::printf("mechanical vignetting at f/%.2f: darkest sampled %.3f, worst error %.4f\n", fNumber, darkest, err);
        EXPECT_LT(darkest, 0.97);
        EXPECT_LT(err, 3e-3); // the grid count's own error
        // The same from a camera state: f-number and mechanical vignetting read from its GPU buffer by the shader.
        json mechState = {
            {"in", loadNode(writeInput(white, "white_mech"))},
            {"camera", {{"type", "test.camera_state"},
                        {"params", {{"f_number", fNumber}, {"wide_open", 2.0}, {"mechanical", 0.8}}}}},
            {"lens", {{"type", "post.lens"},
                      {"params", {{"distortion", false}, {"chromatic_aberration", false}, {"vignetting", false}}},
                      {"in", {{"color", "in.color"}, {"camera_state", "camera.state"}}}}}};
        EXPECT_LT(maxAbsDiff(runGraph(graph(mechState, {{"out", "lens.color"}}, kW, kH)).at("out"), m), 1e-5);
    }
}

// ---------------------------------------------------------------------------------------------------------------
// post.flare

constexpr int kFW = 640, kFH = 360, kFactor = 4;
// shaders/post/flare_ghosts.comp's tints (documented there).
const glm::dvec3 kTints[8] = {{1.0, 0.75, 0.5}, {0.5, 0.8, 1.0},   {0.6, 1.0, 0.6},  {1.0, 0.6, 0.9},
                              {0.9, 0.9, 0.6},  {0.55, 0.65, 1.0}, {1.0, 0.85, 0.7}, {0.7, 1.0, 0.9}};

double channelSum(const Image& img, int c) {
    double s = 0.0;
    for (int i = 0; i < img.width * img.height; ++i)
        s += img.pixels[4 * i + c];
    return s;
}

TEST_F(Lens, FlareGhostsLieOnTheLineThroughTheCentreWithTheirEnergy) {
    // A bright dot at q; in bright-pass pixels the centre is (80, 45) and q - c = (50, 20).
    const glm::dvec2 cLow(kFW / 2.0 / kFactor, kFH / 2.0 / kFactor), dLow(50.0, 20.0);
    const glm::dvec2 q = (cLow + dLow) * double(kFactor);
    Image img = blank(kFW, kFH, 0.01f);
    addDot(img, q.x, q.y, 8.0, glm::vec3(60.0f, 50.0f, 40.0f));
    const double scales[4] = {-0.3, -0.8, 0.55, -1.3};
    const double ghostIntensity = 0.05, threshold = 1.0;
    json params = {{"threshold", threshold},
                   {"downsample", kFactor},
                   {"ghost_intensity", ghostIntensity},
                   {"ghost_scales", {scales[0], scales[1], scales[2], scales[3]}},
                   {"ghost_scales2", {0, 0, 0, 0}},
                   {"halo_intensity", 0.0}};
    json nodes = {{"in", loadNode(writeInput(img, "flare_dot"))},
                  {"flare", {{"type", "post.flare"}, {"params", params}, {"in", {{"color", "in.color"}}}}}};
    auto out = runGraph(
        graph(nodes, {{"out", "flare.color"}, {"flare", "flare.flare"}, {"bright", "flare.bright"}}, kFW, kFH));

    // The bright pass against one computed here.
    const Image& bright = out.at("bright");
    double brightErr = 0.0;
    glm::dvec3 energy(0.0);
    for (int y = 0; y < bright.height; ++y)
        for (int x = 0; x < bright.width; ++x) {
            glm::dvec3 sum(0.0);
            for (int j = 0; j < kFactor; ++j)
                for (int i = 0; i < kFactor; ++i) {
                    const float* p = img.at(x * kFactor + i, y * kFactor + j);
                    double l = 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
                    if (l > threshold) sum += glm::dvec3(p[0], p[1], p[2]) * ((l - threshold) / l);
                }
            sum /= kFactor * kFactor;
            energy += sum;
            for (int c = 0; c < 3; ++c)
                brightErr = std::max(brightErr, std::fabs(bright.at(x, y)[c] - sum[c]) / (1.0 + sum[c]));
        }
    std::printf("flare bright pass: energy (%.1f %.1f %.1f), worst relative error %.2e\n", energy.r, energy.g, energy.b,
                brightErr);
    EXPECT_LT(brightErr, 2e-3); // rgba16f

    const Image& flare = out.at("flare");
    glm::dvec3 ghostTotal(0.0);
    for (int i = 0; i < 4; ++i) {
        glm::dvec2 g = cLow + scales[i] * dLow;
        const double r = 4.0 * 2.0 * std::fabs(scales[i]) + 4.0; // 4 sigma of the ghost's blob, plus the bilinear
        glm::dvec3 e;
        Blob b;
        for (int c = 0; c < 3; ++c) {
            Blob bc = centroid(flare, g.x, g.y, r, c);
            e[c] = bc.sum;
            if (c == 1) b = bc;
        }
        ghostTotal += e;
        // Distance from the line through the centre and q, and position along it.
        glm::dvec2 rel = glm::dvec2(b.x, b.y) - cLow, dir = glm::normalize(dLow);
        double off = std::fabs(rel.x * dir.y - rel.y * dir.x), along = glm::dot(rel, dir) / glm::length(dLow);
        glm::dvec3 expected = ghostIntensity * kTints[i] * energy;
        std::printf("ghost %d (scale %.2f): centroid (%.2f, %.2f) expected (%.2f, %.2f), off the line %.3f px, "
                    "at scale %.4f; energy/expected %.4f %.4f %.4f\n",
                    i, scales[i], b.x, b.y, g.x, g.y, off, along, e.r / expected.r, e.g / expected.g, e.b / expected.b);
        EXPECT_LT(off, 0.25);
        EXPECT_NEAR(along, scales[i], 0.25 / glm::length(dLow));
        for (int c = 0; c < 3; ++c)
            EXPECT_NEAR(e[c] / expected[c], 1.0, 0.03) << "ghost " << i << " channel " << c;
    }
    // Nothing but the ghosts: the whole flare image holds their energy.
    for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(channelSum(flare, c) / ghostTotal[c], 1.0, 0.01);
    // The composite adds the flare, upsampled: downsample^2 its energy.
    Image diff = out.at("out");
    for (size_t i = 0; i < diff.pixels.size(); ++i)
        diff.pixels[i] -= img.pixels[i];
    for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(channelSum(diff, c) / (kFactor * kFactor * channelSum(flare, c)), 1.0, 0.01) << "channel " << c;
}

TEST_F(Lens, FlareRingGhostSurroundsTheMirroredSource) {
    const glm::dvec2 cLow(kFW / 2.0 / kFactor, kFH / 2.0 / kFactor), dLow(30.0, -12.0);
    const glm::dvec2 q = (cLow + dLow) * double(kFactor);
    Image img = blank(kFW, kFH);
    addDot(img, q.x, q.y, 4.0, glm::vec3(80.0f));
    const double radius = 0.3, halo = 0.02;
    json params = {{"downsample", kFactor},
                   {"ghost_intensity", 0.0},
                   {"halo_intensity", halo},
                   {"halo_radius", radius},
                   {"halo_taps", 96}};
    json nodes = {{"in", loadNode(writeInput(img, "halo_dot"))},
                  {"flare", {{"type", "post.flare"}, {"params", params}, {"in", {{"color", "in.color"}}}}}};
    auto out = runGraph(graph(nodes, {{"flare", "flare.flare"}, {"bright", "flare.bright"}}, kFW, kFH));
    const Image& flare = out.at("flare");
    const glm::dvec2 m = cLow - dLow; // the mirror image 2c - q
    const double rLow = radius * 0.5 * std::hypot(kFW, kFH) / kFactor;
    double sum = 0.0, sumR = 0.0, sumR2 = 0.0;
    for (int y = 0; y < flare.height; ++y)
        for (int x = 0; x < flare.width; ++x) {
            double v = flare.at(x, y)[1], r = std::hypot(x + 0.5 - m.x, y + 0.5 - m.y);
            sum += v;
            sumR += v * r;
            sumR2 += v * r * r;
        }
    double meanR = sumR / sum, spread = std::sqrt(std::max(0.0, sumR2 / sum - meanR * meanR));
    double ratio = sum / (halo * channelSum(out.at("bright"), 1));
    std::printf("ring ghost: mean radius %.2f px (expected %.2f), spread %.2f px, energy/expected %.4f\n", meanR, rLow,
                spread, ratio);
    EXPECT_NEAR(meanR, rLow, 0.5);
    EXPECT_LT(spread, 2.0);
    EXPECT_NEAR(ratio, 1.0, 0.01);
}

// ---------------------------------------------------------------------------------------------------------------
// post.streaks

std::map<std::string, Image> runStreaks(const Image& img, json params, json state = nullptr) {
    json nodes = {{"in", loadNode(writeInput(img, "streak_dot"))},
                  {"streaks", {{"type", "post.streaks"}, {"params", params}, {"in", {{"color", "in.color"}}}}}};
    if (!state.is_null()) {
        nodes["camera"] = {{"type", "test.camera_state"}, {"params", state}};
        nodes["streaks"]["in"]["camera_state"] = "camera.state";
    }
    return runGraph(graph(
        nodes, {{"out", "streaks.color"}, {"streaks", "streaks.streaks"}, {"bright", "streaks.bright"}}, kFW, kFH));
}

double bilinear(const Image& img, double x, double y, int c) {
    double fx = x - 0.5, fy = y - 0.5;
    int ix = static_cast<int>(std::floor(fx)), iy = static_cast<int>(std::floor(fy));
    double tx = fx - ix, ty = fy - iy, v = 0.0;
    for (int k = 0; k < 4; ++k) {
        int px = std::clamp(ix + (k & 1), 0, img.width - 1), py = std::clamp(iy + (k >> 1), 0, img.height - 1);
        v += ((k & 1) ? tx : 1 - tx) * ((k >> 1) ? ty : 1 - ty) * img.at(px, py)[c];
    }
    return v;
}

// Spikes around (x, y): runs of the circle of radius r where the streak is above half its maximum there.
int countSpikes(const Image& s, double x, double y, double r) {
    const int n = 2880;
    std::vector<double> v(n);
    for (int i = 0; i < n; ++i) {
        double a = 2 * kPi * i / n;
        v[i] = bilinear(s, x + r * std::cos(a), y + r * std::sin(a), 1);
    }
    double top = *std::max_element(v.begin(), v.end());
    int runs = 0;
    for (int i = 0; i < n; ++i)
        if (v[i] > 0.5 * top && v[(i + n - 1) % n] <= 0.5 * top) ++runs;
    return runs;
}

// post.flare and post.streaks composite: out = in + their layer (at 1 / downsample of the frame) read bilinearly at
// each pixel's centre, zero outside, per channel. A coloured background and a coloured dot, so that a channel read
// wrong or a layer shifted by a fraction of its pixel shows; the bound is RGBA16F's rounding.
TEST_F(Lens, FlareAndStreaksAddTheirUpsampledLayerToTheImage) {
    Image img(kFW, kFH);
    for (int y = 0; y < kFH; ++y)
        for (int x = 0; x < kFW; ++x) {
            float* p = img.at(x, y);
            p[0] = 0.1f + 0.3f * static_cast<float>(x) / kFW;
            p[1] = 0.45f;
            p[2] = 0.8f - 0.3f * static_cast<float>(y) / kFH;
            p[3] = 1.0f;
        }
    addDot(img, 0.37 * kFW, 0.41 * kFH, 4.0, glm::vec3(300.0f, 120.0f, 40.0f));
    const json flare = {{"downsample", kFactor}, {"ghost_intensity", 0.05}, {"halo_intensity", 0.02}};
    const json streaks = {
        {"downsample", kFactor}, {"length", 0.3}, {"strength", 0.2}, {"blades", 6}, {"f_number", 8.0}};
    for (const auto& [type, params] : {std::pair<std::string, json>{"post.flare", flare}, {"post.streaks", streaks}}) {
        SCOPED_TRACE(type);
        const std::string layer = type == "post.flare" ? "flare" : "streaks";
        json nodes = {{"in", loadNode(writeInput(img, "composite_dot"))},
                      {"lens", {{"type", type}, {"params", params}, {"in", {{"color", "in.color"}}}}}};
        auto out = runGraph(graph(nodes, {{"out", "lens.color"}, {"layer", "lens." + layer}}, kFW, kFH));
        const Image& low = out.at("layer");
        ASSERT_EQ(low.width, kFW / kFactor);
        auto layerAt = [&](double px, double py, int c) { // bilinear, zero outside, at low-resolution position (px, py)
            const double qx = px - 0.5, qy = py - 0.5;
            const int ix = static_cast<int>(std::floor(qx)), iy = static_cast<int>(std::floor(qy));
            const double fx = qx - ix, fy = qy - iy;
            double sum = 0.0;
            for (int k = 0; k < 4; ++k) {
                const int tx = ix + (k & 1), ty = iy + (k >> 1);
                if (tx < 0 || ty < 0 || tx >= low.width || ty >= low.height) continue;
                sum += ((k & 1) ? fx : 1.0 - fx) * ((k >> 1) ? fy : 1.0 - fy) * low.at(tx, ty)[c];
            }
            return sum;
        };
        double worst = 0.0, added = 0.0;
        for (int y = 0; y < kFH; ++y)
            for (int x = 0; x < kFW; ++x)
                for (int c = 0; c < 3; ++c) {
                    const double l = layerAt((x + 0.5) / kFactor, (y + 0.5) / kFactor, c);
                    const double expected = img.at(x, y)[c] + l;
                    const double err = std::fabs(out.at("out").at(x, y)[c] - expected) / (1.0 + expected);
                    worst = std::isnan(err) ? 1e30 : std::max(worst, err);
                    added += l;
                }
        std::printf("%s composite: layer energy %.1f, worst relative error of in + layer %.2e\n", type.c_str(), added,
                    worst);
        EXPECT_GT(added, 100.0); // the layer is there
        EXPECT_LT(worst, 2e-3);
    }
}

TEST_F(Lens, StreakCountFollowsTheBladesAndLengthTheFNumber) {
    const glm::dvec2 cLow(kFW / 2.0 / kFactor, kFH / 2.0 / kFactor);
    Image img = blank(kFW, kFH);
    addDot(img, kFW / 2.0, kFH / 2.0, 3.0, glm::vec3(400.0f));
    json base = {{"downsample", kFactor}, {"length", 0.35}, {"strength", 0.2}, {"rotation", 10.0}};
    json six = base;
    six["blades"] = 6;
    six["f_number"] = 8.0;
    auto run6 = runStreaks(img, six);
    int spikes6 = countSpikes(run6.at("streaks"), cLow.x, cLow.y, 12.0);
    // Energy: strength x N / 8 of the bright pass's (no spike reaches the frame's edge), and the composite adds
    // downsample^2 times it.
    const double streakEnergy = channelSum(run6.at("streaks"), 1), brightEnergy = channelSum(run6.at("bright"), 1);
    Image added = run6.at("out");
    for (size_t i = 0; i < added.pixels.size(); ++i)
        added.pixels[i] -= img.pixels[i];
    std::printf("streak energy / (strength x bright energy) %.4f; composite / (16 x streaks) %.4f\n",
                streakEnergy / (0.2 * brightEnergy), channelSum(added, 1) / (kFactor * kFactor * streakEnergy));
    EXPECT_NEAR(streakEnergy / (0.2 * brightEnergy), 1.0, 0.01);
    EXPECT_NEAR(channelSum(added, 1) / (kFactor * kFactor * streakEnergy), 1.0, 0.01);
    // Seven blades from a camera state (f/11, wide open f/1.8: the blades are in).
    int spikes7 = countSpikes(
        runStreaks(img, base, {{"blades", 7}, {"f_number", 11.0}, {"wide_open", 1.8}, {"exposure", 1.0}}).at("streaks"),
        cLow.x, cLow.y, 12.0);
    std::printf("streaks: 6 blades -> %d spikes, 7 blades -> %d spikes\n", spikes6, spikes7);
    EXPECT_EQ(spikes6, 6);
    EXPECT_EQ(spikes7, 14);
    // Wide open the aperture is round: no streaks.
    double wideOpen = channelSum(
        runStreaks(img, base, {{"blades", 7}, {"f_number", 1.8}, {"wide_open", 1.8}, {"exposure", 1.0}}).at("streaks"),
        1);
    EXPECT_EQ(wideOpen, 0.0);
    // A camera state's f-number and exposure, which the shaders read on the GPU, act as the same params: f/8 with the
    // blades in, exposure 1/2 (the param's -1 stop) moving the bright pass.
    json plain = base;
    plain["blades"] = 6;
    plain["rotation"] = 0.0;
    plain["f_number"] = 8.0;
    plain["exposure"] = -1.0;
    auto byParams = runStreaks(img, plain);
    auto byState = runStreaks(img, base, {{"blades", 6}, {"f_number", 8.0}, {"wide_open", 1.8}, {"exposure", 0.5}});
    for (const char* name : {"bright", "streaks", "out"}) {
        const double d = maxAbsDiff(byParams.at(name), byState.at(name));
        std::printf("streaks from a camera state vs params: %s max |diff| %.3g\n", name, d);
        EXPECT_LT(d, 1e-3) << name;
    }
    EXPECT_GT(maxAbsDiff(byParams.at("bright"), run6.at("bright")), 0.1); // the exposure matters

    // Extent of a spike: its intensity-weighted mean distance from the source along it (rotation 0: along +x).
    auto extent = [&](double fNumber) {
        json p = base;
        p["blades"] = 6;
        p["rotation"] = 0.0;
        p["f_number"] = fNumber;
        Image s = runStreaks(img, p).at("streaks");
        double sum = 0.0, sumT = 0.0;
        for (double t = 1.0; t < 79.0; t += 0.25) {
            double v = bilinear(s, cLow.x + t, cLow.y, 1);
            sum += v;
            sumT += v * t;
        }
        return sumT / sum;
    };
    // The model: L = length x (frame height / downsample) x N / 8; the mean distance of exp(-3 t / L) on [0, L] is
    // (L / 3)(1 - 4 e^-3) / (1 - e^-3) = 0.2811 L. The source's own 2 x 2-texel footprint adds under a pixel.
    auto model = [&](double fNumber) {
        double L = 0.35 * (kFH / kFactor) * fNumber / 8.0;
        return L / 3.0 * (1.0 - 4.0 * std::exp(-3.0)) / (1.0 - std::exp(-3.0));
    };
    double e4 = extent(4.0), e16 = extent(16.0);
    std::printf("streak mean distance: f/4 %.2f px (model %.2f), f/16 %.2f px (model %.2f)\n", e4, model(4.0), e16,
                model(16.0));
    EXPECT_NEAR(e4, model(4.0), 1.0);
    EXPECT_NEAR(e16, model(16.0), 1.0);
    EXPECT_GT(e16, 3.0 * e4);
}

} // namespace
} // namespace vitrine::test
