#ifndef DEBUG_VIEW_H
#define DEBUG_VIEW_H
#include "../common/shared.h"

#define VIEW_RGBA 0
#define VIEW_RGB 1
#define VIEW_R 2
#define VIEW_G 3
#define VIEW_B 4
#define VIEW_A 5
#define VIEW_LUMA 6

#ifdef __cplusplus
namespace vitrine::gpu_types {
#endif
VITRINE_PUSH_BEGIN(ViewPush)
    float rangeMin;
    float rangeMax;
    uint channel;    // VIEW_*
    uint falseColor; // 1: map the (single-channel) value through a colour ramp
VITRINE_PUSH_END(pc)
#ifdef __cplusplus
static_assert(sizeof(ViewPush) == 16);
}
#endif
#endif
