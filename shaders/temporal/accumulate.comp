#version 460
#extension GL_GOOGLE_include_directive : require
#include "temporal/accumulate.h"

// Temporal super-sampling of a noisy screen-space signal (MUSEUM_SPEC §5: SSR, fog, AO): the node's own last output is
// reprojected by the velocity buffer and blended with this frame's input as a running mean of at most `maxSamples`
// frames. The history's sample count n (the `samples` output) is cut where the history is not this surface:
//   - off screen, or last frame's view depth differs at every texel of the reprojected point's bilinear footprint
//     (disocclusion; texels of another surface are left out of the fetch): n = 0;
//   - the velocity differs from last frame's velocity there [Sousa13]: n x max(0, 1 - velocityWeight |dv|);
//   - the luminance differs from the history's: n x (1 - luminanceWeight |dL| / max(L, Lh, floor)).
// The input may be smaller than the velocity / depth buffers (half- or quarter-resolution SSR and fog): each input
// pixel reads the full-resolution texel under its centre, and velocities are scaled to input pixels.
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0) uniform sampler2D in_color;
layout(binding = 1) uniform sampler2D in_history;
layout(binding = 2) uniform sampler2D in_history_samples;
layout(binding = 3) uniform sampler2D in_velocity;
layout(binding = 4) uniform sampler2D in_history_velocity;
layout(binding = 5) uniform sampler2D in_depth;
layout(binding = 6) uniform sampler2D in_history_depth;
layout(binding = 7) writeonly uniform image2D out_color;
layout(binding = 8) writeonly uniform image2D out_samples;

ivec2 gSize;     // input (= output) pixels
ivec2 gFullSize; // velocity / depth pixels

float luminance(vec3 c) { return dot(c, vec3(0.2126, 0.7152, 0.0722)); }

// View depth of a G-buffer normal target (z); 0 where nothing was drawn, which counts as infinitely far.
float viewDepth(sampler2D tex, ivec2 q) {
    float d = texelFetch(tex, clamp(q, ivec2(0), gFullSize - 1), 0).z;
    return d > 0.0 ? d : 1e30;
}

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    gSize = imageSize(out_color);
    if (any(greaterThanEqual(p, gSize))) return;
    vec4 current = texelFetch(in_color, p, 0);
    bool hasVelocity = (pc.flags & TEMPORAL_VELOCITY) != 0u;
    gFullSize = hasVelocity ? textureSize(in_velocity, 0) : ((pc.flags & TEMPORAL_DEPTH) != 0u ? textureSize(in_depth, 0) : gSize);
    vec2 toFull = vec2(gFullSize) / vec2(gSize);
    ivec2 full = min(ivec2((vec2(p) + 0.5) * toFull), gFullSize - 1); // the full-resolution texel under p's centre

    vec2 velocity = hasVelocity ? texelFetch(in_velocity, full, 0).xy : vec2(0.0); // full-resolution pixels
    vec2 prevFull = vec2(full) + 0.5 - velocity;
    vec2 prevPos = (vec2(p) + 0.5) - velocity / toFull;
    bool valid = (pc.flags & TEMPORAL_HISTORY_VALID) != 0u && all(greaterThanEqual(prevPos, vec2(0.0))) &&
                 all(lessThanEqual(prevPos, vec2(gSize)));
    ivec2 prevTexel = clamp(ivec2(floor(prevFull)), ivec2(0), gFullSize - 1);
    bool hasDepth = (pc.flags & TEMPORAL_DEPTH) != 0u;
    float here = hasDepth ? viewDepth(in_depth, full) : 0.0;

    // The history: bilinear at the reprojected point, from texel fetches (the filter does not depend on the sampler).
    // With depth, taps whose last-frame depth (the G-buffer texel under the tap's centre) is another surface are left
    // out and the others renormalised; none left is a disocclusion. The sample count is the smallest of the taps that
    // weigh, so a restart nearby is not averaged away.
    vec4 history = vec4(0.0);
    float n = 0.0;
    if (valid) {
        vec2 s = prevPos - 0.5;
        ivec2 b = ivec2(floor(s));
        vec2 f = s - vec2(b);
        n = 1e30;
        float total = 0.0;
        for (int j = 0; j < 2; ++j)
            for (int i = 0; i < 2; ++i) {
                ivec2 q = clamp(b + ivec2(i, j), ivec2(0), gSize - 1);
                float w = (i == 0 ? 1.0 - f.x : f.x) * (j == 0 ? 1.0 - f.y : f.y);
                if (hasDepth) {
                    float before = viewDepth(in_history_depth, min(ivec2((vec2(q) + 0.5) * toFull), gFullSize - 1));
                    if (abs(before - here) > pc.depthTolerance * max(before, here)) w = 0.0;
                }
                history += w * texelFetch(in_history, q, 0);
                total += w;
                if (w > 1e-4) n = min(n, texelFetch(in_history_samples, q, 0).r);
            }
        valid = total > 1e-3;
        history = valid ? history / total : vec4(0.0);
        n = valid ? n : 0.0;
        n = clamp(n, 0.0, pc.maxSamples - 1.0);
        if ((pc.flags & TEMPORAL_VELOCITY_HISTORY) != 0u) {
            // Sousa13: a surface that moves differently than what was here last frame is not the history's surface.
            vec2 before = texelFetch(in_history_velocity, prevTexel, 0).xy;
            n *= clamp(1.0 - pc.velocityWeight * length(velocity - before), 0.0, 1.0);
        }
        float lc = luminance(current.rgb), lh = luminance(history.rgb);
        n *= clamp(1.0 - pc.luminanceWeight * abs(lc - lh) / max(max(lc, lh), pc.luminanceFloor), 0.0, 1.0);
    }
    // Running mean of the n history samples and this one.
    float w = n / (n + 1.0);
    imageStore(out_color, p, mix(current, history, w));
    imageStore(out_samples, p, vec4(n + 1.0, 0.0, 0.0, 1.0));
}
