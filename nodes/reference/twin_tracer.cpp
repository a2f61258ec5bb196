// The ray-traced twins' shared run (see twin.hpp).
#include "nodes/reference/twin_tracer.hpp"
#include "core/base/log.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>

namespace vitrine {

void appendTwinParams(std::vector<ParamSpec>& params, int sppDefault) {
    params.push_back({"spp",
                      ParamType::Int,
                      sppDefault,
                      1.0,
                      4096.0,
                      {},
                      "Samples per pixel per frame (a new estimate every frame), or per batch with target_noise"});
    params.push_back({"seed",
                      ParamType::Int,
                      0,
                      0.0,
                      2147483647.0,
                      {},
                      "Random sequence (independent estimates for noise measurements)"});
    params.push_back({"report",
                      ParamType::Bool,
                      true,
                      {},
                      {},
                      {},
                      "A line per frame with the samples, time and estimated noise (with target_noise: a progress bar)"});
    appendConvergeParams(params);
}

CpuPathTracer& TwinTracer::tracer(const SceneObject& scene) {
    if (!mCpu || mCpu->outdated(scene.pose)) mCpu = std::make_unique<CpuPathTracer>(scene.scene(), scene.pose);
    return *mCpu;
}

CpuTraceSettings TwinTracer::settings(const CameraFrame& cam, int width, int height) {
    CpuTraceSettings s;
    s.invViewProj = glm::inverse(cam.viewProjNoJitter);
    s.cameraPos = cam.state.position;
    s.orthographic = cam.state.lens.projection == scene::Projection::Orthographic;
    s.width = width;
    s.height = height;
    s.antialias = false; // primary surfaces through pixel centres
    return s;
}

const CpuAccumulation& TwinTracer::run(ExecuteContext& ctx, const std::string& node, const SceneObject& scene,
                                       CpuTraceSettings s, const CpuSky& sky, scene::Hasher key,
                                       const CpuSampleFn& sample) {
    const Params& p = ctx.params();
    const uint32_t spp = static_cast<uint32_t>(p.getInt("spp"));
    const uint32_t seed = static_cast<uint32_t>(p.getInt("seed"));
    const bool report = p.getBool("report");
    CpuPathTracer& cpu = tracer(scene);
    if (p.getFloat("target_noise") > 0.0f) {
        for (const char* name : {"spp", "seed", "min_spp"}) key.value(p.getInt(name));
        key.value(p.getFloat("target_noise"));
        const BakeKey bakeKey{"reference", key.result()};
        if (!mConvergedKey || *mConvergedKey != bakeKey.hash) {
            {
                ConvergeRun run;
                run.node = node;
                run.what = "estimating " + node;
                run.width = s.width;
                run.height = s.height;
                run.target = p.getFloat("target_noise");
                run.maxSeconds = p.getFloat("max_seconds");
                run.minSpp = static_cast<double>(p.getInt("min_spp"));
                run.batch = spp;
                run.seed = seed;
                run.report = report;
                run.stop = [&ctx] { return ctx.stopRequested(); };
                convergeCached(bakeKey, run, mAccumulation, [&](uint32_t n, uint32_t batchSeed, uint32_t) {
                    CpuTraceSettings b = s;
                    b.spp = n;
                    b.seed = batchSeed;
                    cpu.estimate(b, sky, mAccumulation, sample);
                });
            }
            mConvergedKey = bakeKey.hash;
        }
        return mAccumulation;
    }
    mConvergedKey.reset();
    const auto start = std::chrono::steady_clock::now();
    s.spp = spp;
    s.seed = (ctx.frameIndex() * 0x9E3779B9u) ^ (seed * 0x85EBCA6Bu + 0x27D4EB2Fu);
    mAccumulation.reset(s.width, s.height);
    const CpuTraceCounters c = cpu.estimate(s, sky, mAccumulation, sample);
    recordNodeFigure(node + " cpu rays/s", static_cast<double>(c.rays) / std::max(c.seconds, 1e-9));
    if (report) {
        double p90 = 0.0;
        const double noise = mAccumulation.relativeNoise(&p90);
        char line[240];
        std::snprintf(line, sizeof line,
                      "%s: %u spp on the CPU in %.2f s (%.2f Mrays/s); standard error %.1f %% of the pixel's mean "
                      "(median), %.1f %% (p90)",
                      node.c_str(), spp,
                      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(),
                      static_cast<double>(c.rays) / std::max(c.seconds, 1e-9) * 1e-6, noise * 100.0, p90 * 100.0);
        logInfo(line);
    }
    return mAccumulation;
}

} // namespace vitrine
