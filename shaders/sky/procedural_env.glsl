#ifndef SKY_PROCEDURAL_ENV_GLSL
#define SKY_PROCEDURAL_ENV_GLSL

// What both sky.procedural shaders share: per workgroup of 64 threads, the sun's radiance and
// the ground's radiance (albedo / pi times the sky's horizontal irradiance plus the sun's),
// then the environment radiance without the sun disk in any direction; all of it scaled by the
// node's `intensity` (a brighter or dimmer day; 1 = Preetham's absolute values).
#include "sky/preetham.glsl"

shared vec3 sIrradianceShare[64];
shared vec3 sSunRadiance;

vec3 gSunRadiance; // disk radiance at the ground
vec3 gSunIlluminance; // on a surface facing the sun
vec3 gGroundRadiance;
float gSkyIntensity;

// Called by all 64 threads of the workgroup, in uniform control flow (it has barriers).
void skyEnvironmentSetup(uint thread, vec3 toSun, float T, float groundAlbedo, float sunAngularRadius, float intensity) {
    gSkyIntensity = intensity;
    sIrradianceShare[thread] = preethamIrradianceShare(thread, 64u, toSun, T);
    if (thread == 0u) sSunRadiance = preethamSunRadiance(T, acos(clamp(toSun.y, -1.0, 1.0)));
    barrier();
    vec3 skyIrradiance = vec3(0.0);
    for (uint i = 0u; i < 64u; ++i) skyIrradiance += sIrradianceShare[i];
    gSunRadiance = sSunRadiance * intensity;
    gSunIlluminance = gSunRadiance * sunDiskFactor(sunAngularRadius);
    gGroundRadiance = groundAlbedo / kSkyPi * (skyIrradiance * intensity + gSunIlluminance * max(toSun.y, 0.0));
}

vec3 skyEnvironment(vec3 d, vec3 toSun, float T) {
    return d.y >= 0.0 ? preethamSky(d, toSun, T) * gSkyIntensity : gGroundRadiance;
}

#endif
