#version 460
#extension GL_GOOGLE_include_directive : require
#include "post/motion_blur_common.glsl"

// Pass 1 (McGuire12 TileMax): per K x K tile, the half-velocity of largest magnitude.
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0) uniform sampler2D in_velocity;
layout(binding = 1, rg16f) uniform image2D out_tile_max;

void main() {
    ivec2 t = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(t, imageSize(out_tile_max)))) return;
    ivec2 size = textureSize(in_velocity, 0);
    ivec2 lo = t * pc.tileSize, hi = min(lo + pc.tileSize, size);
    vec2 best = vec2(0.0);
    float bestLen = 0.0;
    for (int y = lo.y; y < hi.y; ++y)
        for (int x = lo.x; x < hi.x; ++x) {
            vec2 v = halfVelocity(texelFetch(in_velocity, ivec2(x, y), 0).xy);
            float len = dot(v, v);
            if (len > bestLen) {
                bestLen = len;
                best = v;
            }
        }
    imageStore(out_tile_max, t, vec4(best, 0.0, 0.0));
}
