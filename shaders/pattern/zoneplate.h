#ifndef PATTERN_ZONEPLATE_H
#define PATTERN_ZONEPLATE_H
#include "../common/shared.h"

#define ZONEPLATE_SINE 0
#define ZONEPLATE_BINARY 1

#ifdef __cplusplus
namespace vitrine::gpu_types {
#endif
VITRINE_PUSH_BEGIN(ZoneplatePush)
    float maxFrequency; // cycles per pixel reached at the corners
    uint supersample;   // N: N x N stratified samples per pixel, box filter
    uint mode;          // ZONEPLATE_*
    float pad;
    vec2 samplePos;     // this frame's sample position in the pixel (0.5, 0.5 = centre), core/scene/jitter.hpp
    vec2 pad2;
VITRINE_PUSH_END(zp)
#ifdef __cplusplus
static_assert(sizeof(ZoneplatePush) == 32);
}
#endif
#endif
