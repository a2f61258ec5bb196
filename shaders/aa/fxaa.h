#ifndef AA_FXAA_H
#define AA_FXAA_H
#include "../common/shared.h"

#ifdef __cplusplus
namespace vitrine::gpu_types {
#endif
VITRINE_PUSH_BEGIN(FxaaPush)
    float subpix;           // amount of sub-pixel aliasing removal, 0..1
    float edgeThreshold;    // minimum local contrast, relative to the local maximum luma
    float edgeThresholdMin; // absolute contrast below which dark areas are skipped
    uint searchSteps;       // steps of the edge-end search (up to 12)
VITRINE_PUSH_END(pc)
#ifdef __cplusplus
static_assert(sizeof(FxaaPush) == 16);
}
#endif
#endif
