#version 460
#extension GL_GOOGLE_include_directive : require
#include "sky/sky.h"
#include "common/cubemap.glsl"
#include "sky/procedural_env.glsl"

// sky.procedural, cube map pass: one thread per texel, layer = gl_GlobalInvocationID.z.
// The environment (Preetham sky, lit ground) at the texel centre, plus the sun disk's share
// of the texel: kSunPoints equal-area points on the disk (a sunflower spiral), each carrying
// 1 / kSunPoints of the disk's solid angle, are binned into texels. This conserves the sun's
// energy at any face size, also when the disk is far smaller than a texel.
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0) writeonly uniform imageCube out_cubemap;

const uint kSunPoints = 256u;

float sunCoverage(uint face, ivec2 texel, int size, vec3 toSun, float radius) {
    vec3 t1 = normalize(abs(toSun.y) < 0.99 ? cross(toSun, vec3(0.0, 1.0, 0.0)) : cross(toSun, vec3(1.0, 0.0, 0.0)));
    vec3 t2 = cross(toSun, t1);
    uint hits = 0u;
    for (uint k = 0u; k < kSunPoints; ++k) {
        float r = radius * sqrt((float(k) + 0.5) / float(kSunPoints));
        float phi = 2.39996323 * float(k);
        vec3 d = toSun * cos(r) + (t1 * cos(phi) + t2 * sin(phi)) * sin(r);
        vec2 uv;
        uint f = cubeFace(d, uv);
        ivec2 p = clamp(ivec2(floor((uv * 0.5 + 0.5) * float(size))), ivec2(0), ivec2(size - 1));
        if (f == face && p == texel) ++hits;
    }
    return float(hits) / float(kSunPoints);
}

void main() {
    vec3 toSun = pc.toSun.xyz;
    float T = pc.toSun.w;
    skyEnvironmentSetup(gl_LocalInvocationIndex, toSun, T, pc.groundAlbedo, pc.sunAngularRadius, pc.intensity);

    int size = int(pc.size);
    ivec2 texel = ivec2(gl_GlobalInvocationID.xy);
    uint face = gl_GlobalInvocationID.z;
    if (texel.x >= size || texel.y >= size) return;
    vec3 d = cubeTexelDirection(face, texel, size);
    vec3 L = skyEnvironment(d, toSun, T);
    // Texels farther from the sun than the disk radius plus a texel diagonal cannot hold it.
    if (pc.sunInCubemap != 0u && acos(clamp(dot(d, toSun), -1.0, 1.0)) < pc.sunAngularRadius + 3.0 / float(size)) {
        float coverage = sunCoverage(face, texel, size, toSun, pc.sunAngularRadius);
        float halfSin = sin(0.5 * pc.sunAngularRadius); // 1 - cos(r) loses most digits in fp32
        float sunSolidAngle = 4.0 * kSkyPi * halfSin * halfSin;
        L += gSunRadiance * (coverage * sunSolidAngle / cubeTexelSolidAngle(texel, size));
    }
    imageStore(out_cubemap, ivec3(texel, int(face)), vec4(L, 1.0));
}
