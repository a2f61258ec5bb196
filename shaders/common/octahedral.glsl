#ifndef VITRINE_OCTAHEDRAL_GLSL
#define VITRINE_OCTAHEDRAL_GLSL

// Octahedral unit-vector encoding [Meyer10]; CPU mirror: core/shading/octahedral.hpp.
// The G-buffer stores octEncode(n) in [-1, 1]^2 as-is in two RGBA16F channels.
// Round-trip error: < 1e-6 rad in fp32; < 1.1e-3 rad (0.063 deg) after rounding e to half.

vec2 octSignNotZero(vec2 v) { return vec2(v.x >= 0.0 ? 1.0 : -1.0, v.y >= 0.0 ? 1.0 : -1.0); }

vec2 octWrap(vec2 v) { return (1.0 - abs(v.yx)) * octSignNotZero(v); }

// n need not be normalised (it must not be zero).
vec2 octEncode(vec3 n) {
    n /= abs(n.x) + abs(n.y) + abs(n.z);
    return n.z >= 0.0 ? n.xy : octWrap(n.xy);
}

vec3 octDecode(vec2 e) {
    vec3 n = vec3(e, 1.0 - abs(e.x) - abs(e.y));
    if (n.z < 0.0) n.xy = octWrap(n.xy);
    return normalize(n);
}

#endif
