#version 460
#extension GL_GOOGLE_include_directive : require
#include "compare/split.h"

// A/B split view: a on one side of a line, b on the other, an optional line and "A"/"B" markers.
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0) uniform sampler2D in_a;
layout(binding = 1) uniform sampler2D in_b;
layout(binding = 2) writeonly uniform image2D out_color;

// 5x7 bitmap glyphs, one row per entry, bit 4 = leftmost column.
const uint kGlyphA[7] = uint[](0x0Eu, 0x11u, 0x11u, 0x1Fu, 0x11u, 0x11u, 0x11u);
const uint kGlyphB[7] = uint[](0x1Eu, 0x11u, 0x11u, 0x1Eu, 0x11u, 0x11u, 0x1Eu);

// The marker box is the glyph with one glyph pixel of border: 7 x 9 glyph pixels. Returns the colour of the box at
// `p` blended over `c`; pixels outside the box keep `c`.
vec4 marker(ivec2 p, ivec2 box, bool isA, vec4 c) {
    ivec2 g = (p - box) / int(pc.glyphScale);
    if (any(lessThan(p, box)) || g.x >= 7 || g.y >= 9) return c;
    ivec2 q = g - ivec2(1);
    bool on = false;
    if (q.x >= 0 && q.x < 5 && q.y >= 0 && q.y < 7) on = (((isA ? kGlyphA[q.y] : kGlyphB[q.y]) >> uint(4 - q.x)) & 1u) != 0u;
    return vec4(on ? vec3(1.0) : mix(c.rgb, vec3(0.0), 0.7), c.a);
}

// Nearest texel of `tex` at the same relative position as output pixel p (identity when sizes match).
vec4 fetchRelative(sampler2D tex, ivec2 p, ivec2 size) {
    ivec2 texSize = textureSize(tex, 0);
    ivec2 q = texSize == size ? p : min(ivec2((vec2(p) + 0.5) * vec2(texSize) / vec2(size)), texSize - 1);
    return texelFetch(tex, q, 0);
}

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = imageSize(out_color);
    if (any(greaterThanEqual(p, size))) return;
    float d = dot(vec2(p) + 0.5 - pc.origin, pc.normal);
    vec4 c = d < 0.0 ? fetchRelative(in_a, p, size) : fetchRelative(in_b, p, size);
    if (abs(d) < pc.halfWidth) c.rgb = mix(c.rgb, pc.lineColor.rgb, pc.lineColor.a);
    if (pc.labels != 0u) {
        c = marker(p, pc.labelA, true, c);
        c = marker(p, pc.labelB, false, c);
    }
    imageStore(out_color, p, c);
}
