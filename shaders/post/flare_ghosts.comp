#version 460
#extension GL_GOOGLE_include_directive : require
#include "post/flare.h"

// post.flare pass 2, at the bright pass's resolution: ghosts and a ring ghost (Chapman's screen-space "pseudo lens
// flare", re-derived so each term's position and energy are known):
//   - ghost i (scale s_i, tint t_i): the bright image scaled by s_i about the centre (s < 0 mirrors it through the
//     centre), divided by s_i^2 so that its energy is ghostIntensity x t_i x the source's, whatever its size;
//   - the ring ghost: the bright image mirrored through the centre and spread evenly over a circle of radius
//     haloRadius (haloTaps translated copies, energy haloIntensity x the source's).
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0, rgba16f) uniform image2D out_bright;
layout(binding = 1, rgba16f) uniform image2D out_flare;

#define BILINEAR_SOURCE out_bright
#include "post/load_bilinear.glsl"

const float kTau = 6.28318530717959;
// Ghost tints: coatings reflect some wavelengths more than others.
const vec3 kTints[8] = vec3[](vec3(1.0, 0.75, 0.5), vec3(0.5, 0.8, 1.0), vec3(0.6, 1.0, 0.6), vec3(1.0, 0.6, 0.9),
                              vec3(0.9, 0.9, 0.6), vec3(0.55, 0.65, 1.0), vec3(1.0, 0.85, 0.7), vec3(0.7, 1.0, 0.9));

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(p, imageSize(out_flare)))) return;
    vec2 d = vec2(p) + 0.5 - pc.centre;
    vec3 sum = vec3(0.0);
    for (int i = 0; i < 8; ++i) {
        float s = i < 4 ? pc.scalesA[i] : pc.scalesB[i - 4];
        if (s == 0.0) continue;
        sum += pc.ghostIntensity * kTints[i] * loadBilinear(pc.centre + d / s) / (s * s);
    }
    if (pc.haloIntensity > 0.0 && pc.haloTaps > 0u) {
        float radius = pc.haloRadius * pc.halfDiagonal;
        vec3 ring = vec3(0.0);
        for (uint k = 0u; k < pc.haloTaps; ++k) {
            float a = kTau * (float(k) + 0.5) / float(pc.haloTaps);
            ring += loadBilinear(pc.centre - d + radius * vec2(cos(a), sin(a)));
        }
        sum += pc.haloIntensity * ring / float(pc.haloTaps);
    }
    imageStore(out_flare, p, vec4(sum, 1.0));
}
