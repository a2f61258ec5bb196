// temporal.accumulate's push constants, shared by nodes/temporal/accumulate.cpp and shaders/temporal/accumulate.comp.
#ifndef TEMPORAL_ACCUMULATE_H
#define TEMPORAL_ACCUMULATE_H
#include "../common/shared.h"

#define TEMPORAL_HISTORY_VALID 1u    // not the first frame: history and history_samples hold last frame's output
#define TEMPORAL_VELOCITY 2u         // velocity is connected
#define TEMPORAL_VELOCITY_HISTORY 4u // history_velocity is connected (and valid): Sousa13's velocity difference
#define TEMPORAL_DEPTH 8u            // depth and history_depth are connected (and valid): disocclusion test

#ifdef __cplusplus
namespace vitrine::gpu_types {
#endif
VITRINE_PUSH_BEGIN(TemporalAccumulatePush)
    float maxSamples;      // the sample count is capped here: the running mean of the last ~maxSamples frames
    float velocityWeight;  // history weight x max(0, 1 - velocityWeight |v - v_prev|), |.| in velocity-buffer pixels
    float depthTolerance;  // relative view-depth difference beyond which the history is another surface
    float luminanceWeight; // history weight x (1 - luminanceWeight |Lc - Lh| / max(Lc, Lh, luminanceFloor))
    float luminanceFloor;  // luminances below this count as this (noise in the dark is not a ghost)
    uint flags;            // TEMPORAL_*
    uint pad0;
    uint pad1;
VITRINE_PUSH_END(pc)
#ifdef __cplusplus
static_assert(sizeof(TemporalAccumulatePush) == 32);
}
#endif
#endif
