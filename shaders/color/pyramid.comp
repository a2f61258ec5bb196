#version 460
#extension GL_GOOGLE_include_directive : require
#include "depth/hiz.h"
#include "common/mip_atlas.glsl"

// Mip chain of a colour image for glossy lookups (ssr.hiz's cone tracing): each texel the mean of its
// footprint in the dispatch's source level (a box filter; odd sizes: the last row/column averages three).
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0) uniform sampler2D in_color;
layout(binding = 1) uniform sampler2D in_fallback;
layout(binding = 2, rgba16f) uniform image2D out_pyramid;

// pc.fallback: the history (color) is not written yet on the first frame; this frame's colour stands in.
vec4 sourceTexel(ivec2 p) {
    if (pc.source >= 0) return imageLoad(out_pyramid, mipOffset(pc.size, pc.source) + p);
    return pc.fallback != 0 ? texelFetch(in_fallback, p, 0) : texelFetch(in_color, p, 0);
}

void main() {
    ivec2 c = ivec2(gl_GlobalInvocationID.xy);
    int source = max(pc.source, 0);
    if (pc.source < 0) {
        // The first dispatch covers the atlas's width and defines its padding (see mipAtlasInLevel()): this texel
        // of the level-0 rows and the one at the same place in the strip of smaller levels below them.
        ivec2 atlas = imageSize(out_pyramid);
        ivec2 strip = ivec2(c.x, pc.size.y + c.y);
        if (all(lessThan(c, atlas)) && !mipAtlasInLevel(pc.size, c)) imageStore(out_pyramid, c, vec4(0.0));
        if (all(lessThan(strip, atlas)) && !mipAtlasInLevel(pc.size, strip)) imageStore(out_pyramid, strip, vec4(0.0));
    }
    for (int m = 0; m < pc.count; ++m) {
        int level = pc.first + m;
        if (any(greaterThanEqual(c, mipSize(pc.size, level)))) return;
        ivec2 lo, hi;
        mipFootprint(pc.size, source, level, c, lo, hi);
        vec4 sum = vec4(0.0);
        for (int y = lo.y; y <= hi.y; ++y)
            for (int x = lo.x; x <= hi.x; ++x) sum += sourceTexel(ivec2(x, y));
        vec2 n = vec2(hi - lo + 1);
        imageStore(out_pyramid, mipOffset(pc.size, level) + c, vec4(sum.rgb / (n.x * n.y), 1.0));
    }
}
