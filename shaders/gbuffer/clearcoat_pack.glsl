// KHR_materials_clearcoat in the G-buffer. No channel is free, so the coat's strength c and roughness r ride in the
// emissive target's alpha (R16G16B16A16_SFLOAT) next to the lightmapped flag, quantised to 5 bits each:
//     a = lightmapped + 2 (32 q(c) + q(r)),  q(x) = floor(31 x + 0.5)  (GLSL's round() may go either way at .5)
// an integer of at most 2047, exact in fp16 (every integer up to 2048 is). Without a coat a is the flag, 0 or 1, as
// before. gbuffer.layered writes it, lighting.deferred reads it. The coat's own normal has no room: the deferred
// coat takes the G-buffer's (base) normal.
#ifndef GBUFFER_CLEARCOAT_PACK_GLSL
#define GBUFFER_CLEARCOAT_PACK_GLSL

float packClearcoatAlpha(bool lightmapped, vec2 coat) {
    vec2 q = floor(clamp(coat, 0.0, 1.0) * 31.0 + 0.5);
    return (lightmapped ? 1.0 : 0.0) + 2.0 * (32.0 * q.x + q.y);
}

// Returns (c, r); `lightmapped` the flag.
vec2 unpackClearcoatAlpha(float a, out bool lightmapped) {
    float code = floor(a * 0.5);
    lightmapped = a - 2.0 * code > 0.5;
    float qc = floor(code / 32.0);
    return vec2(qc, code - 32.0 * qc) / 31.0;
}

#endif
