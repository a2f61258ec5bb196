#version 460
#extension GL_GOOGLE_include_directive : require
#include "compare/difference.h"
#include "common/magma.glsl"

// |a - b| * scale per channel, or its largest channel through the magma ramp.
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0) uniform sampler2D in_a;
layout(binding = 1) uniform sampler2D in_b;
layout(binding = 2) writeonly uniform image2D out_color;

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = imageSize(out_color);
    if (any(greaterThanEqual(p, size))) return;
    ivec2 sizeB = textureSize(in_b, 0);
    ivec2 q = sizeB == size ? p : min(ivec2((vec2(p) + 0.5) * vec2(sizeB) / vec2(size)), sizeB - 1);
    vec3 d = abs(texelFetch(in_a, p, 0).rgb - texelFetch(in_b, q, 0).rgb) * pc.scale;
    vec3 c = pc.falseColor != 0u ? magma(max(d.r, max(d.g, d.b))) : d;
    imageStore(out_color, p, vec4(c, 1.0));
}
