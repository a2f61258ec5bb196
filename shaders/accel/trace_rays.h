// A batch of rays traced against the BVH (core/accel/ray_batch.hpp): for tests, benchmarks and CPU-side
// bakers that have rays in a buffer. Shared by C++ and GLSL.
#ifndef ACCEL_TRACE_RAYS_H
#define ACCEL_TRACE_RAYS_H
#include "../common/shared.h"

#ifdef __cplusplus
namespace vitrine::gpu_types {
#endif

struct GpuRay {
    vec4 origin;    // xyz; w: tmin
    vec4 direction; // xyz (any length: t is in its units); w: tmax
};

struct GpuRayHit {
    vec4 hit; // x: t (+inf on a miss), yz: barycentrics of v1 and v2, w: 0
    uvec4 id; // x: BVH triangle (VITRINE_BVH_NONE: miss), y: scene instance, z, w: 0
};

VITRINE_PUSH_BEGIN(TraceRaysPush)
    uint rayCount;
    uint anyHit;   // 1: bvhTraceAny (shadow rays): id.x is 0 when something is hit, else VITRINE_BVH_NONE
    uint rowWidth; // rays per row of the dispatch grid: index = x + y * rowWidth
    uint pad;
VITRINE_PUSH_END(push)

#ifdef __cplusplus
static_assert(sizeof(GpuRay) == 32);
static_assert(sizeof(GpuRayHit) == 32);
static_assert(sizeof(TraceRaysPush) == 16);
}
#endif
#endif
