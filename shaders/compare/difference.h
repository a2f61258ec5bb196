#ifndef COMPARE_DIFFERENCE_H
#define COMPARE_DIFFERENCE_H
#include "../common/shared.h"

#ifdef __cplusplus
namespace vitrine::gpu_types {
#endif
VITRINE_PUSH_BEGIN(DifferencePush)
    float scale;     // |a - b| is multiplied by this
    uint falseColor; // 1: magma of clamp(scale * max(|a - b|.rgb), 0, 1), as compare::falseColor() on the CPU
VITRINE_PUSH_END(pc)
#ifdef __cplusplus
static_assert(sizeof(DifferencePush) == 8);
}
#endif
#endif
