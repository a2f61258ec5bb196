#ifndef POST_GRAIN_H
#define POST_GRAIN_H
#include "../common/shared.h"

#ifdef __cplusplus
namespace vitrine::gpu_types {
#endif
VITRINE_PUSH_BEGIN(GrainPush)
    float sigma;  // standard deviation of the grain in sRGB-encoded units
    float size;   // lattice spacing of the grain in pixels
    uint seed;    // hash of the frame index and the `seed` param
    uint pad;
VITRINE_PUSH_END(pc)
#ifdef __cplusplus
static_assert(sizeof(GrainPush) == 16);
}
#endif
#endif
