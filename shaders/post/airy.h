// post.airy (diffraction at a small aperture): push constants shared by nodes/post/airy.cpp and
// shaders/post/airy_psf.comp / airy.comp.
#ifndef POST_AIRY_H
#define POST_AIRY_H
#include "../common/shared.h"

#define AIRY_FIRST_ZERO 3.83170597 // first zero of J1: the Airy pattern's first dark ring at x = 3.8317

#ifdef __cplusplus
namespace vitrine::gpu_types {
#endif

VITRINE_PUSH_BEGIN(AiryPush)
    vec4 firstZero; // rgb: radius of the first dark ring in pixels, 1.22 lambda N / pixel pitch, per channel
    int radius;     // kernel half-size used this frame (pixels); the psf image is (2 maxRadius + 1)^2
    int maxRadius;
    uint supersample; // per axis: the PSF is integrated over each pixel with supersample^2 points
    uint pad;
VITRINE_PUSH_END(pc)

#ifdef __cplusplus
static_assert(sizeof(AiryPush) == 32);
}
#endif
#endif
