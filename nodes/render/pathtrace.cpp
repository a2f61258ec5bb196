// render.pathtrace: progressive path-traced reference of the scene camera (shaders/render/pathtrace.comp).
#include "shaders/render/pathtrace.h"
#include "nodes/render/converge.hpp"
#include "nodes/render/pathtrace_cpu.hpp"
#include "core/accel/gpu_bvh.hpp"
#include "core/gpu/buffer_set.hpp"
#include "core/base/log.hpp"
#include "core/gpu/context.hpp"
#include "core/gpu/transfer.hpp"
#include "core/graph/registry.hpp"
#include "core/scene/gpu_scene.hpp"
#include "core/scene/hash.hpp"
#include "core/bake/cache.hpp"
#include "core/shader/compiler.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <memory>
#include <optional>
#include <string>

namespace vitrine {
namespace {

using gpu_types::PathtracePush;

NodeSchema schema() {
    NodeSchema s;
    s.type = "render.pathtrace";
    s.doc = "Path-traced ground truth of the scene camera: the same layered materials and BRDF as gbuffer.layered + "
            "lighting.deferred, the sun as a directional light (next-event estimation), the sky cube map as an "
            "environment light (importance sampled through sky.env_cdf, MIS with BRDF sampling), emissive surfaces, "
            "Russian roulette. Accumulates across frames through its own @prev outputs and restarts when the camera or "
            "the scene moves; `spp` samples per pixel per frame make one frame a reference. HDR radiance in cd/m², "
            "like lighting.color.";
    auto tex = [](const char* name, const char* doc, bool optional = false) {
        return InputPort{name, PortKind::Texture, {}, optional, Usage::Sampled, doc};
    };
    s.inputs = {
        {"scene",
         PortKind::Scene,
         {},
         false,
         Usage::Sampled,
         "The scene to trace (its BVH is built or loaded on first use)"},
        {"camera",
         PortKind::Camera,
         {},
         false,
         Usage::Sampled,
         "The frame's camera (unjittered; the tracer jitters itself)"},
        tex("sky", "A sky node's cube map (radiance of the environment, without the sun disk: sun_in_cubemap false)"),
        tex("sky_sh", "A sky node's `sh`: sun illuminance (texel 9, lux) and direction (texel 10)"),
        tex("env_cdf", "sky.env_cdf of the same cube map (without it the sky is found by BRDF sampling only)", true),
        tex("history", "This node's color@prev (without it nothing accumulates across frames)", true),
        tex("history_stats", "This node's stats@prev", true),
    };
    // The CPU tracer reads the sky back once a frame.
    for (InputPort& in : s.inputs)
        if (in.name == "sky" || in.name == "sky_sh" || in.name == "env_cdf") in.readBack = true;
    OutputPort color;
    color.name = "color";
    color.format = VK_FORMAT_R32G32B32A32_SFLOAT;
    color.size = SizeRule::frame();
    color.usage = Usage::StorageReadWrite; // refined by each of the frame's dispatches
    color.doc = "Mean radiance (cd/m², rgb) of all samples since the last restart; a = 1";
    OutputPort stats = color;
    stats.name = "stats";
    stats.readBack = true; // the progress line's noise estimate
    stats.doc = "x: samples per pixel since the restart; y: mean luminance; z: sum of squared deviations of the "
                "samples' luminance; w: standard error of the mean luminance (cd/m²)";
    s.outputs = {color, stats};
    s.params = {
        {"spp",
         ParamType::Int,
         16,
         1.0,
         1024.0,
         {},
         "Samples per pixel per frame (for more, accumulate frames with a still camera)"},
        {"max_bounces",
         ParamType::Int,
         8,
         1.0,
         64.0,
         {},
         "Surfaces that reflect light along a path (1: direct light only; Russian roulette ends most paths sooner)"},
        {"sun_scale",
         ParamType::Float,
         1.0,
         0.0,
         100.0,
         {},
         "Multiplier of the sky model's sun illuminance (as lighting.deferred)"},
        {"sky_scale",
         ParamType::Float,
         1.0,
         0.0,
         100.0,
         {},
         "Multiplier of the sky cube map's radiance (0: sun and emitters only)"},
        {"emissive_scale",
         ParamType::Float,
         1.0,
         0.0,
         1e6,
         {},
         "Multiplier of emissive surfaces (as lighting.deferred)"},
        {"antialias",
         ParamType::Bool,
         true,
         {},
         {},
         {},
         "Jitter camera rays over the pixel (off: through pixel centres)"},
        {"report",
         ParamType::Bool,
         true,
         {},
         {},
         {},
         "A progress bar while a frame traces, then its samples per pixel, time and estimated noise (reads `stats` "
         "back once a frame)"},
        {"seed",
         ParamType::Int,
         0,
         0.0,
         2147483647.0,
         {},
         "Random sequence (independent estimates for noise measurements)"},
        {"transparent",
         ParamType::Bool,
         true,
         {},
         {},
         {},
         "Trace what forward.transparent draws: alpha-blended surfaces by their coverage, alpha masks cut away, and "
         "KHR_materials_transmission as thin-walled glass (straight on, tinted by the base colour) for paths and "
         "shadow rays alike, and KHR_materials_volume's glass (thicknessFactor > 0) as a closed volume that paths "
         "refract into and out of, rough by GGX microfacets, absorbing by Beer's law on the way inside, volumes "
         "nesting (a liquid in a glass, a bubble in a block: each boundary bends by the IORs on its two sides); "
         "shadow rays stop at it (faces of such glass that close nothing, e.g. a single quad, are thin-walled glass "
         "tinted over the thickness, as forward.transparent draws them) (off: those surfaces are left out of the "
         "scene, as for the bake and the twins, and masks are opaque)"},
        {"multiscatter",
         ParamType::Bool,
         false,
         {},
         {},
         {},
         "The GGX lobe with its multiple-scattering compensation, 1 + F0 (1 - E) / E (common/brdf.glsl "
         "ggxMultiscatter): rough metals reflect the energy single scattering loses, as lighting.deferred's and "
         "forward.transparent's multiscatter (the truth of a graph that shades with it)"},
        {"backend",
         ParamType::Enum,
         "auto",
         {},
         {},
         {"auto", "gpu", "cpu"},
         "Where paths are traced: gpu (shaders/render/pathtrace.comp), cpu (nodes/render/pathtrace_cpu.cpp: the same "
         "estimator, materials and BRDF through Embree on every core, about 10x the paths per second of lavapipe), "
         "auto: cpu when the Vulkan device is a CPU (lavapipe), else gpu"},
    };
    appendConvergeParams(s.params);
    return s;
}

// Whether any primitive lets light pass where the rasteriser draws it: an alpha mask, blending or transmission.
bool seesThroughAnything(const scene::Scene& scene) {
    for (const scene::Primitive& p : scene.primitives) {
        const scene::Material& m = scene.materials[p.material];
        if (m.transparent() || m.alphaMode == scene::AlphaMode::Mask) return true;
    }
    return false;
}

// pathtrace.comp's defines: the scene's texture count, and the multiple-scattering lobe with `multiscatter`.
ShaderDefines tracerDefines(size_t textures, const Params& p) {
    ShaderDefines d = {{"VITRINE_SCENE_TEXTURES", std::to_string(textures)}};
    if (p.getBool("multiscatter")) d.push_back({"VITRINE_MULTISCATTER", "1"});
    return d;
}

class Pathtrace final : public Node {
public:
    void setup(SetupContext& ctx) override {
        mScene = ctx.objectAs<SceneObject>("scene");
        mCamera = ctx.objectAs<CameraObject>("camera");
        if (ctx.hasInput("history") != ctx.hasInput("history_stats"))
            ctx.failParam("spp",
                          "connect both history (this node's color@prev) and history_stats (stats@prev), or neither");
        size_t textures = std::max<size_t>(1, mScene->scene().textures.size());
        mPipeline = ctx.computePipeline("render/pathtrace.comp", tracerDefines(textures, ctx.params()), 3);
        mStorePipeline = ctx.computePipeline("render/pathtrace_store.comp", {}, 1);
        mSceneSeesThrough = seesThroughAnything(mScene->scene());
    }

    void execute(ExecuteContext& ctx) override {
        const std::string backend = ctx.params().getString("backend");
        const bool cpu = backend == "cpu" ||
                         (backend == "auto" && ctx.gpu().deviceInfo().type == VK_PHYSICAL_DEVICE_TYPE_CPU);
        if (ctx.params().getFloat("target_noise") > 0.0f) executeConverge(ctx, cpu);
        else if (cpu) executeCpu(ctx);
        else executeGpu(ctx);
    }

private:
    void executeGpu(ExecuteContext& ctx) {
        const Params& p = ctx.params();
        const CameraFrame& cam = mCamera->current;
        bool moved =
            cam.viewProjNoJitter != mLastViewProj || mScene->pose.instanceWorld != mScene->previousPose.instanceWorld;
        bool reset = !ctx.hasInput("history") || !ctx.inputValid("history") || moved;
        mLastViewProj = cam.viewProjNoJitter;
        const uint32_t seed = static_cast<uint32_t>(p.getInt("seed")) * 0x85EBCA6Bu + 0x27D4EB2Fu;
        const uint32_t spp = static_cast<uint32_t>(p.getInt("spp"));
        const ImageDesc& out = ctx.output("color").desc();
        const auto start = std::chrono::steady_clock::now();
        const double cpuStart = processCpuSeconds();
        const bool report = p.getBool("report");
        recordGpuSamples(ctx, spp, 0, false, reset, seed, report);
        if (report) reportFrame(ctx, start, cpuStart, static_cast<double>(out.width) * out.height * spp);
    }

    // Records spp samples per pixel of the GPU tracer, in dispatches of PATHTRACE_SAMPLES_PER_DISPATCH. continueFrame:
    // add to what this frame's earlier dispatches wrote; else start from the history (or from nothing with reset).
    void recordGpuSamples(ExecuteContext& ctx, uint32_t spp, uint32_t firstChunk, bool continueFrame, bool reset,
                          uint32_t seed, bool progress = false) {
        GpuScene& gpu = mScene->gpu(ctx.gpu(), ctx.shaders());
        const bool through = seeThrough(ctx.params());
        GpuBvh& bvh = mScene->bvh(ctx.gpu(), through);
        const StorageBufferSet& geometry = gpu.geometrySet();
        const Params& p = ctx.params();
        const CameraFrame& cam = mCamera->current;
        PathtracePush push{};
        push.invViewProj = glm::inverse(cam.viewProjNoJitter);
        push.cameraPos = glm::vec4(cam.state.position, 0.0f);
        push.scales = {p.getFloat("sun_scale"), p.getFloat("sky_scale"), p.getFloat("emissive_scale"), 0.0f};
        uint32_t flags = (reset ? PATHTRACE_RESET : 0u) | (ctx.hasInput("env_cdf") ? PATHTRACE_ENV_CDF : 0u) |
                         (p.getBool("antialias") ? PATHTRACE_ANTIALIAS : 0u) | (through ? PATHTRACE_SEE_THROUGH : 0u) |
                         (cam.state.lens.projection == scene::Projection::Orthographic ? PATHTRACE_ORTHOGRAPHIC : 0u);
        const ImageDesc& out = ctx.output("color").desc();
        const uint32_t chunks = (spp + PATHTRACE_SAMPLES_PER_DISPATCH - 1) / PATHTRACE_SAMPLES_PER_DISPATCH;
        const uint32_t every = std::max(1u, chunks / 10);
        std::unique_ptr<Progress> bar;
        if (progress && chunks >= 4)
            bar = std::make_unique<Progress>("path tracing " + std::to_string(out.width) + "x" +
                                                 std::to_string(out.height) + " at " + std::to_string(spp) + " spp",
                                             chunks);
        std::array<VkDescriptorSetLayout, 3> layouts = {bvh.setLayout(), gpu.setLayout(), geometry.layout()};
        std::array<VkDescriptorSet, 3> sets = {bvh.set(), gpu.set(), geometry.set()};
        for (uint32_t done = 0, chunk = firstChunk; done < spp; ++chunk) {
            const uint32_t count = std::min(PATHTRACE_SAMPLES_PER_DISPATCH, spp - done);
            const bool more = continueFrame || done > 0;
            push.counts = {count, static_cast<uint32_t>(p.getInt("max_bounces")),
                           (ctx.frameIndex() * 0x9E3779B9u + chunk * 0x632BE5ABu) ^ seed,
                           flags | (more ? PATHTRACE_CONTINUE : 0u)};
            if (more) ctx.computeBarrier();
            ctx.dispatchWithSets(mPipeline, &push, sizeof(push), out.width, out.height, layouts, sets);
            done += count;
            if (bar && (chunk - firstChunk + 1) % every == 0 && done < spp) {
                ctx.splitSubmission(); // so the bar moves with the GPU's work
                bar->advance(every);
            }
        }
    }

    // --- target_noise: converge, then cache ---

    // Bump when the CPU tracer's estimator changes (the GPU tracer's SPIR-V is hashed instead).
    static constexpr uint32_t kCpuTracerVersion = 1;

    // Everything a converged result depends on: the scene's content and pose, the camera, the sky (its pixels),
    // the frame size, every param that changes the estimate, and the tracer (CPU version, or the GPU's SPIR-V
    // and device).
    BakeKey referenceKey(ExecuteContext& ctx, bool cpu, const CpuSky& sky, const ImageDesc& out) const {
        const Params& p = ctx.params();
        const CameraFrame& cam = mCamera->current;
        scene::Hasher h;
        h.string("render.pathtrace converged reference v1");
        hashTraceInputs(h, *mScene, cam, sky, static_cast<int>(out.width), static_cast<int>(out.height));
        for (const char* name : {"spp", "max_bounces", "seed", "min_spp"}) h.value(p.getInt(name));
        for (const char* name : {"sun_scale", "sky_scale", "emissive_scale", "target_noise"}) h.value(p.getFloat(name));
        h.value(p.getBool("antialias"));
        if (seeThrough(p)) h.string("see through v1"); // keys of scenes traced as before are unchanged
        if (p.getBool("multiscatter")) h.string("multiscatter"); // the same
        if (cpu) {
            h.string("cpu");
            h.value(kCpuTracerVersion);
        } else {
            h.string("gpu");
            const size_t textures = std::max<size_t>(1, mScene->scene().textures.size());
            const CompiledShader shader = ctx.shaders().compile("render/pathtrace.comp", tracerDefines(textures, p));
            h.bytes(shader.spirv.data(), shader.spirv.size() * sizeof(uint32_t));
            h.string(ctx.gpu().deviceInfo().name);
        }
        return BakeKey{"reference", h.result()};
    }

    void executeConverge(ExecuteContext& ctx, bool cpu) {
        const ImageDesc& out = ctx.output("color").desc();
        ctx.splitSubmission(); // the sky of this frame is computed before it is read back and hashed
        const CpuSky sky = readCpuSky(ctx);
        const BakeKey key = referenceKey(ctx, cpu, sky, out);
        if (!mConvergedKey || *mConvergedKey != key.hash) {
            converge(ctx, cpu, sky, out, key);
            mConvergedKey = key.hash;
        }
        mUpload.upload(ctx, mStorePipeline, mAccumulation);
    }

    // The converged result under `key` from the cache, or traced in batches of `spp` samples into mAccumulation (from
    // a stopped run's partial result if the cache has one) until the target and min_spp hold (true) or max_seconds
    // ran out or the run was asked to stop (false).
    bool converge(ExecuteContext& ctx, bool cpu, const CpuSky& sky, const ImageDesc& out, const BakeKey& key) {
        const Params& p = ctx.params();
        ConvergeRun run;
        run.node = "render.pathtrace";
        run.what = "path tracing";
        run.where = cpu ? "CPU" : "GPU";
        run.width = static_cast<int>(out.width);
        run.height = static_cast<int>(out.height);
        run.target = p.getFloat("target_noise");
        run.maxSeconds = p.getFloat("max_seconds");
        run.minSpp = static_cast<double>(p.getInt("min_spp"));
        run.batch = static_cast<uint32_t>(p.getInt("spp"));
        run.seed = static_cast<uint32_t>(p.getInt("seed"));
        run.report = p.getBool("report");
        run.stop = [&ctx] { return ctx.stopRequested(); };
        ConvergeHooks hooks;
        if (!cpu) {
            // The GPU tracer accumulates in its outputs: a resumed partial result goes there first (its first batch
            // b > 0 continues what they hold, after a barrier), and the colour comes back from there at the end.
            hooks.resumed = [&](const CpuAccumulation& acc) { mUpload.upload(ctx, mStorePipeline, acc); };
            hooks.finished = [&](CpuAccumulation& acc) {
                const Image color = readImage(ctx.gpu(), ctx.output("color"), VK_IMAGE_LAYOUT_GENERAL);
                std::memcpy(acc.color.data(), color.pixels.data(), color.pixels.size() * sizeof(float));
            };
        }
        return convergeCached(
            key, run, mAccumulation,
            [&](uint32_t spp, uint32_t seed, uint32_t b) {
                if (cpu) {
                    traceCpuBatch(ctx, sky, out, spp, seed);
                } else {
                    recordGpuSamples(ctx, spp, b * 1024u, b > 0, true, seed);
                    ctx.splitSubmission();
                    const Image stats = readImage(ctx.gpu(), ctx.output("stats"), VK_IMAGE_LAYOUT_GENERAL);
                    std::memcpy(mAccumulation.stats.data(), stats.pixels.data(), stats.pixels.size() * sizeof(float));
                }
            },
            hooks);
    }

    void traceCpuBatch(ExecuteContext& ctx, const CpuSky& sky, const ImageDesc& out, uint32_t spp, uint32_t seed) {
        const Params& p = ctx.params();
        const CameraFrame& cam = mCamera->current;
        if (!mCpu || mCpu->outdated(mScene->pose) || mCpuSeesThrough != seeThrough(p)) {
            mCpuSeesThrough = seeThrough(p);
            mCpu = std::make_unique<CpuPathTracer>(mScene->scene(), mScene->pose, mCpuSeesThrough);
        }
        CpuTraceSettings s;
        s.invViewProj = glm::inverse(cam.viewProjNoJitter);
        s.cameraPos = cam.state.position;
        s.orthographic = cam.state.lens.projection == scene::Projection::Orthographic;
        s.width = static_cast<int>(out.width);
        s.height = static_cast<int>(out.height);
        s.spp = spp;
        s.maxBounces = static_cast<uint32_t>(p.getInt("max_bounces"));
        s.seed = seed;
        s.sunScale = p.getFloat("sun_scale");
        s.skyScale = p.getFloat("sky_scale");
        s.emissiveScale = p.getFloat("emissive_scale");
        s.antialias = p.getBool("antialias");
        s.multiscatter = p.getBool("multiscatter");
        s.envSampling = ctx.hasInput("env_cdf");
        s.seeThrough = mCpuSeesThrough;
        const CpuTraceCounters c = mCpu->trace(s, sky, mAccumulation);
        mLastPathsPerSecond = static_cast<double>(c.paths) / std::max(c.seconds, 1e-9);
        mLastRaysPerSecond = static_cast<double>(c.rays) / std::max(c.seconds, 1e-9);
        mLastPathsPerCpuSecond = static_cast<double>(c.paths) / std::max(c.cpuSeconds, 1e-9);
        recordCpuFigures();
    }

    void recordCpuFigures() const {
        recordNodeFigure("render.pathtrace cpu paths/s", mLastPathsPerSecond);
        recordNodeFigure("render.pathtrace cpu rays/s", mLastRaysPerSecond);
        recordNodeFigure("render.pathtrace cpu paths per CPU-second", mLastPathsPerCpuSecond);
    }

    void executeCpu(ExecuteContext& ctx) {
        const Params& p = ctx.params();
        const CameraFrame& cam = mCamera->current;
        const bool posed = mCpu && !mCpu->outdated(mScene->pose) && mCpuSeesThrough == seeThrough(p);
        bool moved = cam.viewProjNoJitter != mLastViewProj || !posed;
        bool reset = !ctx.hasInput("history") || !ctx.inputValid("history") || moved;
        mLastViewProj = cam.viewProjNoJitter;
        const auto start = std::chrono::steady_clock::now();

        ctx.splitSubmission(); // the sky nodes' work of this frame is done before it is read back
        const CpuSky sky = readCpuSky(ctx);
        if (!posed) {
            mCpuSeesThrough = seeThrough(p);
            mCpu = std::make_unique<CpuPathTracer>(mScene->scene(), mScene->pose, mCpuSeesThrough);
        }
        const ImageDesc& out = ctx.output("color").desc();
        if (reset || mAccumulation.width != static_cast<int>(out.width) ||
            mAccumulation.height != static_cast<int>(out.height))
            mAccumulation.reset(static_cast<int>(out.width), static_cast<int>(out.height));

        CpuTraceSettings s;
        s.invViewProj = glm::inverse(cam.viewProjNoJitter);
        s.cameraPos = cam.state.position;
        s.orthographic = cam.state.lens.projection == scene::Projection::Orthographic;
        s.width = static_cast<int>(out.width);
        s.height = static_cast<int>(out.height);
        s.spp = static_cast<uint32_t>(p.getInt("spp"));
        s.maxBounces = static_cast<uint32_t>(p.getInt("max_bounces"));
        s.seed = (ctx.frameIndex() * 0x9E3779B9u) ^ (static_cast<uint32_t>(p.getInt("seed")) * 0x85EBCA6Bu + 0x27D4EB2Fu);
        s.sunScale = p.getFloat("sun_scale");
        s.skyScale = p.getFloat("sky_scale");
        s.emissiveScale = p.getFloat("emissive_scale");
        s.antialias = p.getBool("antialias");
        s.multiscatter = p.getBool("multiscatter");
        s.envSampling = ctx.hasInput("env_cdf");
        s.seeThrough = mCpuSeesThrough;

        const bool report = p.getBool("report");
        std::unique_ptr<Progress> bar;
        std::function<void(double)> progress;
        if (report) {
            bar = std::make_unique<Progress>("path tracing " + std::to_string(out.width) + "x" +
                                                 std::to_string(out.height) + " at " + std::to_string(s.spp) +
                                                 " spp on the CPU",
                                             100);
            progress = [&](double done) { bar->advanceTo(done); };
        }
        const CpuTraceCounters counters = mCpu->trace(s, sky, mAccumulation, progress);
        bar.reset();
        const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        mLastPathsPerSecond = static_cast<double>(counters.paths) / std::max(counters.seconds, 1e-9);
        mLastRaysPerSecond = static_cast<double>(counters.rays) / std::max(counters.seconds, 1e-9);
        mLastPathsPerCpuSecond = static_cast<double>(counters.paths) / std::max(counters.cpuSeconds, 1e-9);
        recordCpuFigures();

        mUpload.upload(ctx, mStorePipeline, mAccumulation);

        if (report) {
            std::vector<float> relative;
            float samples = 0.0f;
            for (const glm::vec4& st : mAccumulation.stats) {
                samples = std::max(samples, st.x);
                if (st.y > 0.0f) relative.push_back(st.w / st.y);
            }
            char rate[200];
            std::snprintf(rate, sizeof rate, "; CPU tracer: %.0f paths/s, %.2f Mrays/s (%.0f paths per CPU-second)",
                          mLastPathsPerSecond, mLastRaysPerSecond * 1e-6, mLastPathsPerCpuSecond);
            logInfo(summaryLine(samples, seconds, relative) + rate);
        }
    }

    static std::string summaryLine(float samples, double seconds, std::vector<float>& relative) {
        std::string noise = "no lit pixel";
        if (!relative.empty()) {
            auto at = [&](double q) {
                auto it = relative.begin() + static_cast<std::ptrdiff_t>(q * double(relative.size() - 1));
                std::nth_element(relative.begin(), it, relative.end());
                return *it * 100.0f;
            };
            char text[96];
            std::snprintf(text, sizeof text, "standard error %.1f %% of the pixel's mean (median), %.1f %% (p90)",
                          at(0.5), at(0.9));
            noise = text;
        }
        char line[160];
        std::snprintf(line, sizeof line, "render.pathtrace: %.0f spp accumulated, frame %.1f s; ", samples, seconds);
        return line + noise;
    }

    // Waits for the frame, then prints the samples per pixel since the restart, the frame's time and the median
    // (and 90th percentile) of the per-pixel standard error relative to the pixel's mean luminance.
    void reportFrame(ExecuteContext& ctx, std::chrono::steady_clock::time_point start, double cpuStart, double paths) {
        ctx.splitSubmission();
        const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        const double cpuSeconds = processCpuSeconds() - cpuStart;
        const Image stats = readImage(ctx.gpu(), ctx.output("stats"), VK_IMAGE_LAYOUT_GENERAL);
        std::vector<float> relative;
        relative.reserve(static_cast<size_t>(stats.width) * stats.height);
        float samples = 0.0f;
        for (int y = 0; y < stats.height; ++y)
            for (int x = 0; x < stats.width; ++x) {
                const float* s = stats.at(x, y);
                samples = std::max(samples, s[0]);
                if (s[1] > 0.0f) relative.push_back(s[3] / s[1]);
            }
        recordNodeFigure("render.pathtrace gpu paths/s", paths / std::max(seconds, 1e-9));
        recordNodeFigure("render.pathtrace gpu paths per CPU-second", paths / std::max(cpuSeconds, 1e-9));
        char rate[160];
        std::snprintf(rate, sizeof rate, "; %.0f paths/s (%.0f paths per CPU-second of this process)",
                      paths / std::max(seconds, 1e-9), paths / std::max(cpuSeconds, 1e-9));
        logInfo(summaryLine(samples, seconds, relative) + rate);
    }

    // `transparent`, where the scene has anything to see through (else the opaque scene, traced as without it).
    bool seeThrough(const Params& p) const { return mSceneSeesThrough && p.getBool("transparent"); }

    std::shared_ptr<SceneObject> mScene;
    std::shared_ptr<CameraObject> mCamera;
    bool mSceneSeesThrough = false;
    bool mCpuSeesThrough = false; // what mCpu was built for
    PipelineId mPipeline = 0, mStorePipeline = 0;
    glm::mat4 mLastViewProj{0.0f};
    // The CPU tracer: its Embree scene (of the pose it was built at), its accumulation and the result buffer.
    std::unique_ptr<CpuPathTracer> mCpu;
    CpuAccumulation mAccumulation;
    CpuResultUpload mUpload;
    double mLastPathsPerSecond = 0.0, mLastRaysPerSecond = 0.0, mLastPathsPerCpuSecond = 0.0;
    std::optional<uint64_t> mConvergedKey; // the key of the converged result in mAccumulation
};

const NodeRegistration kRegistration(schema(), [] { return std::make_unique<Pathtrace>(); });

} // namespace
} // namespace vitrine
