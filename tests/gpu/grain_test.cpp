// post.grain against statistics of its own definition, measured on a flat mid-grey input (sRGB-encoded 0.5, so no
// clamping): the grain is zero-mean (the encoded mean stays 0.5 within five standard errors of the mean), its
// standard deviation is strength·√(ISO/100), its autocorrelation at lags of one and two lattice spacings equals the
// normalised cubic-B-spline lattice model's (evaluated here on the CPU from the B-spline, not from the shader),
// the spacing grows as (ISO/100)^¼, a frame's grain is the same in every run and different from the next frame's,
// and camera.physical's ISO replaces the param.
#include "tests/gpu/gpu_test.hpp"

#include "core/graph/compiler.hpp"
#include "core/graph/executor.hpp"
#include "core/graph/loader.hpp"
#include "core/graph/registry.hpp"
#include "core/image/io.hpp"
#include "core/shader/compiler.hpp"

#include <cmath>
#include <cstdio>
#include <unistd.h>

namespace vitrine::test {
namespace {

using nlohmann::json;
namespace fs = std::filesystem;

class Grain : public GpuTest {};

constexpr int kW = 768, kH = 768;

double srgbEncode(double v) { return v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1.0 / 2.4) - 0.055; }
double srgbDecode(double v) { return v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4); }

fs::path greyImage() {
    fs::path dir = fs::path(VITRINE_TEST_OUT) / ("grain-" + std::to_string(::getpid()));
    fs::create_directories(dir);
    Image img(kW, kH);
    for (size_t i = 0; i < img.pixels.size(); ++i) img.pixels[i] = (i % 4 == 3) ? 1.0f : float(srgbDecode(0.5));
    fs::path path = dir / "grey.exr";
    writeExr(path, img, ExrPixelType::Float);
    return path;
}

json grainGraph(const json& params, int frames = 1) {
    return {{"format", "vitrine-graph/1"},
            {"frame", {{"width", kW}, {"height", kH}, {"frames", frames}}},
            {"nodes",
             {{"load", {{"type", "image.load"}, {"params", {{"path", greyImage().string()}}}}},
              {"grain", {{"type", "post.grain"}, {"params", params}, {"in", {{"color", "load.color"}}}}}}},
            {"outputs", {{"final", "grain.color"}}}};
}

// Every frame's output as the grain in encoded units (encoded value − 0.5), green channel.
std::vector<std::vector<double>> runFrames(const json& doc) {
    CompiledGraph graph = compileGraph(validateGraph(doc, "grain-test.json", NodeRegistry::global()));
    ShaderCompiler shaders;
    Executor executor(gpu(), graph, shaders);
    std::vector<std::vector<double>> frames;
    RunOptions options;
    options.progress = false;
    for (uint32_t f = 0; f < graph.desc.frame.frames; ++f) options.write.push_back(f);
    options.onOutput = [&](uint32_t, const std::string&, const Image& image) {
        std::vector<double> g(size_t(kW) * kH);
        for (size_t i = 0; i < g.size(); ++i) g[i] = srgbEncode(image.pixels[i * 4 + 1]) - 0.5;
        frames.push_back(std::move(g));
    };
    executor.run(options);
    return frames;
}

struct Stats {
    double mean = 0.0, sd = 0.0;
};
Stats stats(const std::vector<double>& g) {
    Stats s;
    for (double v : g) s.mean += v;
    s.mean /= double(g.size());
    for (double v : g) s.sd += (v - s.mean) * (v - s.mean);
    s.sd = std::sqrt(s.sd / double(g.size()));
    return s;
}

// Normalised autocorrelation at a lag (pixels), the mean of the horizontal and the vertical one.
double autocorrelation(const std::vector<double>& g, int lag) {
    Stats s = stats(g);
    double sum = 0.0;
    long n = 0;
    for (int y = 0; y < kH; ++y)
        for (int x = 0; x + lag < kW; ++x, ++n) sum += (g[y * kW + x] - s.mean) * (g[y * kW + x + lag] - s.mean);
    for (int y = 0; y + lag < kH; ++y)
        for (int x = 0; x < kW; ++x, ++n) sum += (g[y * kW + x] - s.mean) * (g[(y + lag) * kW + x] - s.mean);
    return sum / double(n) / (s.sd * s.sd);
}

double bspline(double t) {
    t = std::fabs(t);
    if (t < 1.0) return (4.0 - 6.0 * t * t + 3.0 * t * t * t) / 6.0;
    if (t < 2.0) return (2.0 - t) * (2.0 - t) * (2.0 - t) / 6.0;
    return 0.0;
}

// The model's correlation between pixels x and x + lag on a lattice of spacing s, averaged over the pixels of a
// row: Σ_i w_i(x) w_i(x + lag) / √(Σ w_i(x)² Σ w_i(x + lag)²), w_i(x) = B((x + 0.5)/s − i). (For a horizontal lag
// the vertical weights are the same for both pixels and cancel; a vertical lag is the same by symmetry.)
double modelAutocorrelation(double s, int lag) {
    double sum = 0.0;
    int n = 0;
    for (int x = 0; x + lag < kW; ++x, ++n) {
        double qa = (x + 0.5) / s, qb = (x + lag + 0.5) / s;
        double ab = 0.0, aa = 0.0, bb = 0.0;
        for (int i = int(std::floor(qa)) - 3; i <= int(std::floor(qb)) + 3; ++i) {
            double a = bspline(qa - i), b = bspline(qb - i);
            ab += a * b;
            aa += a * a;
            bb += b * b;
        }
        sum += ab / std::sqrt(aa * bb);
    }
    return sum / n;
}

// size param that makes the lattice `px` pixels at ISO 100 in a kH-line frame.
double sizeFor(double px) { return px * 1080.0 / kH; }

TEST_F(Grain, ZeroMeanAndStandardDeviationGrowsAsRootIso) {
    const double strength = 0.02, px = 2.0;
    for (double iso : {100.0, 400.0, 1600.0}) {
        auto frames = runFrames(grainGraph({{"iso", iso}, {"strength", strength}, {"size", sizeFor(px)}}));
        ASSERT_EQ(frames.size(), 1u);
        Stats s = stats(frames[0]);
        const double sigma = strength * std::sqrt(iso / 100.0);
        const double spacing = px * std::pow(iso / 100.0, 0.25);
        // Standard error of the mean of correlated grain: σ s / (∫B² · √N) per the lattice model (∫B² = 0.479).
        const double meanError = sigma * spacing / (0.479 * std::sqrt(double(kW) * kH));
        EXPECT_LT(std::fabs(s.mean), 5.0 * meanError) << "ISO " << iso;
        EXPECT_NEAR(s.sd / sigma, 1.0, 0.04) << "ISO " << iso;
        std::printf("ISO %.0f: mean %+.5f (bound %.5f), sd %.5f (documented %.5f)\n", iso, s.mean, 5.0 * meanError,
                    s.sd, sigma);
    }
}

TEST_F(Grain, GrainSizeFollowsTheLatticeModelAndIso) {
    const double px = 3.0;
    for (double iso : {100.0, 1600.0}) {
        auto frames = runFrames(grainGraph({{"iso", iso}, {"strength", 0.02}, {"size", sizeFor(px)}}));
        const double s = px * std::pow(iso / 100.0, 0.25); // 3 and 6 pixels
        for (int lag : {int(s), int(2 * s)}) {
            const double measured = autocorrelation(frames[0], lag), model = modelAutocorrelation(s, lag);
            EXPECT_NEAR(measured, model, 0.015) << "ISO " << iso << " lag " << lag;
            std::printf("ISO %.0f spacing %.1f px, lag %d: autocorrelation %.4f, model %.4f\n", iso, s, lag, measured, model);
        }
        EXPECT_LT(autocorrelation(frames[0], int(3 * s)), 0.05); // beyond the B-spline's reach
    }
}

TEST_F(Grain, NewEveryFrameAndTheSameForTheSameFrame) {
    const json params = {{"iso", 800.0}, {"strength", 0.03}, {"size", sizeFor(2.0)}};
    auto a = runFrames(grainGraph(params, 2));
    auto b = runFrames(grainGraph(params, 2));
    ASSERT_EQ(a.size(), 2u);
    EXPECT_EQ(a[0], b[0]);
    EXPECT_EQ(a[1], b[1]);
    double cross = 0.0;
    Stats s0 = stats(a[0]), s1 = stats(a[1]);
    for (size_t i = 0; i < a[0].size(); ++i) cross += (a[0][i] - s0.mean) * (a[1][i] - s1.mean);
    cross /= double(a[0].size()) * s0.sd * s1.sd;
    EXPECT_LT(std::fabs(cross), 0.05) << "frames 0 and 1 have correlated grain";
    json seeded = params;
    seeded["seed"] = 7;
    EXPECT_NE(runFrames(grainGraph(seeded, 1))[0], a[0]);
}

TEST_F(Grain, CameraStateIsoReplacesTheParam) {
    json doc = grainGraph({{"iso", 100.0}, {"strength", 0.02}, {"size", sizeFor(2.0)}});
    doc["nodes"]["camera"] = {{"type", "camera.physical"},
                              {"params", {{"mode", "manual"}, {"f_number", 8.0}, {"iso", 1600.0}}}};
    doc["nodes"]["grain"]["in"]["camera_state"] = "camera.state";
    auto frames = runFrames(doc);
    EXPECT_NEAR(stats(frames[0]).sd / (0.02 * 4.0), 1.0, 0.04);
    // The shader reads the camera's ISO on the GPU (camera.physical's default path, manual mode here): the grain, its
    // size included, is the one of iso 1600 given as the param.
    auto byParam = runFrames(grainGraph({{"iso", 1600.0}, {"strength", 0.02}, {"size", sizeFor(2.0)}}));
    ASSERT_EQ(byParam[0].size(), frames[0].size());
    double worst = 0.0;
    for (size_t i = 0; i < frames[0].size(); ++i) worst = std::max(worst, std::abs(frames[0][i] - byParam[0][i]));
    EXPECT_LT(worst, 1e-5);
}

} // namespace
} // namespace vitrine::test
