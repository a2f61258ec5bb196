#ifndef POST_TONEMAP_H
#define POST_TONEMAP_H
#include "../common/shared.h"

#define TONEMAP_LINEAR 0
#define TONEMAP_REINHARD 1
#define TONEMAP_REINHARD_MAX 2
#define TONEMAP_ACES_FIT 3
#define TONEMAP_PBR_NEUTRAL 4

#ifdef __cplusplus
namespace vitrine::gpu_types {
#endif
VITRINE_PUSH_BEGIN(TonemapPush)
    float exposureScale; // 2^EV
    uint op;             // TONEMAP_*
    uint inverse;        // 1: undo the curve, then the exposure
    uint pad;
VITRINE_PUSH_END(pc)
#ifdef __cplusplus
static_assert(sizeof(TonemapPush) == 16);
}
#endif
#endif
