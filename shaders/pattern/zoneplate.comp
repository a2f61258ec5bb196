#version 460
#extension GL_GOOGLE_include_directive : require
#include "pattern/zoneplate.h"

// Fresnel zone plate: phase pi * f * r^2 / R, so the local frequency grows linearly from 0 at
// the centre to maxFrequency cycles/pixel at the corners (radius R). Past 0.5 it aliases.
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0) writeonly uniform image2D out_color;

float plate(vec2 x, vec2 centre, float radius) {
    vec2 d = x - centre;
    float v = cos(3.14159265358979 * zp.maxFrequency * dot(d, d) / radius);
    return zp.mode == ZONEPLATE_BINARY ? step(0.0, v) : 0.5 + 0.5 * v;
}

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = imageSize(out_color);
    if (any(greaterThanEqual(p, size))) return;
    vec2 centre = vec2(size) * 0.5;
    float radius = length(centre);
    uint n = max(zp.supersample, 1u);
    float sum = 0.0;
    for (uint j = 0u; j < n; ++j)
        for (uint i = 0u; i < n; ++i)
            sum += plate(vec2(p) + (vec2(i, j) + 0.5) / float(n) + (zp.samplePos - 0.5), centre, radius);
    float v = sum / float(n * n);
    imageStore(out_color, p, vec4(v, v, v, 1.0));
}
