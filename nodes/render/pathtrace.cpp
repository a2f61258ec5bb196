// render.pathtrace: progressive path-traced reference of the scene camera (shaders/render/pathtrace.comp).
#include "shaders/render/pathtrace.h"
#include "core/accel/gpu_bvh.hpp"
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
    }

    void execute(ExecuteContext& ctx) override {
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
        if (report) reportFrame(ctx, start);
    }

private:
    // Waits for the frame, then prints the samples per pixel since the restart, the frame's time and the median
    // (and 90th percentile) of the per-pixel standard error relative to the pixel's mean luminance.
    void reportFrame(ExecuteContext& ctx, std::chrono::steady_clock::time_point start) {
        ctx.splitSubmission();
        const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
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
        logInfo(line + noise);
    }

public:

private:
    std::shared_ptr<SceneObject> mScene;
    std::shared_ptr<CameraObject> mCamera;
    PipelineId mPipeline = 0;
    glm::mat4 mLastViewProj{0.0f};
};

const NodeRegistration kRegistration(schema(), [] { return std::make_unique<Pathtrace>(); });

} // namespace
} // namespace vitrine
