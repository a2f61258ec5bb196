#version 460
#extension GL_GOOGLE_include_directive : require
#include "aa/accumulate.h"

// The running mean of the first `samples` frames: with a stratified N x N jitter of a static camera, exactly the
// box-filtered N x N supersampled image, at any resolution and with no larger target.
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0) uniform sampler2D in_color;
layout(binding = 1) uniform sampler2D in_history;
layout(binding = 2) writeonly uniform image2D out_color;

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(p, imageSize(out_color)))) return;
    vec4 c = texelFetch(in_color, p, 0);
    vec4 mean = c;
    if (pc.index >= pc.samples) {
        mean = texelFetch(in_history, p, 0);
    } else if (pc.index > 0u) {
        vec4 h = texelFetch(in_history, p, 0);
        mean = h + (c - h) / float(pc.index + 1u);
    }
    imageStore(out_color, p, mean);
}
