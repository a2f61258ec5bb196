#version 460
#extension GL_GOOGLE_include_directive : require
#include "depth/hiz.h"
#include "common/mip_atlas.glsl"

// Hi-Z pyramid of reverse-Z hardware depth [Uludag14]: per texel the minimum (farthest) and maximum (nearest)
// depth of its footprint. One dispatch writes a few levels, each texel reduced straight from the dispatch's
// source level over its whole footprint (odd sizes: the last row/column covers three texels below), so levels
// within a dispatch never read each other.
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0) uniform sampler2D in_depth;
layout(binding = 1, rg32f) uniform image2D out_hiz;

vec2 sourceTexel(ivec2 p) {
    if (pc.source < 0) return vec2(texelFetch(in_depth, p, 0).r);
    return imageLoad(out_hiz, mipOffset(pc.size, pc.source) + p).rg;
}

void main() {
    ivec2 c = ivec2(gl_GlobalInvocationID.xy);
    int source = max(pc.source, 0);
    if (pc.source < 0) {
        // The first dispatch covers the atlas's width and defines its padding (see mipAtlasInLevel()): this texel
        // of the level-0 rows and the one at the same place in the strip of smaller levels below them.
        ivec2 atlas = imageSize(out_hiz);
        ivec2 strip = ivec2(c.x, pc.size.y + c.y);
        if (all(lessThan(c, atlas)) && !mipAtlasInLevel(pc.size, c)) imageStore(out_hiz, c, vec4(0.0));
        if (all(lessThan(strip, atlas)) && !mipAtlasInLevel(pc.size, strip)) imageStore(out_hiz, strip, vec4(0.0));
    }
    for (int m = 0; m < pc.count; ++m) {
        int level = pc.first + m;
        if (any(greaterThanEqual(c, mipSize(pc.size, level)))) return;
        ivec2 lo, hi;
        mipFootprint(pc.size, source, level, c, lo, hi);
        vec2 range = vec2(1e30, -1e30);
        for (int y = lo.y; y <= hi.y; ++y)
            for (int x = lo.x; x <= hi.x; ++x) {
                vec2 d = sourceTexel(ivec2(x, y));
                range = vec2(min(range.x, d.x), max(range.y, d.y));
            }
        imageStore(out_hiz, mipOffset(pc.size, level) + c, vec4(range, 0.0, 0.0));
    }
}
