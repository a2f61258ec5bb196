// post.streaks's push constants, shared by nodes/post/streaks.cpp and shaders/post/streaks*.comp.
#ifndef POST_STREAKS_H
#define POST_STREAKS_H
#include "../common/shared.h"

#ifdef __cplusplus
namespace vitrine::gpu_types {
#endif
VITRINE_PUSH_BEGIN(StreaksPush)
    float exposure;  // linear scale from HDR radiance to display-referred
    float threshold; // display-referred luminance above which light streaks
    int factor;      // bright-pass downsampling
    uint count;      // spikes per source (0: none)
    float rotation;  // angle of the first spike, radians (image x right, y down)
    float spikeLength; // 3 e-folding lengths of a spike, bright-pass pixels
    float strength;  // a source's streak energy / its bright energy (all spikes together)
    uint samples;    // taps per spike
VITRINE_PUSH_END(pc)
#ifdef __cplusplus
static_assert(sizeof(StreaksPush) == 32);
}
#endif
#endif
