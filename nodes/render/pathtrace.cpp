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

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <memory>
#include <string>

#include <time.h>

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
        if (cpu) executeCpu(ctx);
        else executeGpu(ctx);
    }

private:
    void executeGpu(ExecuteContext& ctx) {
        GpuScene& gpu = mScene->gpu(ctx.gpu(), ctx.shaders());
        GpuBvh& bvh = mScene->bvh(ctx.gpu());
        const StorageBufferSet& geometry = gpu.geometrySet();

        const Params& p = ctx.params();
        const CameraFrame& cam = mCamera->current;
        bool moved =
            cam.viewProjNoJitter != mLastViewProj || mScene->pose.instanceWorld != mScene->previousPose.instanceWorld;
        bool reset = !ctx.hasInput("history") || !ctx.inputValid("history") || moved;
        mLastViewProj = cam.viewProjNoJitter;

        PathtracePush push{};
        push.invViewProj = glm::inverse(cam.viewProjNoJitter);
        push.cameraPos = glm::vec4(cam.state.position, 0.0f);
        push.scales = {p.getFloat("sun_scale"), p.getFloat("sky_scale"), p.getFloat("emissive_scale"), 0.0f};
        uint32_t flags = (reset ? PATHTRACE_RESET : 0u) | (ctx.hasInput("env_cdf") ? PATHTRACE_ENV_CDF : 0u) |
                         (p.getBool("antialias") ? PATHTRACE_ANTIALIAS : 0u);
        const uint32_t seed = static_cast<uint32_t>(p.getInt("seed")) * 0x85EBCA6Bu + 0x27D4EB2Fu;
        const uint32_t spp = static_cast<uint32_t>(p.getInt("spp"));
        const ImageDesc& out = ctx.output("color").desc();
        const auto start = std::chrono::steady_clock::now();
        const double cpuStart = processCpuSeconds();
        const bool report = p.getBool("report");
        const uint32_t chunks = (spp + PATHTRACE_SAMPLES_PER_DISPATCH - 1) / PATHTRACE_SAMPLES_PER_DISPATCH;
        const uint32_t every = std::max(1u, chunks / 10);
        std::unique_ptr<Progress> bar;
        if (report && chunks >= 4)
            bar = std::make_unique<Progress>("path tracing " + std::to_string(out.width) + "x" +
                                                 std::to_string(out.height) + " at " + std::to_string(spp) + " spp",
                                             chunks);
        std::array<VkDescriptorSetLayout, 3> layouts = {bvh.setLayout(), gpu.setLayout(), geometry.layout()};
        std::array<VkDescriptorSet, 3> sets = {bvh.set(), gpu.set(), geometry.set()};
        for (uint32_t done = 0, chunk = 0; done < spp; ++chunk) {
            const uint32_t count = std::min(PATHTRACE_SAMPLES_PER_DISPATCH, spp - done);
            push.counts = {count, static_cast<uint32_t>(p.getInt("max_bounces")),
                           (ctx.frameIndex() * 0x9E3779B9u + chunk * 0x632BE5ABu) ^ seed,
                           flags | (done > 0 ? PATHTRACE_CONTINUE : 0u)};
            if (done > 0) ctx.computeBarrier();
            ctx.dispatchWithSets(mPipeline, &push, sizeof(push), out.width, out.height, layouts, sets);
            done += count;
            if (bar && (chunk + 1) % every == 0 && done < spp) {
                ctx.splitSubmission(); // so the bar moves with the GPU's work
                bar->advance(every);
            }
        }
        if (report) reportFrame(ctx, start, cpuStart, static_cast<double>(out.width) * out.height * spp);
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

        // Into the outputs through a host-visible buffer and a copy shader (the outputs stay storage images).
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
        char rate[160];
        std::snprintf(rate, sizeof rate, "; %.0f paths/s (%.0f paths per CPU-second of this process)",
                      paths / std::max(seconds, 1e-9), paths / std::max(cpuSeconds, 1e-9));
        logInfo(summaryLine(samples, seconds, relative) + rate);
    }

    static double processCpuSeconds() {
        timespec t{};
        clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
        return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
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
};

const NodeRegistration kRegistration(schema(), [] { return std::make_unique<Pathtrace>(); });

} // namespace
} // namespace vitrine
