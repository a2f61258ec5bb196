#version 460
#extension GL_GOOGLE_include_directive : require
#include "post/streaks.h"
#include "camera/exposure.glsl"

// post.streaks pass 2, at the bright pass's resolution: `count` spikes per bright texel, evenly spaced in angle from
// `rotation`, each an exponential tail exp(-3 t / length) of whole-texel translated copies of the bright pass (so
// the energy is exact), normalised so that all spikes of a source together carry strength x its bright energy.
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0, rgba16f) uniform image2D out_bright;
layout(binding = 1, rgba16f) uniform image2D out_streaks;

const float kTau = 6.28318530717959;

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = imageSize(out_streaks);
    if (any(greaterThanEqual(p, size))) return;
    float spikeLength = pc.spikeLength, strength = pc.strength;
    uint samples = pc.samples;
#ifdef CAMERA_EXPOSURE
    // The camera's f-number, on the GPU: pc.spikeLength and pc.strength are per unit f-number then, and pc.samples
    // the cap. Wide open the blades are out of the light path (no spikes); straight edges by a stop down.
    float n = cameraExposure.fNumber;
    spikeLength *= n;
    strength *= n * clamp(cameraExposure.stopsDown, 0.0, 1.0);
    samples = uint(clamp(int(ceil(spikeLength)), 1, int(pc.samples)));
#endif
    vec3 sum = vec3(0.0);
    float norm = 0.0;
    for (uint j = 1u; j <= samples; ++j) norm += exp(-3.0 * float(j) / float(samples));
    for (uint k = 0u; k < pc.count; ++k) {
        float a = pc.rotation + kTau * float(k) / float(pc.count);
        vec2 dir = vec2(cos(a), sin(a));
        for (uint j = 1u; j <= samples; ++j) {
            float t = spikeLength * float(j) / float(samples);
            ivec2 q = p + ivec2(floor(0.5 - dir * t));
            if (any(lessThan(q, ivec2(0))) || any(greaterThanEqual(q, size))) continue;
            sum += exp(-3.0 * float(j) / float(samples)) * imageLoad(out_bright, q).rgb;
        }
    }
    float w = pc.count > 0u ? strength / (norm * float(pc.count)) : 0.0;
    imageStore(out_streaks, p, vec4(sum * w, 1.0));
}
