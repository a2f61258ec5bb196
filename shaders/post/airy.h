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

#ifndef __cplusplus
#include "camera/exposure.glsl"
// Rings the kernel reaches: its half-size is this many first-zero radii (nodes/post/airy.cpp's kRingsReach).
#define AIRY_RINGS_REACH (16.4706 / AIRY_FIRST_ZERO)
// The first dark ring's radius per channel (pixels) this frame: pc.firstZero, or with the camera's f-number on the
// GPU (camera_state connected, f_number 0) pc.firstZero per unit f-number times it.
vec3 airyFirstZero() {
#ifdef CAMERA_EXPOSURE
    return pc.firstZero.rgb * cameraExposure.fNumber;
#else
    return pc.firstZero.rgb;
#endif
}
// The kernel half-size this frame: pc.radius, or with the camera's f-number derived here (pc.radius is the cap).
int airyRadius() {
#ifdef CAMERA_EXPOSURE
    vec3 r0 = airyFirstZero();
    return clamp(int(ceil(AIRY_RINGS_REACH * max(max(r0.r, r0.g), r0.b))), 1, pc.maxRadius);
#else
    return pc.radius;
#endif
}
#endif
#endif
