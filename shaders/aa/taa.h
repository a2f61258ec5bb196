// aa.taa's push constants, shared by nodes/aa/taa.cpp and shaders/aa/taa.comp.
#ifndef AA_TAA_H
#define AA_TAA_H
#include "../common/shared.h"

#define TAA_CLAMP_NONE 0u
#define TAA_CLAMP_MINMAX 1u
#define TAA_CLAMP_VARIANCE 2u

#define TAA_FILTER_CATMULL_ROM 0u
#define TAA_FILTER_BILINEAR 1u

#define TAA_HISTORY_VALID 1u // not the first frame: the history holds last frame's output
#define TAA_VELOCITY 2u      // the velocity input is connected
#define TAA_DEPTH 4u         // depth and history_depth are connected

#ifdef __cplusplus
namespace vitrine::gpu_types {
#endif
VITRINE_PUSH_BEGIN(TaaPush)
    float feedback;       // largest weight of the history in the blend
    float exposureScale;  // 2^exposure, applied before the tone curve of the blend
    float gamma;          // variance clip: box of mean +- gamma * sigma
    float maxVelocity;    // pixels per frame; faster pixels skip the history
    float depthTolerance; // relative view-depth difference beyond which the history is another surface
    float sharpen;        // 0..1, unsharp mask of the current frame (tone-mapped)
    uint clampMode;       // TAA_CLAMP_*
    uint historyFilter;   // TAA_FILTER_*
    uint flags;           // TAA_HISTORY_VALID | TAA_VELOCITY | TAA_DEPTH
    uint pad0;
    uint pad1;
    uint pad2;
VITRINE_PUSH_END(pc)
#ifdef __cplusplus
static_assert(sizeof(TaaPush) == 48);
}
#endif
#endif
