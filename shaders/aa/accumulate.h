// aa.accumulate's push constants, shared by nodes/aa/accumulate.cpp and shaders/aa/accumulate.comp.
#ifndef AA_ACCUMULATE_H
#define AA_ACCUMULATE_H
#include "../common/shared.h"

#ifdef __cplusplus
namespace vitrine::gpu_types {
#endif
VITRINE_PUSH_BEGIN(AccumulatePush)
    uint index; // this frame's sample: 0 restarts, index < samples adds, index >= samples keeps the mean
    uint samples; // N x N
    uint pad0;
    uint pad1;
VITRINE_PUSH_END(pc)
#ifdef __cplusplus
static_assert(sizeof(AccumulatePush) == 16);
}
#endif
#endif
