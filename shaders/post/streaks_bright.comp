#version 460
#extension GL_GOOGLE_include_directive : require
#include "post/streaks.h"
#include "post/bright_pass.glsl"

// post.streaks pass 1: the bright pass, downsampled by `factor`.
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0) uniform sampler2D in_color;
layout(binding = 1, rgba16f) uniform image2D out_bright;

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(p, imageSize(out_bright)))) return;
    imageStore(out_bright, p, vec4(brightPass(in_color, p, pc.factor, brightPassExposure(pc.exposure), pc.threshold), 1.0));
}
