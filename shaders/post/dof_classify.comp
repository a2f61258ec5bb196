#version 460
#extension GL_GOOGLE_include_directive : require
#include "post/dof.h"
#include "post/dof_layers.glsl"

// post.dof pass 2: scatter or gather. A pixel that stands out of its neighbourhood (a bright point or the bright
// side of a high-contrast edge: luminance above scatterRatio times the mean of its 8 neighbours) and is out of
// focus (|CoC| >= scatterMinCoc) hands its excess over that mean to a sprite (position, CoC, colour) of the scatter
// list, as long as the list has room; what stays (the neighbours' mean, or the whole colour) is gathered. Every
// pixel also marks its layer in its 16x16 tile's mask, so the gather visits only the layers present near it.
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0) uniform sampler2D in_color;
layout(binding = 1, r32f) readonly uniform image2D out_coc;
layout(binding = 2, rgba32f) writeonly uniform image2D out_prepared;
layout(binding = 3, r32ui) uniform uimage2D out_tiles;
layout(binding = 4, r32ui) uniform uimage2D out_sprite_count;
layout(binding = 5, rgba32f) writeonly uniform image2D out_sprites;

float luminance(vec3 c) { return dot(c, vec3(0.2126, 0.7152, 0.0722)); }

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = imageSize(out_prepared);
    if (any(greaterThanEqual(p, size))) return;
    float coc = imageLoad(out_coc, p).r;
    float span = layerSpan(imageLoad(out_sprite_count, ivec2(1, 0)).r);
    imageAtomicOr(out_tiles, p / DOF_TILE, 1u << layerOf(coc, span));

    vec3 c = max(texelFetch(in_color, p, 0).rgb, vec3(0.0));
    vec3 keep = c;
    if (abs(coc) >= pc.scatterMinCoc && pc.maxSprites > 0u) {
        vec3 mean = vec3(0.0);
        for (int i = 0; i < 9; ++i) {
            if (i == 4) continue;
            ivec2 q = clamp(p + ivec2(i % 3 - 1, i / 3 - 1), ivec2(0), size - 1);
            mean += max(texelFetch(in_color, q, 0).rgb, vec3(0.0));
        }
        mean *= 1.0 / 8.0;
        float l = luminance(c);
        if (l > 0.0 && l > pc.scatterRatio * luminance(mean)) {
            uint index = imageAtomicAdd(out_sprite_count, ivec2(0), 1u);
            if (index < pc.maxSprites) {
                keep = min(c, mean);
                imageStore(out_sprites, ivec2(2 * index, 0), vec4(vec2(p) + 0.5, coc, 0.0));
                imageStore(out_sprites, ivec2(2 * index + 1, 0), vec4(c - keep, 0.0));
            }
        }
    }
    // The pixel's layer beside the colour: the gather's taps read one texel and compare its layer.
    imageStore(out_prepared, p, vec4(keep, float(layerOf(coc, span))));
}
