// The sun's visibility from shadow.directional's cascades (bilinear-weighted PCF), for every pass lit by the
// sun: lighting.deferred, forward.transparent, fog.volumetric.
#ifndef LIGHTING_SUN_SHADOW_GLSL
#define LIGHTING_SUN_SHADOW_GLSL
#include "shadow/cascades.h"

// VITRINE_SHADOW names the shader's ShadowCascades (a uniform member). It is read in place, not passed as an
// argument: a copy of the struct, indexed by cascade, costs lavapipe a scratch array per invocation (the
// deferred pass ran about 1.7x slower that way).
#ifndef VITRINE_SHADOW
#error "define VITRINE_SHADOW (the ShadowCascades to read) before including lighting/sun_shadow.glsl"
#endif

float shadowTap(sampler2D shadowMap, ivec2 texel, float depth) {
    ivec2 size = textureSize(shadowMap, 0);
    texel = clamp(texel, ivec2(0), size - 1);
    return depth <= texelFetch(shadowMap, texel, 0).r ? 1.0 : 0.0;
}

// Bilinear-weighted PCF: every tap compares 2x2 texels and interpolates the results; taps on a grid
// of radius lightDir.w texels around the point p (world) with normal n, at linear view depth viewDepth.
float sunVisibility(sampler2D shadowMap, vec3 p, vec3 n, float viewDepth) {
    int count = int(VITRINE_SHADOW.params.x);
    int c = 0;
    while (c < count - 1 && viewDepth > VITRINE_SHADOW.splits[c]) ++c;
    if (viewDepth > VITRINE_SHADOW.splits[count - 1]) return 1.0;
    vec3 offsetP = p + n * VITRINE_SHADOW.params.w * VITRINE_SHADOW.texelWorld[c];
    vec4 s = VITRINE_SHADOW.worldToShadow[c] * vec4(offsetP, 1.0);
    float atlas = VITRINE_SHADOW.params.y;
    vec2 st = s.xy * atlas - 0.5;
    float depth = s.z;
    int r = int(ceil(VITRINE_SHADOW.lightDir.w));
    float sum = 0.0, weight = 0.0;
    for (int y = -r; y <= r; ++y)
        for (int x = -r; x <= r; ++x) {
            vec2 q = st + vec2(x, y);
            ivec2 base = ivec2(floor(q));
            vec2 f = q - vec2(base);
            float a = mix(shadowTap(shadowMap, base, depth), shadowTap(shadowMap, base + ivec2(1, 0), depth), f.x);
            float b = mix(shadowTap(shadowMap, base + ivec2(0, 1), depth), shadowTap(shadowMap, base + ivec2(1, 1), depth), f.x);
            sum += mix(a, b, f.y);
            weight += 1.0;
        }
    return sum / weight;
}

// The sun's visibility at a point in the air (no surface, so no normal offset), at linear view depth viewDepth:
// one bilinear-weighted 2x2 comparison, no PCF grid. fog.volumetric reads it at every step of its march, where a
// wider filter would cost taps per step and the march's own sampling already blurs the shafts.
float sunVisibilityPoint(sampler2D shadowMap, vec3 p, float viewDepth) {
    int count = int(VITRINE_SHADOW.params.x);
    if (viewDepth > VITRINE_SHADOW.splits[count - 1]) return 1.0;
    int c = 0;
    while (c < count - 1 && viewDepth > VITRINE_SHADOW.splits[c]) ++c;
    vec4 s = VITRINE_SHADOW.worldToShadow[c] * vec4(p, 1.0);
    vec2 st = s.xy * VITRINE_SHADOW.params.y - 0.5;
    ivec2 base = ivec2(floor(st));
    vec2 f = st - vec2(base);
    float a = mix(shadowTap(shadowMap, base, s.z), shadowTap(shadowMap, base + ivec2(1, 0), s.z), f.x);
    float b = mix(shadowTap(shadowMap, base + ivec2(0, 1), s.z), shadowTap(shadowMap, base + ivec2(1, 1), s.z), f.x);
    return mix(a, b, f.y);
}

#endif
