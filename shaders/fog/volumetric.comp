#version 460
#extension GL_GOOGLE_include_directive : require
#include "fog/volumetric.h"
#include "common/sh.glsl"

// fog.volumetric (MUSEUM_SPEC §5): at low resolution, march from the camera to the G-buffer's surface (or
// cameraPos.w metres where there is sky) through a participating medium of density sigma(y) =
// sigma0 exp(-falloff (y - y0)) and scattering albedo 1. Each step adds the light scattered towards the camera,
//   sun:     E_sun p_HG(l . v) V(x)        (V from the cascaded shadow map: shafts through the windows)
//   ambient: sum_lm g^l L_lm Y_lm(v)       (the sky's SH radiance convolved with the HG lobe: HG's zonal
//                                          coefficients are g^l, so this is the integral of L(w) p_HG(w . v) dw)
// integrated over the step with sigma and the source held constant: L += T S (1 - exp(-sigma dt)),
// T *= exp(-sigma dt). Writes the in-scattered radiance (rgb) and the transmittance to the surface (a), and the
// distance marched, for fog.composite's depth-aware upsample. The march starts at a sub-step offset: fixed,
// or per pixel (interleaved gradient noise) moved each frame by the golden ratio, so that a temporal
// accumulation between this node and fog.composite converges to the integral.
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0) uniform sampler2D in_depth;
layout(binding = 1) uniform sampler2D in_shadow_map;
layout(binding = 2) uniform sampler2D in_sky_sh;
layout(binding = 3) writeonly uniform image2D out_scatter;
layout(binding = 4) writeonly uniform image2D out_distance;
layout(binding = 5) uniform Uniforms { FogMarchUniforms u; };
#define VITRINE_SHADOW u.shadow
#include "lighting/sun_shadow.glsl"

const float kPi = 3.14159265358979;
const float kHalfMax = 60000.0; // keep the RGBA16F output finite
// The sky nodes' `sh` texels (shaders/sky/sky.h, not included: it declares sky.procedural's push constants).
const int kSkyTexelSunIlluminance = 9, kSkyTexelSunDirection = 10;

// Henyey-Greenstein phase function (1/sr), normalised over the sphere; cosTheta between the light's direction
// of travel and the scattered light's (here: dot(toward the light, toward the scene point)).
float phaseHg(float cosTheta, float g) {
    float d = 1.0 + g * g - 2.0 * g * cosTheta;
    return (1.0 - g * g) / (4.0 * kPi * d * sqrt(d));
}

// Interleaved gradient noise [Jimenez14]: a per-pixel offset in [0, 1) that spreads well over neighbours.
float interleavedGradientNoise(vec2 p) { return fract(52.9829189 * fract(dot(p, vec2(0.06711056, 0.00583715)))); }

void main() {
    ivec2 q = ivec2(gl_GlobalInvocationID.xy);
    ivec2 lowSize = imageSize(out_scatter);
    if (any(greaterThanEqual(q, lowSize))) return;
    ivec2 fullSize = ivec2(u.march.yz);
    // The full-resolution pixel this low-resolution pixel stands for (the one under its centre).
    ivec2 p = min(ivec2((vec2(q) + 0.5) * vec2(fullSize) / vec2(lowSize)), fullSize - 1);
    vec2 uv = (vec2(p) + 0.5) / vec2(fullSize);
    float z = texelFetch(in_depth, p, 0).r;
    vec4 wh = u.invViewProj * vec4(uv * 2.0 - 1.0, max(z, 1e-7), 1.0);
    vec3 toPoint = wh.xyz / wh.w - u.cameraPos.xyz;
    vec3 dir = normalize(toPoint);
    float dist = z > 0.0 ? length(toPoint) : u.cameraPos.w;

    vec3 sunE = texelFetch(in_sky_sh, ivec2(kSkyTexelSunIlluminance, 0), 0).rgb * u.lighting.x;
    vec3 l = normalize(texelFetch(in_sky_sh, ivec2(kSkyTexelSunDirection, 0), 0).xyz);
    float g = u.medium.w;
    vec3 sunSource = sunE * phaseHg(dot(l, dir), g);
    float b[9];
    shBasis9(dir, b);
    vec3 ambient = texelFetch(in_sky_sh, ivec2(0, 0), 0).rgb * b[0];
    for (int i = 1; i < 4; ++i) ambient += g * texelFetch(in_sky_sh, ivec2(i, 0), 0).rgb * b[i];
    for (int i = 4; i < 9; ++i) ambient += g * g * texelFetch(in_sky_sh, ivec2(i, 0), 0).rgb * b[i];
    ambient = max(ambient, vec3(0.0)) * u.lighting.y;

    int steps = int(u.march.x);
    float dt = dist / float(steps);
    float offset = u.lighting.w >= 0.0 ? u.lighting.w
                                       : fract(interleavedGradientNoise(vec2(q)) + 0.618034 * float(u.march.w % 64u));
    bool shadows = u.lighting.z > 0.5;
    vec3 scatter = vec3(0.0);
    float transmittance = 1.0;
    for (int i = 0; i < steps; ++i) {
        vec3 x = u.cameraPos.xyz + dir * ((float(i) + offset) * dt);
        float sigma = u.medium.x * exp(-u.medium.y * (x.y - u.medium.z));
        float visibility = shadows ? sunVisibilityPoint(in_shadow_map, x, dot(x - u.cameraPos.xyz, u.cameraFwd.xyz)) : 1.0;
        float stepT = exp(-sigma * dt);
        scatter += transmittance * (sunSource * visibility + ambient) * (1.0 - stepT);
        transmittance *= stepT;
    }
    imageStore(out_scatter, q, vec4(min(scatter, vec3(kHalfMax)), transmittance));
    imageStore(out_distance, q, vec4(z > 0.0 ? dist : FOG_SKY_DISTANCE));
}
