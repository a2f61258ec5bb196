#version 460
#extension GL_GOOGLE_include_directive : require
#include "aa/taa.h"
#include "common/color.glsl"

// Temporal anti-aliasing after Karis 2014 ("High quality temporal supersampling"): last frame's output is
// reprojected by the velocity buffer (Catmull-Rom fetch), rejected where depth says it is another surface or the
// pixel moved too far, clamped or variance-clipped to the current 3x3 neighbourhood in YCoCg, and blended with the
// current frame. Everything is blended in a tone-mapped space (Reinhard on the largest channel of
// common/color.glsl, exactly invertible) so one sample of brightness ~100 cannot dominate 10-20 dark ones, then
// returned to linear HDR. The alpha of the output counts the samples the history holds: the blend is their running
// mean until it reaches `feedback`.
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0) uniform sampler2D in_color;
layout(binding = 1) uniform sampler2D in_history;
layout(binding = 2) uniform sampler2D in_velocity;
layout(binding = 3) uniform sampler2D in_depth;
layout(binding = 4) uniform sampler2D in_history_depth;
layout(binding = 5) writeonly uniform image2D out_color;
layout(binding = 6) writeonly uniform image2D out_weight;

// Tone-mapped values stay below 1 so the inverse exists.
const float kMaxTonemapped = 0.9999;
const float kMaxCount = 4096.0;

ivec2 gSize;

vec3 toTonemapped(vec3 c) { return tonemapReinhardMax(max(c, vec3(0.0)) * pc.exposureScale); }
vec3 fromTonemapped(vec3 t) { return tonemapReinhardMaxInverse(clamp(t, vec3(0.0), vec3(kMaxTonemapped))) / pc.exposureScale; }

vec3 rgbToYCoCg(vec3 c) {
    return vec3(0.25 * c.r + 0.5 * c.g + 0.25 * c.b, 0.5 * c.r - 0.5 * c.b, -0.25 * c.r + 0.5 * c.g - 0.25 * c.b);
}
vec3 yCoCgToRgb(vec3 c) { return vec3(c.x + c.y - c.z, c.x + c.z, c.x - c.y - c.z); }

vec4 historyTexel(ivec2 q) { return texelFetch(in_history, clamp(q, ivec2(0), gSize - 1), 0); }

// History at `pos` (pixels, texel centres at i + 0.5), from texel fetches so the filter does not depend on the
// sampler: Catmull-Rom (16 taps, keeps the history sharp under sub-pixel motion) or bilinear (4 taps, blurs).
vec4 fetchHistory(vec2 pos) {
    vec2 s = pos - 0.5;
    ivec2 base = ivec2(floor(s));
    vec2 f = s - vec2(base);
    if (pc.historyFilter == TAA_FILTER_BILINEAR) {
        return mix(mix(historyTexel(base), historyTexel(base + ivec2(1, 0)), f.x),
                   mix(historyTexel(base + ivec2(0, 1)), historyTexel(base + ivec2(1, 1)), f.x), f.y);
    }
    vec2 w0 = f * (-0.5 + f * (1.0 - 0.5 * f));
    vec2 w1 = 1.0 + f * f * (-2.5 + 1.5 * f);
    vec2 w2 = f * (0.5 + f * (2.0 - 1.5 * f));
    vec2 w3 = f * f * (-0.5 + 0.5 * f);
    float wx[4] = float[](w0.x, w1.x, w2.x, w3.x);
    float wy[4] = float[](w0.y, w1.y, w2.y, w3.y);
    vec4 sum = vec4(0.0);
    for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 4; ++i) sum += wx[i] * wy[j] * historyTexel(base + ivec2(i - 1, j - 1));
    return sum;
}

// Clips c toward the centre of the box [lo, hi] (Karis 2014): keeps the hue of the history where a clamp per
// axis would not.
vec3 clipToBox(vec3 c, vec3 lo, vec3 hi) {
    vec3 centre = 0.5 * (hi + lo);
    vec3 extent = 0.5 * (hi - lo) + 1e-6;
    vec3 v = c - centre;
    vec3 units = abs(v / extent);
    float m = max(units.x, max(units.y, units.z));
    return m > 1.0 ? centre + v / m : c;
}

// View depth of the G-buffer's normal target (z); 0 where nothing was drawn, which counts as infinitely far.
float viewDepth(sampler2D tex, ivec2 q) {
    float d = texelFetch(tex, clamp(q, ivec2(0), gSize - 1), 0).z;
    return d > 0.0 ? d : 1e30;
}

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    gSize = imageSize(out_color);
    if (any(greaterThanEqual(p, gSize))) return;
    bool hasDepth = (pc.flags & TAA_DEPTH) != 0u;

    // The 3x3 neighbourhood of the current frame, tone-mapped: its moments and bounds in YCoCg, the cross for
    // sharpening, and the nearest surface (whose velocity the pixel takes, so edges of moving objects move).
    vec3 m1 = vec3(0.0), m2 = vec3(0.0), lo = vec3(1e30), hi = vec3(-1e30), cross4 = vec3(0.0), centre = vec3(0.0);
    float nearest = 1e31;
    ivec2 nearestAt = p;
    for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
            ivec2 q = clamp(p + ivec2(dx, dy), ivec2(0), gSize - 1);
            vec3 t = toTonemapped(texelFetch(in_color, q, 0).rgb);
            if (dx == 0 && dy == 0) centre = t;
            else if (dx == 0 || dy == 0) cross4 += t;
            vec3 y = rgbToYCoCg(t);
            m1 += y;
            m2 += y * y;
            lo = min(lo, y);
            hi = max(hi, y);
            if (hasDepth) {
                float d = viewDepth(in_depth, q);
                if (d < nearest) {
                    nearest = d;
                    nearestAt = q;
                }
            }
        }

    vec3 current = centre;
    if (pc.sharpen > 0.0) current = clamp(centre + pc.sharpen * (centre - 0.25 * cross4), vec3(0.0), vec3(kMaxTonemapped));

    vec2 velocity = (pc.flags & TAA_VELOCITY) != 0u ? texelFetch(in_velocity, nearestAt, 0).xy : vec2(0.0);
    vec2 prevPos = vec2(p) + 0.5 - velocity;
    bool valid = (pc.flags & TAA_HISTORY_VALID) != 0u && all(greaterThanEqual(prevPos, vec2(0.0))) &&
                 all(lessThanEqual(prevPos, vec2(gSize))) && length(velocity) <= pc.maxVelocity;
    if (valid && hasDepth) {
        // Same surface: this pixel's surface, or the nearest one whose velocity it took, was somewhere in the 3x3
        // around the reprojected point last frame (a window, because the sub-pixel jitter moves edges by up to a
        // pixel between frames). A disoccluded pixel's surfaces were hidden there.
        float here = viewDepth(in_depth, p);
        ivec2 b = ivec2(floor(prevPos));
        float closest = 1e31;
        for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
                float before = viewDepth(in_history_depth, b + ivec2(dx, dy));
                closest = min(closest, min(abs(before - here) / max(before, here),
                                           abs(before - nearest) / max(before, nearest)));
            }
        valid = closest <= pc.depthTolerance;
    }

    vec4 history = valid ? fetchHistory(prevPos) : vec4(0.0);
    float count = valid ? clamp(history.a, 0.0, kMaxCount) : 0.0;
    vec3 h = toTonemapped(history.rgb);
    if (pc.clampMode != TAA_CLAMP_NONE) {
        vec3 y = rgbToYCoCg(h);
        if (pc.clampMode == TAA_CLAMP_MINMAX) {
            y = clamp(y, lo, hi);
        } else {
            vec3 mean = m1 / 9.0;
            vec3 sigma = sqrt(max(m2 / 9.0 - mean * mean, vec3(0.0)));
            y = clipToBox(y, max(mean - pc.gamma * sigma, lo), min(mean + pc.gamma * sigma, hi));
        }
        h = yCoCgToRgb(y);
    }

    // Running mean of the samples until the history's weight reaches `feedback`.
    float w = min(pc.feedback, count / (count + 1.0));
    vec3 blended = mix(current, clamp(h, vec3(0.0), vec3(kMaxTonemapped)), w);
    imageStore(out_color, p, vec4(fromTonemapped(blended), min(count + 1.0, kMaxCount)));
    imageStore(out_weight, p, vec4(vec3(w), 1.0));
}
