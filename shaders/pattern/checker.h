#ifndef PATTERN_CHECKER_H
#define PATTERN_CHECKER_H
#include "../common/shared.h"

#ifdef __cplusplus
namespace vitrine::gpu_types {
#endif
VITRINE_PUSH_BEGIN(CheckerPush)
    vec4 colorA;
    vec4 colorB;
    float cellSize;     // pixels
    float angle;        // radians
    uint supersample;
    float pad;
VITRINE_PUSH_END(ck)
#ifdef __cplusplus
static_assert(sizeof(CheckerPush) == 48);
}
#endif
#endif
