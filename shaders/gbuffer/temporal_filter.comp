#version 460
#extension GL_GOOGLE_include_directive : require
#include "gbuffer/temporal_filter.h"
#include "common/brdf.glsl"
#include "common/octahedral.glsl"

// Temporal G-buffer filtering (MUSEUM_SPEC §5): the world-space normal is blended over time with its history,
// reprojected by the velocity buffer, WITHOUT renormalising, and shininess is reduced Toksvig-style from the blended
// normal's length, as the G-buffer does for normal-map mips (common/brdf.glsl's toksvigRoughness): where the normal
// a pixel sees changes from frame to frame (thin railings, fine normal maps, sub-pixel jitter) the average is
// shorter and the highlight wider and steadier. The history keeps the unnormalised average and the view depth;
// history texels of another surface (view depth beyond the tolerance) are left out of its bilinear fetch.
// Output: the G-buffer normal target's layout (octahedral normal of the average, view depth, shininess), for
// lighting.deferred in place of gbuffer.normal. Shininess never increases.
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0) uniform sampler2D in_normal;
layout(binding = 1) uniform sampler2D in_velocity;
layout(binding = 2) uniform sampler2D in_history;
layout(binding = 3) writeonly uniform image2D out_normal;
layout(binding = 4) writeonly uniform image2D out_history;

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = imageSize(out_normal);
    if (any(greaterThanEqual(p, size))) return;
    vec4 g = texelFetch(in_normal, p, 0);
    if (g.z <= 0.0) {
        imageStore(out_normal, p, g); // nothing drawn
        imageStore(out_history, p, vec4(0.0));
        return;
    }
    vec3 n = octDecode(g.xy);
    float depth = g.z;

    vec2 velocity = (pc.flags & GBUFFER_FILTER_VELOCITY) != 0u ? texelFetch(in_velocity, p, 0).xy : vec2(0.0);
    vec2 prevPos = vec2(p) + 0.5 - velocity;
    vec3 history = vec3(0.0);
    float historyWeight = 0.0;
    if ((pc.flags & GBUFFER_FILTER_HISTORY_VALID) != 0u && all(greaterThanEqual(prevPos, vec2(0.0))) &&
        all(lessThanEqual(prevPos, vec2(size)))) {
        vec2 s = prevPos - 0.5;
        ivec2 b = ivec2(floor(s));
        vec2 f = s - vec2(b);
        for (int j = 0; j < 2; ++j)
            for (int i = 0; i < 2; ++i) {
                vec4 h = texelFetch(in_history, clamp(b + ivec2(i, j), ivec2(0), size - 1), 0);
                float w = (i == 0 ? 1.0 - f.x : f.x) * (j == 0 ? 1.0 - f.y : f.y);
                if (h.w > 0.0 && abs(h.w - depth) <= pc.depthTolerance * max(h.w, depth)) {
                    history += w * h.xyz;
                    historyWeight += w;
                }
            }
    }
    // The same surface's texels of the footprint, renormalised by their bilinear weights (not the vector).
    vec3 average = historyWeight > 1e-3 ? mix(n, history / historyWeight, pc.feedback) : n;
    float len = length(average);
    float shininess = g.w;
    float filtered = 1.0 - toksvigRoughness(roughnessFromShininess(shininess), min(len, 1.0));
    imageStore(out_normal, p, vec4(octEncode(len > 1e-6 ? average : n), depth, min(shininess, filtered)));
    imageStore(out_history, p, vec4(average, depth));
}
