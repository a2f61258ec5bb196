#pragma once
// "Converge, then cache" for per-pixel Monte Carlo estimates: render.pathtrace's target_noise, shared with the
// ray-traced twins (nodes/reference/). An estimate accumulates batches of samples (CpuAccumulation: mean colour
// and the stats of the samples' luminance) until the median relative standard error over lit pixels is at most
// target_noise and min_spp samples are in (or max_seconds ran out); a converged result is stored in the bake cache
// under a key of everything it depends on and loaded, not traced, by later runs.
#include "core/bake/cache.hpp"
#include "core/graph/node.hpp"
#include "core/gpu/buffer_set.hpp"
#include "core/gpu/resources.hpp"
#include "core/scene/gpu_scene.hpp"
#include "core/scene/hash.hpp"
#include "nodes/render/pathtrace_cpu.hpp"

#include <functional>
#include <string>
#include <vector>

namespace vitrine {

// Appends target_noise, min_spp and max_seconds (render.pathtrace's docs and ranges) to a node's params.
void appendConvergeParams(std::vector<ParamSpec>& params);

struct ConvergeRun {
    std::string node;              // the node type, for log lines ("render.pathtrace")
    std::string what = "tracing";  // the progress bar's verb phrase
    std::string where = "CPU";     // "CPU" or "GPU", for the bar
    int width = 0, height = 0;
    double target = 0.0, maxSeconds = 0.0, minSpp = 1.0;
    uint32_t batch = 16;  // samples per pixel per batch
    uint32_t seed = 0;    // the node's `seed` param
    bool report = true;   // progress bar and the time estimate
};

// The seed of batch b of a run whose `seed` param is `seed` (independent sequences per seed and batch).
uint32_t convergeBatchSeed(uint32_t seed, uint32_t b);

// Resets acc and calls traceBatch(spp, seed, b) for b = 0, 1, ... until the target and min_spp hold (true) or
// max_seconds ran out (false). traceBatch adds its samples to acc; acc.stats must be current when it returns.
bool convergeAccumulation(const ConvergeRun& run, CpuAccumulation& acc,
                          const std::function<void(uint32_t spp, uint32_t seed, uint32_t batch)>& traceBatch);

// The converged result under `key`, if the bake cache has one of this size (logs the load time and its noise).
bool loadConverged(const BakeKey& key, const std::string& node, int width, int height, CpuAccumulation& acc);
// Stores a converged result (a warning if the cache cannot be written).
void storeConverged(const BakeKey& key, const std::string& node, const CpuAccumulation& acc);

// What every traced estimate of the camera's view depends on, into a cache key: the scene's light-transport content
// and pose, the camera (unjittered view-projection and position), the sky's pixels and sun, the frame size. The
// caller adds its node's name and version and every param that changes the estimate.
void hashTraceInputs(scene::Hasher& h, const SceneObject& scene, const CameraFrame& camera, const CpuSky& sky,
                     int width, int height);

// The sky nodes' outputs read back for the CPU tracer: inputs `sky` (cube), `sky_sh` (sun texels 9 and 10) and the
// optional `env_cdf`. They must be computed earlier in the frame (call ctx.splitSubmission() first) and declared
// readBack.
CpuSky readCpuSky(ExecuteContext& ctx);
// A CpuSky of six read-back cube faces (+X -X +Y -Y +Z -Z) and a sky node's `sh` (sun illuminance at texel 9,
// direction at texel 10), without a sampling table; readCpuSky's own, and for nodes that read the sky themselves.
CpuSky cpuSkyFrom(std::vector<Image> faces, const Image& sh);

// A CpuAccumulation into a node's `color` and `stats` outputs (storage images) through a host-visible buffer and
// render/pathtrace_store.comp (the pipeline, made in setup: ctx.computePipeline("render/pathtrace_store.comp", {}, 1)).
class CpuResultUpload {
public:
    void upload(ExecuteContext& ctx, PipelineId storePipeline, const CpuAccumulation& acc);

private:
    GpuBuffer mBuffer;
    StorageBufferSet mSet;
};

} // namespace vitrine
