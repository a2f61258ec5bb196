#ifndef COMPARE_SIDE_BY_SIDE_H
#define COMPARE_SIDE_BY_SIDE_H
#include "../common/shared.h"

#ifdef __cplusplus
namespace vitrine::gpu_types {
#endif
VITRINE_PUSH_BEGIN(SideBySidePush)
    vec4 separatorColor; // linear RGBA of the seam line; alpha blends it over the images
    uint separatorWidth; // pixels of the seam line on each side of the middle (0: none)
    uint pad0;
    uint pad1;
    uint pad2;
VITRINE_PUSH_END(pc)
#ifdef __cplusplus
static_assert(sizeof(SideBySidePush) == 32);
}
#endif
#endif
