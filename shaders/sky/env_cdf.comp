#version 460
#extension GL_GOOGLE_include_directive : require
#include "common/color.glsl"
#include "common/cubemap.glsl"

// sky.env_cdf: the table that importance-samples a sky cube map (shaders/pathtrace/sampling.glsl). A cube
// of N^2 texels per face has 6N rows (face f, texel row y: row f N + y). The output, (N + 1) x (6N + 1)
// R32F, holds:
//   (x, row), x < N:  the row's CDF over its texels, inclusive and normalised: sum_{x' <= x} w / sum_row w
//   (N, row):         the CDF over rows, inclusive and normalised
//   (0, 6N):          the total weight sum w (0 for a black sky)
// with w = luminance (cd/m^2) x the texel's exact solid angle. One workgroup: rows are shared out, then
// one invocation accumulates the rows' totals.
layout(local_size_x = 64) in;
layout(binding = 0) uniform samplerCube in_sky;
layout(binding = 1) writeonly uniform image2D out_cdf;

const int kMaxRows = 6 * 512;
shared float rowTotal[kMaxRows];

float texelWeight(int face, ivec2 t, int size) {
    vec3 c = textureLod(in_sky, cubeTexelDirection(uint(face), t, size), 0.0).rgb;
    return max(luminance(c), 0.0) * cubeTexelSolidAngle(t, size);
}

void main() {
    int size = textureSize(in_sky, 0).x;
    int rows = 6 * size;
    uint lane = gl_LocalInvocationID.x;
    for (int row = int(lane); row < rows; row += 64) {
        int face = row / size, y = row % size;
        float sum = 0.0;
        for (int x = 0; x < size; ++x) sum += texelWeight(face, ivec2(x, y), size);
        rowTotal[row] = sum;
        float acc = 0.0;
        for (int x = 0; x < size; ++x) {
            acc += texelWeight(face, ivec2(x, y), size);
            // A black row is never chosen; make its CDF uniform so it stays a valid table.
            imageStore(out_cdf, ivec2(x, row), vec4(sum > 0.0 ? acc / sum : float(x + 1) / float(size)));
        }
    }
    barrier();
    if (lane != 0u) return;
    float total = 0.0;
    for (int row = 0; row < rows; ++row) total += rowTotal[row];
    float acc = 0.0;
    for (int row = 0; row < rows; ++row) {
        acc += rowTotal[row];
        imageStore(out_cdf, ivec2(size, row), vec4(total > 0.0 ? acc / total : float(row + 1) / float(rows)));
    }
    for (int x = 0; x <= size; ++x) imageStore(out_cdf, ivec2(x, rows), vec4(x == 0 ? total : 0.0));
}
