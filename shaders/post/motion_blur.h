// post.motion_blur's push constants, shared by nodes/post/motion_blur.cpp and shaders/post/motion_blur*.comp.
#ifndef POST_MOTION_BLUR_H
#define POST_MOTION_BLUR_H
#include "../common/shared.h"

#ifdef __cplusplus
namespace vitrine::gpu_types {
#endif
VITRINE_PUSH_BEGIN(MotionBlurPush)
    float halfScale; // half-length of a pixel's blur = |velocity| x halfScale (0.5 x the exposed fraction of a frame)
    float maxRadius; // half-lengths are clamped to this (the tile size), so the neighbour max bounds every blur
    int tileSize;    // K: pixels per tile side
    uint samples;    // S: gather taps along the neighbourhood's dominant velocity
    float softZ;     // metres over which "in front of" fades in (McGuire12's SOFT_Z_EXTENT)
    float dither;    // 0: taps at fixed offsets; 1: offsets jittered per pixel by up to half a tap
    uint frame;      // varies the dither per frame
    uint pad;
VITRINE_PUSH_END(pc)
#ifdef __cplusplus
static_assert(sizeof(MotionBlurPush) == 32);
}
#endif
#endif
