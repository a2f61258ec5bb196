// render.pathtrace: progressive path-traced reference of the scene camera (shaders/render/pathtrace.comp).
#include "shaders/render/pathtrace.h"
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
        {"backend",
         ParamType::Enum,
         "auto",
         {},
         {},
         {"auto", "gpu", "cpu"},
         "Where paths are traced: gpu (shaders/render/pathtrace.comp), cpu (nodes/render/pathtrace_cpu.cpp: the same "
         "estimator, materials and BRDF through Embree on every core, about 10x the paths per second of lavapipe), "
         "auto: cpu when the Vulkan device is a CPU (lavapipe), else gpu"},
        {"target_noise",
         ParamType::Float,
         0.0,
         0.0,
         1.0,
         {},
         "Converge, then cache: > 0 traces batches of `spp` samples until the median over lit pixels of the standard "
         "error of the mean luminance, relative to that mean (stats.w / stats.y), is at most this and min_spp is "
         "reached (or max_seconds ran out); the converged result is stored in the bake cache under a key of "
         "everything it depends on and loaded, not traced, by later runs. 0: `spp` samples a frame, no cache"},
        {"min_spp",
         ParamType::Int,
         64,
         1.0,
         1e9,
         {},
         "With target_noise: at least this many samples per pixel (the noise estimate of a few samples is itself noisy)"},
        {"max_seconds",
         ParamType::Float,
         0.0,
         0.0,
         1e7,
         {},
         "With target_noise: stop after this long even if the target is not reached (0: no limit); a result stopped "
         "early is not cached"},
    };
    return s;
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
        mPipeline =
            ctx.computePipeline("render/pathtrace.comp", {{"VITRINE_SCENE_TEXTURES", std::to_string(textures)}}, 3);
        mStorePipeline = ctx.computePipeline("render/pathtrace_store.comp", {}, 1);
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
        GpuBvh& bvh = mScene->bvh(ctx.gpu());
        const StorageBufferSet& geometry = gpu.geometrySet();
        const Params& p = ctx.params();
        const CameraFrame& cam = mCamera->current;
        PathtracePush push{};
        push.invViewProj = glm::inverse(cam.viewProjNoJitter);
        push.cameraPos = glm::vec4(cam.state.position, 0.0f);
        push.scales = {p.getFloat("sun_scale"), p.getFloat("sky_scale"), p.getFloat("emissive_scale"), 0.0f};
        uint32_t flags = (reset ? PATHTRACE_RESET : 0u) | (ctx.hasInput("env_cdf") ? PATHTRACE_ENV_CDF : 0u) |
                         (p.getBool("antialias") ? PATHTRACE_ANTIALIAS : 0u);
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

    // The median (and 90th percentile) over pixels with light of the standard error of the mean luminance relative
    // to that mean.
    static double relativeNoise(const std::vector<glm::vec4>& stats, double* p90 = nullptr) {
        std::vector<float> relative;
        relative.reserve(stats.size());
        for (const glm::vec4& st : stats)
            if (st.y > 0.0f) relative.push_back(st.w / st.y);
        if (relative.empty()) return 0.0;
        auto at = [&](double q) {
            auto it = relative.begin() + static_cast<std::ptrdiff_t>(q * double(relative.size() - 1));
            std::nth_element(relative.begin(), it, relative.end());
            return static_cast<double>(*it);
        };
        if (p90) *p90 = at(0.9);
        return at(0.5);
    }

    // Everything a converged result depends on: the scene's content and pose, the camera, the sky (its pixels),
    // the frame size, every param that changes the estimate, and the tracer (CPU version, or the GPU's SPIR-V
    // and device).
    BakeKey referenceKey(ExecuteContext& ctx, bool cpu, const CpuSky& sky, const ImageDesc& out) const {
        const Params& p = ctx.params();
        const CameraFrame& cam = mCamera->current;
        scene::Hasher h;
        h.string("render.pathtrace converged reference v1");
        h.value(mScene->scene().lightTransportHash());
        h.array(mScene->pose.instanceWorld);
        h.value(cam.viewProjNoJitter);
        h.value(cam.state.position);
        for (const Image& face : sky.faces) h.array(face.pixels);
        h.value(sky.sunIlluminance);
        h.value(sky.sunDirection);
        h.value(sky.envCdf.empty());
        h.value(out.width);
        h.value(out.height);
        for (const char* name : {"spp", "max_bounces", "seed", "min_spp"}) h.value(p.getInt(name));
        for (const char* name : {"sun_scale", "sky_scale", "emissive_scale", "target_noise"}) h.value(p.getFloat(name));
        h.value(p.getBool("antialias"));
        if (cpu) {
            h.string("cpu");
            h.value(kCpuTracerVersion);
        } else {
            h.string("gpu");
            const size_t textures = std::max<size_t>(1, mScene->scene().textures.size());
            const CompiledShader shader =
                ctx.shaders().compile("render/pathtrace.comp", {{"VITRINE_SCENE_TEXTURES", std::to_string(textures)}});
            h.bytes(shader.spirv.data(), shader.spirv.size() * sizeof(uint32_t));
            h.string(ctx.gpu().deviceInfo().name);
        }
        return BakeKey{"reference", h.result()};
    }

    std::vector<uint8_t> serializeAccumulation() const {
        const uint32_t header[4] = {0x52545056u /* "VPTR" */, static_cast<uint32_t>(mAccumulation.width),
                                    static_cast<uint32_t>(mAccumulation.height), 1u};
        const size_t n = mAccumulation.color.size() * sizeof(glm::vec4);
        std::vector<uint8_t> bytes(sizeof header + 2 * n);
        std::memcpy(bytes.data(), header, sizeof header);
        std::memcpy(bytes.data() + sizeof header, mAccumulation.color.data(), n);
        std::memcpy(bytes.data() + sizeof header + n, mAccumulation.stats.data(), n);
        return bytes;
    }

    bool deserializeAccumulation(const std::vector<uint8_t>& bytes, const ImageDesc& out) {
        uint32_t header[4];
        const size_t n = static_cast<size_t>(out.width) * out.height * sizeof(glm::vec4);
        if (bytes.size() != sizeof header + 2 * n) return false;
        std::memcpy(header, bytes.data(), sizeof header);
        if (header[0] != 0x52545056u || header[1] != out.width || header[2] != out.height || header[3] != 1u) return false;
        mAccumulation.reset(static_cast<int>(out.width), static_cast<int>(out.height));
        std::memcpy(mAccumulation.color.data(), bytes.data() + sizeof header, n);
        std::memcpy(mAccumulation.stats.data(), bytes.data() + sizeof header + n, n);
        return true;
    }

    void executeConverge(ExecuteContext& ctx, bool cpu) {
        const Params& p = ctx.params();
        const ImageDesc& out = ctx.output("color").desc();
        ctx.splitSubmission(); // the sky of this frame is computed before it is read back and hashed
        const CpuSky sky = readSky(ctx);
        const BakeKey key = referenceKey(ctx, cpu, sky, out);
        if (!mConvergedKey || *mConvergedKey != key.hash) {
            const BakeCache cache(defaultCacheDir());
            const auto loadStart = std::chrono::steady_clock::now();
            std::optional<std::vector<uint8_t>> bytes = cache.get(key);
            if (bytes && deserializeAccumulation(*bytes, out)) {
                double p90 = 0.0;
                const double noise = relativeNoise(mAccumulation.stats, &p90);
                char line[240];
                std::snprintf(line, sizeof line,
                              "render.pathtrace: converged reference loaded from the bake cache in %.0f ms (%.0f spp, "
                              "standard error %.2f %% of the pixel's mean (median), %.2f %% (p90))",
                              std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - loadStart).count(),
                              static_cast<double>(mAccumulation.stats.empty() ? 0.0f : mAccumulation.stats[0].x),
                              noise * 100.0, p90 * 100.0);
                logInfo(line);
            } else if (converge(ctx, cpu, sky, out)) {
                if (!cache.put(key, serializeAccumulation()))
                    logWarning("render.pathtrace: could not write the converged reference to the bake cache under " +
                               cache.dir().string());
            }
            mConvergedKey = key.hash;
        }
        storeAccumulation(ctx, out);
        (void)p;
    }

    // Traces batches of `spp` samples into mAccumulation until the target and min_spp hold (true) or max_seconds
    // ran out (false).
    bool converge(ExecuteContext& ctx, bool cpu, const CpuSky& sky, const ImageDesc& out) {
        const Params& p = ctx.params();
        const double target = p.getFloat("target_noise"), maxSeconds = p.getFloat("max_seconds");
        const double minSpp = static_cast<double>(p.getInt("min_spp"));
        const uint32_t batch = static_cast<uint32_t>(p.getInt("spp"));
        const bool report = p.getBool("report");
        const auto start = std::chrono::steady_clock::now();
        auto elapsed = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(); };

        mAccumulation.reset(static_cast<int>(out.width), static_cast<int>(out.height));
        std::unique_ptr<Progress> bar;
        if (report) {
            char label[160];
            std::snprintf(label, sizeof label, "path tracing %ux%u to %.2f %% noise on the %s", out.width, out.height,
                          target * 100.0, cpu ? "CPU" : "GPU");
            bar = std::make_unique<Progress>(label, 1000);
        }
        size_t shown = 0;
        double samples = 0.0, noise = 1.0, p90 = 0.0;
        bool announced = false, converged = false;
        for (uint32_t b = 0;; ++b) {
            const uint32_t seed = (static_cast<uint32_t>(p.getInt("seed")) * 0x85EBCA6Bu + 0x27D4EB2Fu) ^ (b * 0x9E3779B9u);
            if (cpu) {
                traceCpuBatch(ctx, sky, out, batch, seed);
            } else {
                recordGpuSamples(ctx, batch, b * 1024u, b > 0, true, seed);
                ctx.splitSubmission();
                const Image stats = readImage(ctx.gpu(), ctx.output("stats"), VK_IMAGE_LAYOUT_GENERAL);
                std::memcpy(mAccumulation.stats.data(), stats.pixels.data(), stats.pixels.size() * sizeof(float));
            }
            samples += batch;
            noise = relativeNoise(mAccumulation.stats, &p90);
            const double t = elapsed();
            // Noise falls as 1 / sqrt(samples): the samples the target needs, and the time that takes.
            const double needed = std::max(minSpp, samples * (noise / target) * (noise / target));
            if (report && !announced) {
                char line[240];
                std::snprintf(line, sizeof line,
                              "render.pathtrace: %.0f spp in %.1f s, standard error %.1f %% (median); the target %.2f %% "
                              "needs about %.0f spp: about %.0f s on this machine",
                              samples, t, noise * 100.0, target * 100.0, needed, t / samples * needed);
                std::fprintf(stderr, "\n");
                logInfo(line);
                announced = true;
            }
            if (bar) {
                const size_t now = static_cast<size_t>(std::min(0.999, samples / needed) * 1000.0);
                if (now > shown) bar->advance(now - shown);
                shown = std::max(shown, now);
            }
            if (samples >= minSpp && noise <= target) {
                converged = true;
                break;
            }
            if (maxSeconds > 0.0 && t >= maxSeconds) break;
        }
        if (bar) {
            bar->advance(1000 - shown);
            bar.reset();
        }
        if (!cpu) {
            const Image color = readImage(ctx.gpu(), ctx.output("color"), VK_IMAGE_LAYOUT_GENERAL);
            std::memcpy(mAccumulation.color.data(), color.pixels.data(), color.pixels.size() * sizeof(float));
        }
        char line[240];
        std::snprintf(line, sizeof line,
                      "render.pathtrace: %s after %.0f spp in %.1f s: standard error %.2f %% of the pixel's mean "
                      "(median), %.2f %% (p90)%s",
                      converged ? "converged" : "stopped at max_seconds", samples, elapsed(), noise * 100.0, p90 * 100.0,
                      converged ? "; stored in the bake cache" : ", above the target: not cached");
        if (converged) logInfo(line);
        else logWarning(line);
        return converged;
    }

    void traceCpuBatch(ExecuteContext& ctx, const CpuSky& sky, const ImageDesc& out, uint32_t spp, uint32_t seed) {
        const Params& p = ctx.params();
        const CameraFrame& cam = mCamera->current;
        if (!mCpu || mScene->pose.instanceWorld != mCpuPose) {
            mCpu = std::make_unique<CpuPathTracer>(mScene->scene(), mScene->pose.instanceWorld);
            mCpuPose = mScene->pose.instanceWorld;
        }
        CpuTraceSettings s;
        s.invViewProj = glm::inverse(cam.viewProjNoJitter);
        s.cameraPos = cam.state.position;
        s.width = static_cast<int>(out.width);
        s.height = static_cast<int>(out.height);
        s.spp = spp;
        s.maxBounces = static_cast<uint32_t>(p.getInt("max_bounces"));
        s.seed = seed;
        s.sunScale = p.getFloat("sun_scale");
        s.skyScale = p.getFloat("sky_scale");
        s.emissiveScale = p.getFloat("emissive_scale");
        s.antialias = p.getBool("antialias");
        s.envSampling = ctx.hasInput("env_cdf");
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

    // mAccumulation into the outputs, through a host-visible buffer and a copy shader (the outputs stay storage
    // images, written by the GPU tracer's dispatches otherwise).
    void storeAccumulation(ExecuteContext& ctx, const ImageDesc& out) {
        const size_t bytes = mAccumulation.color.size() * 2 * sizeof(glm::vec4);
        if (!mStoreBuffer || mStoreBuffer.size() < bytes) {
            mStoreSet = StorageBufferSet();
            mStoreBuffer = GpuBuffer(ctx.gpu(), bytes, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, true, "pathtrace.cpu_result");
            const VkBuffer buffers[1] = {mStoreBuffer.buffer()};
            mStoreSet = StorageBufferSet(ctx.gpu(), buffers, VK_SHADER_STAGE_COMPUTE_BIT, "pathtrace.cpu_result");
        }
        auto* dst = static_cast<glm::vec4*>(mStoreBuffer.mapped());
        for (size_t i = 0; i < mAccumulation.color.size(); ++i) {
            dst[2 * i] = mAccumulation.color[i];
            dst[2 * i + 1] = mAccumulation.stats[i];
        }
        const glm::uvec4 push(out.width, out.height, 0u, 0u);
        std::array<VkDescriptorSetLayout, 1> layouts = {mStoreSet.layout()};
        std::array<VkDescriptorSet, 1> sets = {mStoreSet.set()};
        ctx.dispatchWithSets(mStorePipeline, &push, sizeof(push), out.width, out.height, layouts, sets);
    }

    // The sky nodes' outputs, read back for the CPU tracer (they were computed earlier in this frame).
    CpuSky readSky(ExecuteContext& ctx) {
        CpuSky sky;
        const GpuImage& cube = ctx.input("sky");
        sky.size = static_cast<int>(cube.desc().width);
        for (uint32_t face = 0; face < 6; ++face)
            sky.faces.push_back(readImage(ctx.gpu(), cube, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, 0, face));
        const Image sh = readImage(ctx.gpu(), ctx.input("sky_sh"), VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
        sky.sunIlluminance = glm::vec3(sh.at(9, 0)[0], sh.at(9, 0)[1], sh.at(9, 0)[2]);
        sky.sunDirection = glm::vec3(sh.at(10, 0)[0], sh.at(10, 0)[1], sh.at(10, 0)[2]);
        if (ctx.hasInput("env_cdf"))
            sky.envCdf = readImage(ctx.gpu(), ctx.input("env_cdf"), VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
        return sky;
    }

    void executeCpu(ExecuteContext& ctx) {
        const Params& p = ctx.params();
        const CameraFrame& cam = mCamera->current;
        const bool posed = mCpu && mScene->pose.instanceWorld == mCpuPose;
        bool moved = cam.viewProjNoJitter != mLastViewProj || !posed;
        bool reset = !ctx.hasInput("history") || !ctx.inputValid("history") || moved;
        mLastViewProj = cam.viewProjNoJitter;
        const auto start = std::chrono::steady_clock::now();

        ctx.splitSubmission(); // the sky nodes' work of this frame is done before it is read back
        const CpuSky sky = readSky(ctx);
        if (!posed) {
            mCpu = std::make_unique<CpuPathTracer>(mScene->scene(), mScene->pose.instanceWorld);
            mCpuPose = mScene->pose.instanceWorld;
        }
        const ImageDesc& out = ctx.output("color").desc();
        if (reset || mAccumulation.width != static_cast<int>(out.width) ||
            mAccumulation.height != static_cast<int>(out.height))
            mAccumulation.reset(static_cast<int>(out.width), static_cast<int>(out.height));

        CpuTraceSettings s;
        s.invViewProj = glm::inverse(cam.viewProjNoJitter);
        s.cameraPos = cam.state.position;
        s.width = static_cast<int>(out.width);
        s.height = static_cast<int>(out.height);
        s.spp = static_cast<uint32_t>(p.getInt("spp"));
        s.maxBounces = static_cast<uint32_t>(p.getInt("max_bounces"));
        s.seed = (ctx.frameIndex() * 0x9E3779B9u) ^ (static_cast<uint32_t>(p.getInt("seed")) * 0x85EBCA6Bu + 0x27D4EB2Fu);
        s.sunScale = p.getFloat("sun_scale");
        s.skyScale = p.getFloat("sky_scale");
        s.emissiveScale = p.getFloat("emissive_scale");
        s.antialias = p.getBool("antialias");
        s.envSampling = ctx.hasInput("env_cdf");

        const bool report = p.getBool("report");
        std::unique_ptr<Progress> bar;
        size_t shown = 0;
        std::function<void(double)> progress;
        if (report) {
            bar = std::make_unique<Progress>("path tracing " + std::to_string(out.width) + "x" +
                                                 std::to_string(out.height) + " at " + std::to_string(s.spp) +
                                                 " spp on the CPU",
                                             100);
            progress = [&](double done) {
                size_t now = static_cast<size_t>(done * 100.0);
                if (now > shown) bar->advance(now - shown);
                shown = std::max(shown, now);
            };
        }
        const CpuTraceCounters counters = mCpu->trace(s, sky, mAccumulation, progress);
        bar.reset();
        const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        mLastPathsPerSecond = static_cast<double>(counters.paths) / std::max(counters.seconds, 1e-9);
        mLastRaysPerSecond = static_cast<double>(counters.rays) / std::max(counters.seconds, 1e-9);
        mLastPathsPerCpuSecond = static_cast<double>(counters.paths) / std::max(counters.cpuSeconds, 1e-9);
        recordCpuFigures();

        storeAccumulation(ctx, out);

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

    std::shared_ptr<SceneObject> mScene;
    std::shared_ptr<CameraObject> mCamera;
    PipelineId mPipeline = 0, mStorePipeline = 0;
    glm::mat4 mLastViewProj{0.0f};
    // The CPU tracer: its Embree scene (of the pose it was built at), its accumulation and the result buffer.
    std::unique_ptr<CpuPathTracer> mCpu;
    std::vector<glm::mat4> mCpuPose;
    CpuAccumulation mAccumulation;
    GpuBuffer mStoreBuffer;
    StorageBufferSet mStoreSet;
    double mLastPathsPerSecond = 0.0, mLastRaysPerSecond = 0.0, mLastPathsPerCpuSecond = 0.0;
    std::optional<uint64_t> mConvergedKey; // the key of the converged result in mAccumulation
};

const NodeRegistration kRegistration(schema(), [] { return std::make_unique<Pathtrace>(); });

} // namespace
} // namespace vitrine
