#version 460
#extension GL_GOOGLE_include_directive : require
#include "post/grain.h"
#include "camera/exposure.glsl"

// Film grain in display-referred space: the display-linear colour is sRGB-encoded, a zero-mean Gaussian grain of
// standard deviation pc.sigma added (the same to all three channels) and the result decoded again.
// The grain is white Gaussian noise on a square lattice of spacing pc.size pixels (one N(0, 1) value per lattice
// point, hashed from its coordinates and the frame's seed), interpolated with the cubic B-spline and divided by
// the root of the sum of the squared weights, so every pixel's grain has unit variance; its autocorrelation at a
// lag of one lattice spacing is about 0.49 (the B-spline's autocorrelation, see the README).
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0) uniform sampler2D in_color;
layout(binding = 1) writeonly uniform image2D out_color;

uvec3 pcg3d(uvec3 v) {
    v = v * 1664525u + 1013904223u;
    v.x += v.y * v.z;
    v.y += v.z * v.x;
    v.z += v.x * v.y;
    v ^= v >> 16u;
    v.x += v.y * v.z;
    v.y += v.z * v.x;
    v.z += v.x * v.y;
    return v;
}

// N(0, 1) at a lattice point (Box-Muller of two hashed uniforms in (0, 1]).
float gaussianAt(ivec2 cell) {
    uvec3 h = pcg3d(uvec3(uint(cell.x), uint(cell.y), pc.seed));
    float u1 = (float(h.x >> 8u) + 1.0) / 16777216.0;
    float u2 = float(h.y >> 8u) / 16777216.0;
    return sqrt(-2.0 * log(u1)) * cos(6.28318530718 * u2);
}

// Cubic B-spline weight.
float bspline(float t) {
    t = abs(t);
    if (t < 1.0) return (4.0 - 6.0 * t * t + 3.0 * t * t * t) / 6.0;
    if (t < 2.0) {
        float u = 2.0 - t;
        return u * u * u / 6.0;
    }
    return 0.0;
}

float srgbEncode(float v) { return v <= 0.0031308 ? 12.92 * v : 1.055 * pow(v, 1.0 / 2.4) - 0.055; }
float srgbDecode(float v) { return v <= 0.04045 ? v / 12.92 : pow((v + 0.055) / 1.055, 2.4); }

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    if (any(greaterThanEqual(p, imageSize(out_color)))) return;
    vec4 c = texelFetch(in_color, p, 0);

    float sigma = pc.sigma, size = pc.size;
#ifdef CAMERA_EXPOSURE
    // The camera's ISO, on the GPU: pc.sigma and pc.size are the grain's at ISO 100 then.
    float isoScale = cameraExposure.iso / 100.0;
    sigma *= sqrt(isoScale);
    size = max(0.5, size * pow(isoScale, 0.25));
#endif
    vec2 q = (vec2(p) + 0.5) / size;
    ivec2 base = ivec2(floor(q)) - 1;
    float wx[4], wy[4];
    float sx = 0.0, sy = 0.0;
    for (int k = 0; k < 4; ++k) {
        wx[k] = bspline(q.x - float(base.x + k));
        wy[k] = bspline(q.y - float(base.y + k));
        sx += wx[k] * wx[k];
        sy += wy[k] * wy[k];
    }
    float g = 0.0;
    for (int j = 0; j < 4; ++j)
        for (int i = 0; i < 4; ++i) g += wx[i] * wy[j] * gaussianAt(base + ivec2(i, j));
    g /= sqrt(sx * sy);

    vec3 rgb;
    for (int k = 0; k < 3; ++k) rgb[k] = srgbDecode(max(srgbEncode(max(c[k], 0.0)) + sigma * g, 0.0));
    imageStore(out_color, p, vec4(rgb, c.a));
}
