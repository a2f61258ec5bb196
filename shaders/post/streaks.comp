#version 460
#extension GL_GOOGLE_include_directive : require
#include "post/streaks.h"

// post.streaks pass 3: the colour plus the streaks, upsampled bilinearly from the bright pass's resolution.
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0) uniform sampler2D in_color;
layout(binding = 1, rgba16f) uniform image2D out_streaks;
layout(binding = 2) writeonly uniform image2D out_color;

#define BILINEAR_SOURCE out_streaks
#include "post/load_bilinear.glsl"

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(p, imageSize(out_color)))) return;
    vec4 c = texelFetch(in_color, p, 0);
    imageStore(out_color, p, vec4(c.rgb + loadBilinear((vec2(p) + 0.5) / float(pc.factor)), c.a));
}
