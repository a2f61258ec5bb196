#ifndef DEPTH_HIZ_H
#define DEPTH_HIZ_H
#include "../common/shared.h"

#ifdef __cplusplus
namespace vitrine::gpu_types {
#endif
// One dispatch of a mip-atlas reduction (depth.hiz, color.pyramid): levels first .. first + count - 1 from
// level `source` (-1: the input texture, which is level 0's size).
VITRINE_PUSH_BEGIN(MipChainPush)
    ivec2 size; // level 0
    int source;
    int first;
    int count;
    int fallback; // color.pyramid: 1 when the `fallback` input stands in for a history not yet written
VITRINE_PUSH_END(pc)
#ifdef __cplusplus
static_assert(sizeof(MipChainPush) == 24);
}
#endif
#endif
