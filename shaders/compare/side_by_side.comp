#version 460
#extension GL_GOOGLE_include_directive : require
#include "compare/side_by_side.h"

// a | b: the output is twice as wide as a; b fills the right half at a's size.
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0) uniform sampler2D in_a;
layout(binding = 1) uniform sampler2D in_b;
layout(binding = 2) writeonly uniform image2D out_color;

vec4 fetchRelative(sampler2D tex, ivec2 p, ivec2 size) {
    ivec2 texSize = textureSize(tex, 0);
    ivec2 q = texSize == size ? p : min(ivec2((vec2(p) + 0.5) * vec2(texSize) / vec2(size)), texSize - 1);
    return texelFetch(tex, q, 0);
}

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = imageSize(out_color);
    if (any(greaterThanEqual(p, size))) return;
    int halfW = size.x / 2;
    ivec2 halfSize = ivec2(halfW, size.y);
    vec4 c = p.x < halfW ? fetchRelative(in_a, p, halfSize) : fetchRelative(in_b, ivec2(p.x - halfW, p.y), halfSize);
    int w = int(pc.separatorWidth);
    if (w > 0 && p.x >= halfW - w && p.x < halfW + w) c.rgb = mix(c.rgb, pc.separatorColor.rgb, pc.separatorColor.a);
    imageStore(out_color, p, c);
}
