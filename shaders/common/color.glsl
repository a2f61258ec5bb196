#ifndef VITRINE_COLOR_GLSL
#define VITRINE_COLOR_GLSL

// Rec.709 / sRGB primaries, linear.
float luminance(vec3 c) { return dot(c, vec3(0.2126, 0.7152, 0.0722)); }

float max3(vec3 c) { return max(c.r, max(c.g, c.b)); }

// Reinhard on the largest channel: c / (1 + max(c)). Hue-preserving and exactly invertible,
// the curve temporal AA blends through so a pixel of brightness 100 cannot dominate.
vec3 tonemapReinhardMax(vec3 c) { return c / (1.0 + max3(c)); }
vec3 tonemapReinhardMaxInverse(vec3 c) { return c / max(1.0 - max3(c), 1e-6); }

vec3 tonemapReinhard(vec3 c) { return c / (1.0 + c); }
vec3 tonemapReinhardInverse(vec3 c) { return c / max(1.0 - c, vec3(1e-6)); }

// Narkowicz 2015 fit of the ACES RRT+ODT (sRGB, 1000 nits scaled to 1).
vec3 tonemapAcesFit(vec3 x) {
    const float a = 2.51, b = 0.03, c = 2.43, d = 0.59, e = 0.14;
    return clamp((x * (a * x + b)) / (x * (c * x + d) + e), 0.0, 1.0);
}

// Khronos PBR Neutral (KhronosGroup/ToneMapping, PBR_Neutral): colours whose largest channel stays below the
// compression start pass unchanged but for a small offset that takes away the 0.04 dielectric reflection a lit
// surface adds (a base colour rendered under unit white light comes out as itself); above it the largest channel is
// rolled off towards 1 with the hue kept, and the colour is pulled towards white in proportion to the compression.
const float kPbrNeutralStart = 0.8 - 0.04;     // compression starts here (after the offset)
const float kPbrNeutralDesaturation = 0.15;    // how fast compressed colours go to white
vec3 tonemapPbrNeutral(vec3 c) {
    float low = min(c.r, min(c.g, c.b));
    // The offset is 0.04 for lit surfaces, a quadratic toe (reaching 0 at black) below a channel of 0.08.
    float offset = low < 0.08 ? low - 6.25 * low * low : 0.04;
    c -= offset;
    float peak = max3(c);
    if (peak < kPbrNeutralStart) return c;
    float room = 1.0 - kPbrNeutralStart;
    float compressed = 1.0 - room * room / (peak + room - kPbrNeutralStart);
    c *= compressed / peak;
    float toWhite = 1.0 - 1.0 / (kPbrNeutralDesaturation * (peak - compressed) + 1.0);
    return mix(c, vec3(compressed), toWhite);
}

#endif
