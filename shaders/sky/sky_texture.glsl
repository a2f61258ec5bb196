#ifndef SKY_SKY_TEXTURE_GLSL
#define SKY_SKY_TEXTURE_GLSL

// Reading the `sh` output of sky.procedural / sky.hdri (layout in sky/sky.h) from a lighting
// shader that binds it as `sampler2D`.
#include "sky/sky.h"
#include "common/sh.glsl"

// Irradiance (lux) from the environment without the sun on a surface with unit normal n.
vec3 skyIrradiance(sampler2D skySh, vec3 n) {
    vec3 c[9];
    for (int i = 0; i < 9; ++i) c[i] = texelFetch(skySh, ivec2(i, 0), 0).rgb;
    return shIrradiance(c, n);
}

// Sun illuminance (lux) on a surface facing it; the directional light's intensity is this / pi.
vec3 skySunIlluminance(sampler2D skySh) { return texelFetch(skySh, ivec2(SKY_TEXEL_SUN_ILLUMINANCE, 0), 0).rgb; }
vec3 skySunDirection(sampler2D skySh) { return texelFetch(skySh, ivec2(SKY_TEXEL_SUN_DIRECTION, 0), 0).xyz; }

#endif
