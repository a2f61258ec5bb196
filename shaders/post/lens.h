// post.lens's push constants, shared by nodes/post/lens.cpp and shaders/post/lens.comp.
#ifndef POST_LENS_H
#define POST_LENS_H
#include "../common/shared.h"

#ifdef __cplusplus
namespace vitrine::gpu_types {
#endif
VITRINE_PUSH_BEGIN(LensPush)
    vec2 centre;        // optical centre in pixels (the image centre)
    float halfDiagonal; // pixels: radii are normalised to it
    float k1;           // r_d = r (1 + k1 r^2 + k2 r^4), r the ideal (undistorted) normalised radius
    float k2;
    float caRed;        // lateral CA: the red and blue images' radial scale relative to green (1: none)
    float caBlue;
    float mmPerPixel;   // sensor millimetres per pixel (sensor width / image width)
    float focalMm;      // natural vignetting: cos^4 of the field angle, tan = r_mm / focal
    float pupil;        // mechanical vignetting: the entrance pupil's radius relative to the barrel's opening
    float mechanical;   // the opening's offset at the frame corner, in its radii (0: none)
    uint flags;         // LENS_* bits
VITRINE_PUSH_END(pc)
#ifdef __cplusplus
static_assert(sizeof(LensPush) == 48);
}
#endif

#define LENS_DISTORTION 1u
#define LENS_CA 2u
#define LENS_NATURAL_VIGNETTING 4u
#define LENS_MECHANICAL_VIGNETTING 8u
#endif
