#pragma once
// What the ray-traced twins (nodes/reference/) share: the CPU tracer of the frame's pose, their common params (spp,
// seed, report and render.pathtrace's target_noise / min_spp / max_seconds) and the run of one estimate per frame,
// or, with target_noise > 0, "converge, then cache" (nodes/render/converge.hpp) under a key of everything the
// estimate depends on.
#include "nodes/render/converge.hpp"
#include "nodes/render/pathtrace_cpu.hpp"

#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace vitrine {

// spp, seed, report, then appendConvergeParams (sppDefault samples per pixel per frame or per batch).
void appendTwinParams(std::vector<ParamSpec>& params, int sppDefault);

class TwinTracer {
public:
    // The CPU tracer of the scene at this frame's pose (rebuilt when the pose changes).
    CpuPathTracer& tracer(const SceneObject& scene);

    // The settings of the camera's unjittered view at `width` x `height` (spp and seed left to run()).
    static CpuTraceSettings settings(const CameraFrame& cam, int width, int height);

    // The frame's estimate: with target_noise 0, `spp` samples of `sample` per pixel (a new estimate every frame,
    // seeded by the frame index and `seed`); with target_noise > 0, the converged result cached under `key` (the
    // caller hashes hashTraceInputs, its node name and version, and every param that changes the estimate; this
    // adds spp, seed, min_spp and target_noise), traced batch by batch the first time.
    const CpuAccumulation& run(ExecuteContext& ctx, const std::string& node, const SceneObject& scene,
                               CpuTraceSettings settings, const CpuSky& sky, scene::Hasher key,
                               const CpuSampleFn& sample);

private:
    std::unique_ptr<CpuPathTracer> mCpu;
    CpuAccumulation mAccumulation;
    std::optional<uint64_t> mConvergedKey;
};

} // namespace vitrine
