#pragma once
// "Converge, then cache" for per-pixel Monte Carlo estimates: render.pathtrace's target_noise, shared with the
// ray-traced twins (nodes/reference/). An estimate accumulates batches of samples (CpuAccumulation: mean colour
// and the stats of the samples' luminance) until the median relative standard error over lit pixels is at most
// target_noise and min_spp samples are in; a converged result is stored in the bake cache under a key of everything
// it depends on and loaded, not traced, by later runs. A run that stops first (max_seconds ran out, or the user
// pressed Ctrl-C) keeps what it accumulated in the cache as a partial result, and the next run under the same key
// resumes from it: an hour-long reference can be traced in pieces.
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
    // Asked after every batch: true stops the run there as max_seconds does (ExecuteContext::stopRequested: Ctrl-C).
    std::function<bool()> stop;
    // Where a resumed run starts: the batches an earlier run of the same key traced (acc then holds their samples and
    // is not reset) and the seconds it took. 0: a fresh run (acc is reset).
    uint32_t firstBatch = 0;
    double secondsBefore = 0.0;
};

// How far a run got: its batches (0 .. batches - 1 are in the accumulation) and the seconds they took, over every
// run that resumed it.
struct ConvergeProgress {
    uint32_t batches = 0;
    double seconds = 0.0;
    bool converged = false;
};

// The seed of batch b of a run whose `seed` param is `seed` (independent sequences per seed and batch).
uint32_t convergeBatchSeed(uint32_t seed, uint32_t b);

using TraceBatchFn = std::function<void(uint32_t spp, uint32_t seed, uint32_t batch)>;

// Resets acc (unless run.firstBatch > 0) and calls traceBatch(spp, convergeBatchSeed(seed, b), b) for
// b = run.firstBatch, ... until the target and min_spp hold (converged) or max_seconds ran out or run.stop said so.
// traceBatch adds its samples to acc; acc.stats must be current when it returns.
ConvergeProgress convergeAccumulation(const ConvergeRun& run, CpuAccumulation& acc, const TraceBatchFn& traceBatch);

// What a tracer does around convergeCached's batches. resumed(acc): acc now holds a partial result loaded from the
// cache (the GPU tracer uploads it into its outputs before it adds batches). finished(acc): the batches are done and
// acc is about to be stored (the GPU tracer reads its colour back into it).
struct ConvergeHooks {
    std::function<void(const CpuAccumulation&)> resumed;
    std::function<void(CpuAccumulation&)> finished;
};

// The whole "converge, then cache" of one estimate under `key` (of kind "reference"): the converged result if the
// cache has it; else the partial result an earlier run stopped with (kind "reference_partial", the same hash), if
// any, resumed, or a fresh run; a converged result is stored and its partial removed, a stopped one stored as the
// partial. Batch b's seed is the same whichever run traces it, so on the CPU tracers a result converged over several
// runs is bit for bit the one a single run makes. True when acc holds a converged result.
bool convergeCached(const BakeKey& key, const ConvergeRun& run, CpuAccumulation& acc, const TraceBatchFn& traceBatch,
                    const ConvergeHooks& hooks = {});
// The key a stopped run's partial result is kept under.
BakeKey partialKey(const BakeKey& key);

// What every traced estimate of the camera's view depends on, into a cache key: the scene's light-transport content
// and pose (where a mesh deforms, every node and morph weight too), the camera (unjittered view-projection and
// position), the sky's pixels and sun, the frame size. The caller adds its node's name and version and every param that
// changes the estimate.
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
