// gbuffer.temporal_filter's push constants, shared by nodes/gbuffer/temporal_filter.cpp and
// shaders/gbuffer/temporal_filter.comp.
#ifndef GBUFFER_TEMPORAL_FILTER_H
#define GBUFFER_TEMPORAL_FILTER_H
#include "../common/shared.h"

#define GBUFFER_FILTER_HISTORY_VALID 1u // not the first frame: the history holds last frame's averaged normals
#define GBUFFER_FILTER_VELOCITY 2u      // the velocity input is connected

#ifdef __cplusplus
namespace vitrine::gpu_types {
#endif
VITRINE_PUSH_BEGIN(GbufferFilterPush)
    float feedback;       // weight of the reprojected history in the normal's running blend
    float depthTolerance; // relative view-depth difference beyond which a history texel is another surface
    uint flags;           // GBUFFER_FILTER_*
    uint pad0;
VITRINE_PUSH_END(pc)
#ifdef __cplusplus
static_assert(sizeof(GbufferFilterPush) == 16);
}
#endif
#endif
