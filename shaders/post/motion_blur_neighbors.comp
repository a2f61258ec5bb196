#version 460
#extension GL_GOOGLE_include_directive : require
// Pass 2 (McGuire12 NeighborMax): per tile, the largest tile-max of its 3 x 3 neighbourhood, so a pixel's gather
// reaches every blur that can cover it (half-lengths are clamped to one tile).
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0, rg16f) uniform image2D out_tile_max;
layout(binding = 1, rg16f) uniform image2D out_neighbor_max;

void main() {
    ivec2 t = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = imageSize(out_neighbor_max);
    if (any(greaterThanEqual(t, size))) return;
    vec2 best = vec2(0.0);
    float bestLen = 0.0;
    for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
            ivec2 q = t + ivec2(dx, dy);
            if (any(lessThan(q, ivec2(0))) || any(greaterThanEqual(q, size))) continue;
            vec2 v = imageLoad(out_tile_max, q).xy;
            float len = dot(v, v);
            if (len > bestLen) {
                bestLen = len;
                best = v;
            }
        }
    imageStore(out_neighbor_max, t, vec4(best, 0.0, 0.0));
}
