#ifndef COMPARE_FLIP_H
#define COMPARE_FLIP_H
#include "../common/shared.h"

#ifdef __cplusplus
namespace vitrine::gpu_types {
#endif
VITRINE_PUSH_BEGIN(FlipPush)
    // Share of each CSF Gaussian term in its channel's 2D kernel: Y, Cx, and the two terms of Cz. The 1D kernels
    // themselves arrive as defines (FLIP_KERNEL_*), computed by core/compare for the chosen pixels per degree.
    vec4 csfWeights;
VITRINE_PUSH_END(pc)
#ifdef __cplusplus
static_assert(sizeof(FlipPush) == 16);
}
#endif
#endif
