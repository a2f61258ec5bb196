#pragma once

// Traces a batch of rays from the host through a GpuBvh with one compute dispatch
// (shaders/accel/trace_rays.comp) and reads the hits back, with the dispatch's GPU time from timestamp
// queries and on the host. For tests (GPU traversal against the CPU), `vitrine bench --bvh` and bakers whose rays start
// on the CPU; a render pass traces from its own shader through shaders/accel/bvh.glsl instead.

#include "core/accel/gpu_bvh.hpp"
#include "shaders/accel/trace_rays.h"

#include <span>
#include <vector>

namespace vitrine {

class ShaderCompiler;

class RayBatchTracer {
public:
    RayBatchTracer(Context& ctx, ShaderCompiler& shaders);
    ~RayBatchTracer();
    RayBatchTracer(const RayBatchTracer&) = delete;
    RayBatchTracer& operator=(const RayBatchTracer&) = delete;

    struct Result {
        std::vector<gpu_types::GpuRayHit> hits; // one per ray, same order
        double gpuMs = 0.0;  // the dispatch alone, by timestamp queries (not trustworthy on lavapipe)
        double wallMs = 0.0; // its submission, from vkQueueSubmit until the fence signalled (host clock)
    };
    // Closest hits, or occlusion (anyHit: bvhTraceAny; id.x is 0 when occluded, else VITRINE_BVH_NONE). Waits.
    Result trace(const GpuBvh& bvh, std::span<const gpu_types::GpuRay> rays, bool anyHit = false);

private:
    Context& mCtx;
    VkDescriptorSetLayout mRaySetLayout = VK_NULL_HANDLE;
    VkPipelineLayout mLayout = VK_NULL_HANDLE;
    VkPipeline mPipeline = VK_NULL_HANDLE;
    VkDescriptorSetLayout mBvhSetLayout = VK_NULL_HANDLE; // the layout the pipeline was made with
    uint32_t mLocalSize = 64;
};

} // namespace vitrine
