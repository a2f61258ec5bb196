// The ray-traced twins' shared node (see twin.hpp): render.pathtrace's CPU path with another estimator.
#include "nodes/reference/twin.hpp"
#include "core/base/log.hpp"
#include "core/gpu/context.hpp"
#include "core/shading/brdf.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>

namespace vitrine {

NodeSchema twinSchema(const TwinSchema& t) {
    NodeSchema s;
    s.type = t.type;
    s.doc = t.doc +
            " Traced on the CPU (Embree, every core) whatever the Vulkan device, with render.pathtrace's materials, "
            "BRDF (core/shading) and estimator of the light arriving along a ray; primary surfaces are the camera "
            "rays through pixel centres (unjittered; with antialias through random points of the pixel). With "
            "target_noise > 0 it converges, then caches, as render.pathtrace does.";
    auto tex = [](const char* name, const char* doc, bool optional = false) {
        InputPort in{name, PortKind::Texture, {}, optional, Usage::Sampled, doc};
        in.readBack = true; // the CPU tracer reads the sky back once a frame
        return in;
    };
    s.inputs = {
        {"scene", PortKind::Scene, {}, false, Usage::Sampled, "The scene to trace"},
        {"camera", PortKind::Camera, {}, false, Usage::Sampled, "The frame's camera (its unjittered view)"},
        tex("sky", "A sky node's cube map (radiance of the environment, without the sun disk: sun_in_cubemap false)"),
        tex("sky_sh", "A sky node's `sh`: sun illuminance (texel 9, lux) and direction (texel 10)"),
        tex("env_cdf", "sky.env_cdf of the same cube map (without it the sky is found by BRDF sampling only)", true),
    };
    OutputPort color;
    color.name = "color";
    color.format = VK_FORMAT_R32G32B32A32_SFLOAT;
    color.size = SizeRule::frame();
    color.usage = Usage::StorageReadWrite;
    color.doc = t.colorDoc;
    OutputPort stats = color;
    stats.name = "stats";
    stats.doc = "x: samples per pixel; y: mean luminance of the samples; z: sum of squared deviations of the samples' "
                "luminance; w: standard error of the mean luminance (as render.pathtrace's stats)";
    s.outputs = {color, stats};
    s.params = {
        {"spp", ParamType::Int, 16, 1.0, 4096.0, {}, "Samples per pixel per frame (per batch with target_noise)"},
        {"max_bounces",
         ParamType::Int,
         8,
         1.0,
         64.0,
         {},
         "Surfaces that reflect light along each traced ray's path (render.pathtrace's max_bounces, counted from the "
         "surface the ray finds)"},
        {"sun_scale", ParamType::Float, 1.0, 0.0, 100.0, {}, "Multiplier of the sky model's sun illuminance"},
        {"sky_scale", ParamType::Float, 1.0, 0.0, 100.0, {}, "Multiplier of the sky cube map's radiance"},
        {"emissive_scale", ParamType::Float, 1.0, 0.0, 1e6, {}, "Multiplier of emissive surfaces"},
        {"report", ParamType::Bool, true, {}, {}, {}, "A progress bar and a summary line"},
        {"seed", ParamType::Int, 0, 0.0, 2147483647.0, {}, "Random sequence (independent estimates)"},
        {"antialias",
         ParamType::Bool,
         false,
         {},
         {},
         {},
         "Each sample's camera ray through a random point of the pixel (a box filter, as render.pathtrace's "
         "antialias): textures and edges averaged over the pixel, as the path-traced reference's pixel sees them; "
         "off: every ray through the pixel's centre"},
        {"multiscatter",
         ParamType::Bool,
         false,
         {},
         {},
         {},
         "The GGX lobe with its multiple-scattering compensation at every surface the paths meet (the twin of a "
         "lighting.deferred or forward.transparent with multiscatter on; as render.pathtrace's multiscatter)"},
    };
    appendConvergeParams(s.params);
    return s;
}

void TwinNode::setup(SetupContext& ctx) {
    mScene = ctx.objectAs<SceneObject>("scene");
    mCamera = ctx.objectAs<CameraObject>("camera");
    mStorePipeline = ctx.computePipeline("render/pathtrace_store.comp", {}, 1);
}

CpuTraceSettings TwinNode::settings(ExecuteContext& ctx, uint32_t spp, uint32_t seed) const {
    const Params& p = ctx.params();
    const CameraFrame& cam = mCamera->current;
    const ImageDesc& out = ctx.output("color").desc();
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
    s.antialias = false;
    s.envSampling = ctx.hasInput("env_cdf");
    s.multiscatter = mMultiscatter;
    return s;
}

void TwinNode::traceBatch(ExecuteContext& ctx, const CpuSky& sky, uint32_t spp, uint32_t seed,
                          const std::function<void(double)>& progress) {
    if (!mCpu || mCpu->outdated(mScene->pose)) mCpu = std::make_unique<CpuPathTracer>(mScene->scene(), mScene->pose);
    const CpuTraceSettings s = settings(ctx, spp, seed);
    const CpuTraceCounters c = mCpu->estimate(
        s, sky, mAccumulation, [this](const CpuRays& rays, int x, int y, uint32_t& rng) { return sample(rays, x, y, rng); },
        progress);
    recordNodeFigure(mTwin.type + " samples/s", static_cast<double>(c.paths) / std::max(c.seconds, 1e-9));
}

void TwinNode::execute(ExecuteContext& ctx) {
    mAntialias = ctx.params().getBool("antialias");
    mMultiscatter = ctx.params().getBool("multiscatter");
    readParams(ctx.params());
    if (ctx.params().getFloat("target_noise") > 0.0f) {
        executeConverge(ctx);
        return;
    }
    // One estimate of `spp` samples a frame (nothing accumulates across frames).
    const Params& p = ctx.params();
    const auto start = std::chrono::steady_clock::now();
    ctx.splitSubmission(); // the sky nodes' work of this frame is done before it is read back
    const CpuSky sky = readCpuSky(ctx);
    const ImageDesc& out = ctx.output("color").desc();
    mAccumulation.reset(static_cast<int>(out.width), static_cast<int>(out.height));
    const uint32_t spp = static_cast<uint32_t>(p.getInt("spp"));
    const uint32_t seed =
        (ctx.frameIndex() * 0x9E3779B9u) ^ (static_cast<uint32_t>(p.getInt("seed")) * 0x85EBCA6Bu + 0x27D4EB2Fu);
    const bool report = p.getBool("report");
    std::unique_ptr<Progress> bar;
    std::function<void(double)> progress;
    if (report) {
        bar = std::make_unique<Progress>(mTwin.what + " " + std::to_string(out.width) + "x" +
                                             std::to_string(out.height) + " at " + std::to_string(spp) +
                                             " spp on the CPU",
                                         100);
        progress = [&](double done) { bar->advanceTo(done); };
    }
    traceBatch(ctx, sky, spp, seed, progress);
    bar.reset();
    mUpload.upload(ctx, mStorePipeline, mAccumulation);
    mConvergedKey.reset();
    if (report) {
        double p90 = 0.0;
        const double noise = mAccumulation.relativeNoise(&p90);
        char line[240];
        std::snprintf(line, sizeof line, "%s: %u spp, %.1f s; standard error %.1f %% of the pixel's mean (median), "
                                         "%.1f %% (p90)",
                      mTwin.type.c_str(), spp,
                      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), noise * 100.0,
                      p90 * 100.0);
        logInfo(line);
    }
}

void TwinNode::executeConverge(ExecuteContext& ctx) {
    const Params& p = ctx.params();
    const ImageDesc& out = ctx.output("color").desc();
    const int w = static_cast<int>(out.width), h = static_cast<int>(out.height);
    ctx.splitSubmission(); // the sky of this frame is computed before it is read back and hashed
    const CpuSky sky = readCpuSky(ctx);
    scene::Hasher hasher;
    hasher.string(mTwin.type + " converged v" + std::to_string(mTwin.version));
    hashTraceInputs(hasher, *mScene, mCamera->current, sky, w, h);
    for (const char* name : {"spp", "max_bounces", "seed", "min_spp"}) hasher.value(p.getInt(name));
    for (const char* name : {"sun_scale", "sky_scale", "emissive_scale", "target_noise"})
        hasher.value(p.getFloat(name));
    hasher.value(ctx.hasInput("env_cdf"));
    if (p.getBool("antialias")) hasher.string("antialias"); // off: the keys of before the param
    if (p.getBool("multiscatter")) hasher.string("multiscatter");
    hashParams(hasher, p);
    const BakeKey key{"reference", hasher.result()};
    if (!mConvergedKey || *mConvergedKey != key.hash) {
        {
            ConvergeRun run;
            run.node = mTwin.type;
            run.what = mTwin.what;
            run.width = w;
            run.height = h;
            run.target = p.getFloat("target_noise");
            run.maxSeconds = p.getFloat("max_seconds");
            run.minSpp = static_cast<double>(p.getInt("min_spp"));
            run.batch = static_cast<uint32_t>(p.getInt("spp"));
            run.seed = static_cast<uint32_t>(p.getInt("seed"));
            run.report = p.getBool("report");
            run.stop = [&ctx] { return ctx.stopRequested(); };
            convergeCached(key, run, mAccumulation,
                           [&](uint32_t spp, uint32_t seed, uint32_t) { traceBatch(ctx, sky, spp, seed); });
        }
        mConvergedKey = key.hash;
    }
    mUpload.upload(ctx, mStorePipeline, mAccumulation);
}

// --- sampling (nodes/render/pathtrace_cpu.cpp's, line for line) ---

} // namespace vitrine
