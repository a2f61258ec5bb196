#version 460
#extension GL_GOOGLE_include_directive : require
#include "sky/sky.h"
#include "common/cubemap.glsl"
#include "common/sh.glsl"
#include "sky/procedural_env.glsl"

// sky.procedural, SH pass: one workgroup of 64 threads projects the environment WITHOUT the
// sun disk, evaluated at the centre of every texel of the cube map (the same values the cube
// pass writes there), onto SH9 with exact texel solid angles; then writes the sun's data.
// A fixed-order reduction through shared memory keeps the result deterministic.
layout(local_size_x = 64) in;
layout(binding = 0) writeonly uniform image2D out_sh;

shared vec3 sCoefficients[64][9];

void main() {
    uint t = gl_LocalInvocationIndex;
    vec3 toSun = pc.toSun.xyz;
    float T = pc.toSun.w;
    skyEnvironmentSetup(t, toSun, T, pc.groundAlbedo, pc.sunAngularRadius, pc.intensity);

    int size = int(pc.size);
    uint texels = 6u * uint(size * size);
    vec3 c[9];
    for (int i = 0; i < 9; ++i) c[i] = vec3(0.0);
    for (uint i = t; i < texels; i += 64u) {
        uint face = i / uint(size * size);
        uint rem = i % uint(size * size);
        ivec2 texel = ivec2(rem % uint(size), rem / uint(size));
        vec3 d = cubeTexelDirection(face, texel, size);
        vec3 L = skyEnvironment(d, toSun, T) * cubeTexelSolidAngle(texel, size);
        float b[9];
        shBasis9(d, b);
        for (int k = 0; k < 9; ++k) c[k] += L * b[k];
    }
    for (int k = 0; k < 9; ++k) sCoefficients[t][k] = c[k];
    barrier();
    if (t < 9u) {
        vec3 sum = vec3(0.0);
        for (uint i = 0u; i < 64u; ++i) sum += sCoefficients[i][t];
        imageStore(out_sh, ivec2(int(t), 0), vec4(sum, 0.0));
    } else if (t == SKY_TEXEL_SUN_ILLUMINANCE) {
        imageStore(out_sh, ivec2(int(t), 0), vec4(gSunIlluminance, 0.0));
    } else if (t == SKY_TEXEL_SUN_DIRECTION) {
        imageStore(out_sh, ivec2(int(t), 0), vec4(toSun, 0.0));
    } else if (t == SKY_TEXEL_SUN_INFO) {
        imageStore(out_sh, ivec2(int(t), 0), vec4(dot(gSunRadiance, vec3(0.2126729, 0.7151522, 0.0721750)), pc.sunAngularRadius, T, 0.0));
    } else if (t < uint(SKY_SH_WIDTH)) {
        imageStore(out_sh, ivec2(int(t), 0), vec4(0.0));
    }
}
