#version 460
#extension GL_GOOGLE_include_directive : require
#include "pattern/checker.h"

// A rotated checkerboard: long straight edges at an angle, the classic FXAA/TAA edge test.
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0) writeonly uniform image2D out_color;

vec4 checker(vec2 x, vec2 centre) {
    float c = cos(ck.angle), s = sin(ck.angle);
    vec2 d = x - centre;
    vec2 q = vec2(c * d.x + s * d.y, -s * d.x + c * d.y) / ck.cellSize;
    bool odd = ((int(floor(q.x)) + int(floor(q.y))) & 1) != 0;
    return odd ? ck.colorB : ck.colorA;
}

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = imageSize(out_color);
    if (any(greaterThanEqual(p, size))) return;
    vec2 centre = vec2(size) * 0.5;
    uint n = max(ck.supersample, 1u);
    vec4 sum = vec4(0.0);
    for (uint j = 0u; j < n; ++j)
        for (uint i = 0u; i < n; ++i)
            sum += checker(vec2(p) + (vec2(i, j) + 0.5) / float(n), centre);
    imageStore(out_color, p, sum / float(n * n));
}
