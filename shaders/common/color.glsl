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

#endif
