#ifndef SKY_SKY_H
#define SKY_SKY_H
#include "../common/shared.h"

// The `sh` output of the sky nodes (sky.procedural, sky.hdri): a 16x1 RGBA32F texture.
//   texels 0-8  SH9 RADIANCE coefficients (rgb, cd/m^2) of the environment WITHOUT the sun
//               (order and irradiance convolution: shaders/common/sh.glsl)
//   texel 9     sun illuminance on a surface perpendicular to the sun (rgb; luminance in lux)
//   texel 10    unit direction toward the sun (xyz), w = 0
//   texel 11    (sun disk radiance luminance cd/m^2, sun angular radius rad, turbidity, 0)
//   texels 12-15 zero (reserved)
#define SKY_SH_WIDTH 16
#define SKY_TEXEL_SUN_ILLUMINANCE 9
#define SKY_TEXEL_SUN_DIRECTION 10
#define SKY_TEXEL_SUN_INFO 11

#ifdef __cplusplus
namespace vitrine::gpu_types {
#endif
VITRINE_PUSH_BEGIN(SkyProceduralPush)
    vec4 toSun;             // xyz: unit direction toward the sun; w: turbidity
    float groundAlbedo;     // Lambertian ground below the horizon
    float sunAngularRadius; // radians
    uint size;              // cube face size
    uint sunInCubemap;      // 1: add the sun disk to the cube map (never to the SH)
    float intensity;        // scale of all radiance: sky, sun, ground
    float pad0, pad1, pad2;
VITRINE_PUSH_END(pc)
#ifdef __cplusplus
static_assert(sizeof(SkyProceduralPush) == 48);
}
#endif
#endif
