#version 460
#extension GL_GOOGLE_include_directive : require
#include "post/flare.h"

// post.flare pass 3: the colour plus the flare, upsampled bilinearly from the bright pass's resolution (energy is
// kept: a bright-pass texel stands for factor^2 pixels and holds their mean).
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0) uniform sampler2D in_color;
layout(binding = 1, rgba16f) uniform image2D out_flare;
layout(binding = 2) writeonly uniform image2D out_color;

#define BILINEAR_SOURCE out_flare
#include "post/load_bilinear.glsl"

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(p, imageSize(out_color)))) return;
    vec4 c = texelFetch(in_color, p, 0);
    vec3 flare = loadBilinear((vec2(p) + 0.5) / float(pc.factor));
    imageStore(out_color, p, vec4(c.rgb + flare, c.a));
}
