#version 460
#extension GL_GOOGLE_include_directive : require
#include "post/airy.h"

// post.airy pass 2: the colour convolved with the per-channel Airy kernel, normalised by the kernel's sum so the
// image's energy is kept (the rings beyond the kernel radius are left out, their share spread over the rest).
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0) uniform sampler2D in_color;
layout(binding = 1, rgba32f) readonly uniform image2D out_psf;
layout(binding = 2) writeonly uniform image2D out_color;

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = imageSize(out_color);
    if (any(greaterThanEqual(p, size))) return;
    vec3 sum = vec3(0.0), weight = vec3(0.0);
    int radius = airyRadius();
    for (int y = -radius; y <= radius; ++y)
        for (int x = -radius; x <= radius; ++x) {
            vec3 k = imageLoad(out_psf, ivec2(x, y) + ivec2(pc.maxRadius)).rgb;
            // The kernel is the pattern a point spreads into: a pixel receives from p - offset.
            ivec2 q = clamp(p - ivec2(x, y), ivec2(0), size - 1);
            sum += k * max(texelFetch(in_color, q, 0).rgb, vec3(0.0));
            weight += k;
        }
    imageStore(out_color, p, vec4(sum / max(weight, vec3(1e-20)), texelFetch(in_color, p, 0).a));
}
