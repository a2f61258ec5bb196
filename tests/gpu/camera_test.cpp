// camera.physical on the GPU (the default path: metering, adaptation and program all on the GPU, the result read
// back from its buffer after the frame): the metered EV against CPU statistics of the same pixels (flat images, a
// weighted gradient, a trimmed three-level image), doubling the luminance moving the EV by 1, the program reacting to
// the light with the f-numbers and shutters of the documented curve (worked out by hand in
// tests/unit/camera/program_test.cpp) and matching the CPU's program, eye adaptation's exponential without waits in
// the frame, post.tonemap taking its exposure from the camera state, and the default path's image against the
// `readback: same_frame` debug path's (CPU metering and program).
#include "tests/gpu/gpu_test.hpp"

#include "core/base/error.hpp"
#include "core/base/paths.hpp"
#include "core/graph/compiler.hpp"
#include "core/graph/executor.hpp"
#include "core/graph/loader.hpp"
#include "core/graph/registry.hpp"
#include "core/image/io.hpp"
#include "core/shader/compiler.hpp"
#include "nodes/camera/camera_state.hpp"
#include "nodes/camera/lens.hpp"
#include "nodes/camera/program.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <numeric>
#include <unistd.h>

namespace vitrine::test {
namespace {

using nlohmann::json;
namespace fs = std::filesystem;

class Camera : public GpuTest {};

fs::path scratch() {
    fs::path dir = fs::path(VITRINE_TEST_OUT) / ("camera-" + std::to_string(::getpid()));
    fs::create_directories(dir);
    return dir;
}

// Writes an image whose pixel (x, y) is grey of luminance lum(x, y) (cd/m²) as a float EXR.
fs::path writeGrey(const std::string& name, int w, int h, const std::function<double(int, int)>& lum) {
    Image img(w, h);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            float* p = img.at(x, y);
            p[0] = p[1] = p[2] = static_cast<float>(lum(x, y));
            p[3] = 1.0f;
        }
    fs::path path = scratch() / (name + ".exr");
    writeExr(path, img, ExrPixelType::Float);
    return path;
}

// previous: the camera meters last frame's image, through a copy (a linear tone map at 0 EV) that is written every
// frame (image.load writes its texture once, so its own @prev history would hold its first frame only).
json cameraGraph(const fs::path& image, const json& cameraParams, int frames = 1, bool previous = false) {
    return {{"format", "vitrine-graph/1"},
            {"frame", {{"width", 64}, {"height", 64}, {"frames", frames}}},
            {"nodes",
             {{"load", {{"type", "image.load"}, {"params", {{"path", image.string()}}}}},
              {"copy", {{"type", "post.tonemap"}, {"params", {{"operator", "linear"}}}, {"in", {{"color", "load.color"}}}}},
              {"camera",
               {{"type", "camera.physical"},
                {"params", cameraParams},
                {"in", {{"color", previous ? "copy.color@prev" : "load.color"}}}}},
              {"tonemap",
               {{"type", "post.tonemap"},
                {"params", {{"operator", "linear"}}},
                {"in", {{"color", "load.color"}, {"camera_state", "camera.state"}}}}}}},
            {"outputs", {{"final", "tonemap.color"}}}};
}

struct CameraRun {
    std::vector<CameraState> states; // per frame (the GPU buffer's fields read back after each frame)
    std::vector<gpu_types::CameraExposure> exposures; // per frame, the buffer itself
    std::vector<CameraState> cpuStates; // per frame, the CPU half as the producer left it
    Image final;                     // the last frame's output
    uint32_t inFrameWaits = 0;       // fence waits while recording, all frames together
    uint32_t inFrameWaitsAfterFirst = 0;
};

CameraRun run(const json& doc) {
    CompiledGraph graph = compileGraph(validateGraph(doc, "camera-test.json", NodeRegistry::global()));
    std::shared_ptr<CameraStateObject> state;
    for (const auto& r : graph.resources)
        if (r.name == "camera.state") state = std::dynamic_pointer_cast<CameraStateObject>(r.object);
    EXPECT_TRUE(state) << "no camera.state object";
    ShaderCompiler shaders;
    Executor executor(gpu(), graph, shaders);
    CameraRun out;
    RunOptions options;
    options.progress = false;
    options.write.resize(graph.desc.frame.frames);
    std::iota(options.write.begin(), options.write.end(), 0u);
    options.onOutput = [&](uint32_t frame, const std::string& name, const Image& image) {
        if (name != "final") return;
        EXPECT_EQ(state->frame, frame);
        out.states.push_back(state->resolved());
        out.exposures.push_back(state->gpuExposure());
        out.cpuStates.push_back(state->state);
        out.final = image;
    };
    executor.run(options);
    for (size_t f = 0; f < executor.timings().size(); ++f) {
        out.inFrameWaits += executor.timings()[f].inFrameWaits;
        if (f > 0) out.inFrameWaitsAfterFirst += executor.timings()[f].inFrameWaits;
    }
    return out;
}

const json kAverage = {{"centre_weight", 0.0}, {"meter_low", 0.0}, {"meter_high", 1.0}};

// A flat image of luminance L meters at log2(L · 100 / 12.5); twice as bright, one EV more (within 0.05, the
// issue's bound; measured to ~1e-5). Both are read back in the same frame (converged at frame 0).
TEST_F(Camera, FlatImageMetersItsLuminanceAndDoublingAddsOneEv) {
    const double L = 300.0;
    CameraRun a = run(cameraGraph(writeGrey("flat300", 64, 64, [&](int, int) { return L; }), json::object()));
    CameraRun b = run(cameraGraph(writeGrey("flat600", 64, 64, [&](int, int) { return 2.0 * L; }), json::object()));
    ASSERT_EQ(a.states.size(), 1u);
    ASSERT_EQ(b.states.size(), 1u);
    EXPECT_NEAR(a.states[0].meteredEv100, std::log2(L * 8.0), 1e-3);
    EXPECT_NEAR(b.states[0].meteredEv100 - a.states[0].meteredEv100, 1.0, 0.05);
    EXPECT_NEAR(b.states[0].meteredEv100 - a.states[0].meteredEv100, 1.0, 1e-3);
    std::printf("flat %g cd/m²: EV %.5f; %g cd/m²: EV %.5f\n", L, a.states[0].meteredEv100, 2 * L,
                b.states[0].meteredEv100);
}

// Luminance is Rec.709 Y: a flat (L, L/2, L/4) image meters at log2(8 · 0.58825 L).
TEST_F(Camera, ColouredImageMetersItsRec709Luminance) {
    const double L = 500.0;
    Image img(32, 32);
    for (int y = 0; y < 32; ++y)
        for (int x = 0; x < 32; ++x) {
            float* p = img.at(x, y);
            p[0] = float(L), p[1] = float(L / 2), p[2] = float(L / 4), p[3] = 1.0f;
        }
    const fs::path path = scratch() / "orange.exr";
    writeExr(path, img, ExrPixelType::Float);
    CameraRun r = run(cameraGraph(path, json::object()));
    EXPECT_NEAR(r.states[0].meteredEv100, std::log2(8.0 * L * (0.2126 + 0.7152 / 2 + 0.0722 / 4)), 1e-3);
}

// Centre weighting on a horizontal gradient of log luminance, every pixel counted (no trimming): the GPU's
// histogram mean equals the CPU's weighted mean of log2 Y with w = (1 − c) + c exp(−r²/2σ²). 320x224 is 280
// tiles, more than one reduction workgroup's 256 invocations.
TEST_F(Camera, CentreWeightedMeanOfLogLuminanceMatchesCpu) {
    const int W = 320, H = 224;
    // Brighter toward the left and right edges (log2 Y rises with the squared distance from a point left of
    // centre), so centre weighting lowers the reading and average metering does not.
    auto lum = [&](int x, int y) { double u = (x - 0.4 * W) / W; return std::exp2(2.0 + 20.0 * u * u + 0.02 * y); };
    const fs::path image = writeGrey("gradient", W, H, lum);
    for (double c : {0.0, 0.75, 1.0}) {
        const double sigma = 0.4;
        double sw = 0.0, sl = 0.0;
        for (int y = 0; y < H; ++y)
            for (int x = 0; x < W; ++x) {
                double dx = (x + 0.5 - 0.5 * W) / (0.5 * H), dy = (y + 0.5 - 0.5 * H) / (0.5 * H);
                double w = (1.0 - c) + c * std::exp(-(dx * dx + dy * dy) / (2.0 * sigma * sigma));
                float y709 = static_cast<float>(lum(x, y)); // as stored in the float EXR
                sw += w;
                sl += w * std::log2(double(y709));
            }
        json params = {{"centre_weight", c}, {"centre_sigma", sigma}, {"meter_low", 0.0}, {"meter_high", 1.0}};
        CameraRun r = run(cameraGraph(image, params));
        const double expected = std::log2(std::exp2(sl / sw) * 8.0);
        EXPECT_NEAR(r.states[0].meteredEv100, expected, 2e-3) << "centre_weight " << c;
        std::printf("centre_weight %.2f: GPU EV %.5f, CPU %.5f\n", c, r.states[0].meteredEv100, expected);
    }
}

// Percentile trimming: thirds of the image at 2^2, 2^8 and 2^14 cd/m² (one bin each), average metering; with
// meter_low 0.1 and meter_high 0.95 the mean log2 is (7·2 + 10·8 + 8.5·14) / 25.5 (the thirds weighing 10 each).
TEST_F(Camera, PercentilesIgnoreTheDarkestAndBrightest) {
    const fs::path image = writeGrey("thirds", 96, 64, [](int x, int) { return std::exp2(x < 32 ? 2.0 : x < 64 ? 8.0 : 14.0); });
    CameraRun r = run(cameraGraph(image, {{"centre_weight", 0.0}, {"meter_low", 0.1}, {"meter_high", 0.95}}));
    const double meanLog = (7.0 * 2.0 + 10.0 * 8.0 + 8.5 * 14.0) / 25.5;
    EXPECT_NEAR(r.states[0].meteredEv100, meanLog + 3.0, 2e-3);
}

// The camera reacting to the light (the demo's point): brighter scenes stop the lens down along the program line.
// 50 mm f/1.8 STM, ISO 100: scenes metering EV 10 and EV 14 (L = 2^EV / 8) give f/2.73 at 1/138 s and f/5.45
// at 1/551 s, as the documented curve says; a +2 program shift at EV 14 gives f/10.9 at 1/138 s. The tone-mapped
// output (linear operator) is L times the exposure, 1 / 9.6 for a flat image exposed as metered.
TEST_F(Camera, ProgramStopsDownAsTheSceneBrightens) {
    struct Case {
        double ev, shift, fNumber, shutter;
    };
    for (const Case& c : {Case{10.0, 0.0, 2.72693, 0.007261844}, Case{14.0, 0.0, 5.45385, 0.001815461},
                          Case{14.0, 2.0, 10.90771, 0.007261844}}) {
        const double L = std::exp2(c.ev) / 8.0;
        json params = kAverage;
        params["program_shift"] = c.shift;
        CameraRun r = run(cameraGraph(writeGrey("ev" + std::to_string(int(c.ev)), 64, 64, [&](int, int) { return L; }), params));
        const CameraState& s = r.states[0];
        EXPECT_NEAR(s.fNumber / c.fNumber, 1.0, 2e-3) << "EV " << c.ev << " shift " << c.shift;
        EXPECT_NEAR(s.shutterSeconds / c.shutter, 1.0, 2e-3) << "EV " << c.ev << " shift " << c.shift;
        EXPECT_NEAR(s.ev100, c.ev, 2e-3);
        EXPECT_NEAR(s.exposure, 1.0 / (1.2 * std::exp2(s.ev100)), 1e-9);
        EXPECT_NEAR(r.final.at(10, 10)[1], 1.0 / 9.6, 1e-4);
        EXPECT_EQ(s.bladeCount, 7);
        EXPECT_FLOAT_EQ(s.wideOpenFNumber, 1.8f);
        std::printf("EV %.1f shift %+.0f: f/%.3f, 1/%.1f s, ISO %.0f\n", c.ev, c.shift, s.fNumber, 1.0 / s.shutterSeconds,
                    s.iso);
    }
}

// post.tonemap with camera_state connected multiplies by the state's exposure, not by its own `exposure` param:
// the output equals the same graph without the camera and with exposure = log2(state.exposure).
TEST_F(Camera, TonemapTakesTheCameraExposure) {
    const fs::path image = writeGrey("ramp", 64, 64, [](int x, int y) { return 50.0 + 40.0 * x + 3.0 * y; });
    json withCamera = cameraGraph(image, {{"mode", "manual"}, {"f_number", 4.0}, {"shutter", 1.0 / 60.0}, {"iso", 400.0}});
    withCamera["nodes"]["tonemap"]["params"] = {{"operator", "aces_fit"}, {"exposure", 5.0}};
    CameraRun r = run(withCamera);
    const double ev = std::log2(16.0 * 60.0) - 2.0;
    EXPECT_NEAR(r.states[0].ev100, ev, 1e-5);
    json plain = withCamera;
    plain["nodes"].erase("camera");
    plain["nodes"].erase("copy");
    plain["nodes"]["tonemap"]["in"].erase("camera_state");
    plain["nodes"]["tonemap"]["params"]["exposure"] = std::log2(1.0 / (1.2 * std::exp2(ev)));
    auto out = runGraph(plain);
    EXPECT_LT(maxAbsDiff(r.final, out.at("final")), 1e-6);
    plain["nodes"]["tonemap"]["params"]["exposure"] = 5.0;
    EXPECT_GT(maxAbsDiff(r.final, runGraph(plain).at("final")), 0.1); // the param alone is something else
}

// Eye adaptation on the CPU (the `readback` debug paths): with the result read back a frame late, frame 0 has no
// metering and uses initial_ev100; from frame 1 on the EV approaches the metered M as M + (I − M) exp(−k dt / τ).
// Metering last frame's image (`copy.color@prev`) in the same frame gives the same curve (frame 0's input is not
// valid yet).
TEST_F(Camera, EyeAdaptationIsExponentialInTime) {
    const double L = 1000.0, M = std::log2(8.0 * L), I = 6.0, tau = 0.25, fps = 24.0;
    const fs::path image = writeGrey("flat1000", 64, 64, [&](int, int) { return L; });
    json params = {{"initial_ev100", I}, {"adaptation_time", tau}, {"fps", fps}, {"readback", "next_frame"}};
    CameraRun late = run(cameraGraph(image, params, 6));
    params["readback"] = "same_frame";
    CameraRun prev = run(cameraGraph(image, params, 6, true));
    for (CameraRun* r : {&late, &prev}) {
        ASSERT_EQ(r->states.size(), 6u);
        EXPECT_NEAR(r->states[0].meteredEv100, I, 1e-6);
        for (int k = 1; k < 6; ++k)
            EXPECT_NEAR(r->states[k].meteredEv100, M + (I - M) * std::exp(-k / fps / tau), 2e-3) << "frame " << k;
    }
    params["adaptation_time"] = 0.0;
    CameraRun instant = run(cameraGraph(image, params, 2, true));
    EXPECT_NEAR(instant.states[1].meteredEv100, M, 1e-3);
}

// The default path (readback: none) keeps eye adaptation on the GPU across frames: metering last frame's image, the
// EV follows the same exponential as the CPU debug paths, and no frame waits for the GPU while it is recorded; the
// same_frame path does wait (once a frame that meters), so the counter can fail.
TEST_F(Camera, GpuEyeAdaptationIsExponentialWithoutWaits) {
    const double L = 1000.0, M = std::log2(8.0 * L), I = 6.0, tau = 0.25, fps = 24.0;
    const fs::path image = writeGrey("flat1000gpu", 64, 64, [&](int, int) { return L; });
    json params = {{"initial_ev100", I}, {"adaptation_time", tau}, {"fps", fps}};
    CameraRun gpuRun = run(cameraGraph(image, params, 6, true));
    ASSERT_EQ(gpuRun.states.size(), 6u);
    EXPECT_NEAR(gpuRun.states[0].meteredEv100, I, 1e-6);
    for (int k = 1; k < 6; ++k)
        EXPECT_NEAR(gpuRun.states[k].meteredEv100, M + (I - M) * std::exp(-k / fps / tau), 2e-3) << "frame " << k;
    EXPECT_EQ(gpuRun.inFrameWaits, 0u);
    // A second run of the same executor starts over at frame 0 (the state in the buffer is reset, not continued).
    {
        CompiledGraph graph =
            compileGraph(validateGraph(cameraGraph(image, params, 3, true), "camera-test.json", NodeRegistry::global()));
        std::shared_ptr<CameraStateObject> state;
        for (const auto& r : graph.resources)
            if (r.name == "camera.state") state = std::dynamic_pointer_cast<CameraStateObject>(r.object);
        ASSERT_TRUE(state);
        ShaderCompiler shaders;
        Executor executor(gpu(), graph, shaders);
        std::vector<float> first;
        RunOptions options;
        options.progress = false;
        options.write = {0u, 1u, 2u};
        options.onOutput = [&](uint32_t, const std::string&, const Image&) { first.push_back(state->resolved().meteredEv100); };
        executor.run(options);
        executor.run(options);
        ASSERT_EQ(first.size(), 6u);
        for (int k = 0; k < 3; ++k) EXPECT_NEAR(first[3 + k], first[k], 1e-6) << "second run, frame " << k;
    }
    params["readback"] = "same_frame";
    CameraRun cpuRun = run(cameraGraph(image, params, 6, true));
    EXPECT_EQ(cpuRun.inFrameWaits, 5u); // frames 1..5 meter (frame 0's @prev input is not valid)
    for (int k = 0; k < 6; ++k) EXPECT_NEAR(gpuRun.states[k].meteredEv100, cpuRun.states[k].meteredEv100, 1e-4);
}

// The program line and what follows from the f-number (aperture roundness and area, mechanical vignetting) on the GPU
// against the same shaders/camera/exposure.h functions compiled for the CPU (and core/scene/aperture.cpp's area):
// scenes from EV -2 to EV 22 (the whole line: wide open with slow shutters, the diagonal, the smallest aperture, the
// shutter limit) with auto ISO, a program shift, exposure compensation and a zoom with mechanical vignetting.
TEST_F(Camera, GpuProgramMatchesTheCpuProgram) {
    const camera::LensData zoom = camera::loadLens(camera::findLens("canon_ef_24-70mm_f2.8l_ii", ".", dataDir()));
    EXPECT_GT(camera::evaluateLens(zoom, 25.0f, 5.0f, 2.8f).mechanicalVignetting, 0.01f); // something to fade
    // (EV, program shift): shift +8 at EV -4 runs into the longest shutter (30 s) before the smallest aperture.
    const std::vector<std::pair<double, double>> cases = {{-4.0, 8.0}, {-2.0, 1.0}, {4.0, 1.0}, {9.0, 1.0},
                                                          {13.0, 1.0}, {17.5, 1.0}, {22.0, 1.0}};
    for (const auto& [ev, shift] : cases) {
        const double L = std::exp2(ev) / 8.0;
        json params = kAverage;
        params["lens"] = "canon_ef_24-70mm_f2.8l_ii";
        params["focal_length"] = 25.0;
        params["auto_iso"] = true;
        params["program_shift"] = shift;
        params["exposure_compensation"] = -0.9;
        const fs::path image =
            writeGrey("program" + std::to_string(int(ev * 10)) + "_" + std::to_string(int(shift)), 32, 32,
                      [&](int, int) { return L; });
        CameraRun r = run(cameraGraph(image, params));
        const CameraState& s = r.states[0];
        EXPECT_NEAR(s.meteredEv100, ev, 1e-3);
        camera::ProgramLimits limits;
        limits.wideOpenFNumber = s.wideOpenFNumber;
        limits.minFNumber = s.minFNumber;
        limits.focalLengthMm = 25.0f;
        limits.autoIso = true;
        const camera::ExposureSettings e =
            camera::programExposure(s.meteredEv100 + 0.9f, static_cast<float>(shift), limits);
        EXPECT_LE(s.shutterSeconds, 30.0f * 1.0001f) << "EV " << ev;
        EXPECT_NEAR(s.fNumber / e.fNumber, 1.0, 1e-4) << "EV " << ev;
        EXPECT_NEAR(s.shutterSeconds / e.shutterSeconds, 1.0, 1e-4) << "EV " << ev;
        EXPECT_NEAR(s.iso / e.iso, 1.0, 1e-4) << "EV " << ev;
        EXPECT_NEAR(s.ev100, e.ev100, 1e-4) << "EV " << ev;
        EXPECT_NEAR(s.exposure / camera::exposureScale(e.ev100), 1.0, 1e-4) << "EV " << ev;
        const gpu_types::CameraExposure cpu = exposureOf(s), gpuSide = r.exposures[0];
        EXPECT_NEAR(gpuSide.stopsDown, cpu.stopsDown, 1e-4) << "EV " << ev;
        EXPECT_NEAR(gpuSide.apertureRoundness, cpu.apertureRoundness, 1e-4) << "EV " << ev;
        EXPECT_NEAR(gpuSide.apertureArea, cpu.apertureArea, 1e-4) << "EV " << ev;
        // The CPU's evaluateLens at the GPU's f-number.
        const camera::LensState lens = camera::evaluateLens(zoom, 25.0f, 5.0f, s.fNumber);
        EXPECT_NEAR(gpuSide.mechanicalVignetting, lens.mechanicalVignetting, 1e-5) << "EV " << ev;
        std::printf("EV %5.1f: f/%.3f 1/%.1f s ISO %.0f, roundness %.4f area %.5f mech %.4f\n", ev, s.fNumber,
                    1.0 / s.shutterSeconds, s.iso, gpuSide.apertureRoundness, gpuSide.apertureArea,
                    gpuSide.mechanicalVignetting);
    }
}

// The default path's image equals the same_frame path's (CPU metering, adaptation and program, uploaded) through
// every post node that reads the camera in its shaders and takes only an image and the camera: tone map, lens,
// flare, streaks, Airy diffraction and grain, on a bright, uneven still image over a few frames of adaptation (last
// frame's image metered, from an initial EV 12).
TEST_F(Camera, DefaultPathImageEqualsSameFrame) {
    const fs::path image = writeGrey("spots", 96, 64, [](int x, int y) {
        double dx = x - 30.0, dy = y - 20.0;
        return 40.0 + 5.0 * x + 2e5 * std::exp(-(dx * dx + dy * dy) / 6.0);
    });
    json doc = cameraGraph(image, {{"lens", "canon_ef_24-70mm_f2.8l_ii"}, {"focal_length", 24.0},
                                   {"initial_ev100", 12.0}, {"adaptation_time", 0.2}}, 4, true);
    json& nodes = doc["nodes"];
    nodes["lens"] = {{"type", "post.lens"}, {"in", {{"color", "load.color"}, {"camera_state", "camera.state"}}}};
    nodes["airy"] = {{"type", "post.airy"}, {"in", {{"color", "lens.color"}, {"camera_state", "camera.state"}}}};
    nodes["flare"] = {{"type", "post.flare"}, {"params", {{"threshold", 0.5}}},
                      {"in", {{"color", "airy.color"}, {"camera_state", "camera.state"}}}};
    nodes["streaks"] = {{"type", "post.streaks"}, {"params", {{"threshold", 0.5}}},
                        {"in", {{"color", "flare.color"}, {"camera_state", "camera.state"}}}};
    nodes["tonemap"]["in"]["color"] = "streaks.color";
    nodes["tonemap"]["params"]["operator"] = "aces_fit";
    nodes["grain"] = {{"type", "post.grain"}, {"params", {{"strength", 0.05}}},
                      {"in", {{"color", "tonemap.color"}, {"camera_state", "camera.state"}}}};
    doc["outputs"] = {{"final", "grain.color"}};
    CameraRun gpuRun = run(doc);
    nodes["camera"]["params"]["readback"] = "same_frame";
    CameraRun cpuRun = run(doc);
    ASSERT_EQ(gpuRun.states.size(), 4u);
    for (int k = 0; k < 4; ++k) {
        std::printf("frame %d: metered EV %.4f (same_frame %.4f), EV %.4f, f/%.3f, 1/%.1f s\n", k, gpuRun.states[k].meteredEv100,
                    cpuRun.states[k].meteredEv100, gpuRun.states[k].ev100, gpuRun.states[k].fNumber, 1.0 / gpuRun.states[k].shutterSeconds);
        EXPECT_NEAR(gpuRun.states[k].meteredEv100, cpuRun.states[k].meteredEv100, 1e-4) << "frame " << k;
        EXPECT_NEAR(gpuRun.states[k].ev100, cpuRun.states[k].ev100, 1e-4) << "frame " << k;
        EXPECT_NEAR(gpuRun.states[k].fNumber / cpuRun.states[k].fNumber, 1.0, 1e-4) << "frame " << k;
    }
    EXPECT_GT(std::abs(gpuRun.states[3].meteredEv100 - gpuRun.states[0].meteredEv100), 0.1); // it did adapt
    EXPECT_GT(gpuRun.states[3].fNumber, gpuRun.states[3].wideOpenFNumber * 1.2f); // stopped down: streaks, no round pupil
    const double diff = maxAbsDiff(gpuRun.final, cpuRun.final);
    std::printf("default vs same_frame: max |diff| %.3g, RMSE %.3g\n", diff, rmse(gpuRun.final, cpuRun.final));
    EXPECT_LT(diff, 1e-3);
    EXPECT_EQ(gpuRun.inFrameWaits, 0u);
}

TEST(CameraParams, BadLensAndSettingsNameTheParam) {
    const fs::path image = writeGrey("params", 8, 8, [](int, int) { return 1.0; });
    auto refuse = [&](const json& params, const std::string& pointer, const std::string& words) {
        try {
            compileGraph(validateGraph(cameraGraph(image, params), "camera-test.json", NodeRegistry::global()));
            ADD_FAILURE() << "accepted " << params.dump();
        } catch (const UserError& e) {
            EXPECT_NE(std::string(e.what()).find(pointer), std::string::npos) << e.what();
            EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
        }
    };
    refuse({{"lens", "leica_noctilux"}}, "/nodes/camera/params/lens", "canon_ef_50mm_f1.8_stm");
    refuse({{"lens", "canon_ef-s_18-55mm_f3.5-5.6_is_stm"}, {"focal_length", 70.0}}, "/nodes/camera/params/focal_length",
           "18-55");
    refuse({{"mode", "manual"}, {"f_number", 1.2}}, "/nodes/camera/params/f_number", "f/1.8-22");
}

} // namespace
} // namespace vitrine::test
