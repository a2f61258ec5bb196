#version 460
#extension GL_GOOGLE_include_directive : require
#include "post/airy.h"

// post.airy pass 1: the Airy pattern of a circular aperture, I(r) = (2 J1(x) / x)^2 with x = 3.8317 r / r0 (r0 the
// first dark ring, 1.22 lambda N on the sensor), integrated over each kernel pixel, for R, G and B; zero beyond
// the kernel radius. J1 by its Bessel integral J1(x) = 1/(2 pi) int_0^2pi cos(t - x sin t) dt with the trapezoid
// rule, which converges geometrically for this periodic integrand (48 points: < 1e-9 for x < 30).
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0, rgba32f) writeonly uniform image2D out_psf;

float besselJ1(float x) {
    const int n = 48;
    float sum = 0.0;
    for (int i = 0; i < n; ++i) {
        float t = 6.28318530718 * float(i) / float(n);
        sum += cos(t - x * sin(t));
    }
    return sum / float(n);
}

float airy(float r, float r0) {
    float x = AIRY_FIRST_ZERO * r / r0;
    if (x < 1e-4) return 1.0;
    float a = 2.0 * besselJ1(x) / x;
    return a * a;
}

void main() {
    ivec2 t = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = imageSize(out_psf);
    if (any(greaterThanEqual(t, size))) return;
    vec2 offset = vec2(t - ivec2(pc.maxRadius));
    vec3 value = vec3(0.0);
    vec3 firstZero = airyFirstZero();
    int radius = airyRadius();
    if (max(abs(offset.x), abs(offset.y)) <= float(radius)) {
        float n = float(pc.supersample);
        for (uint j = 0u; j < pc.supersample; ++j)
            for (uint i = 0u; i < pc.supersample; ++i) {
                float r = length(offset + (vec2(i, j) + 0.5) / n - 0.5);
                if (r > float(radius)) continue;
                value += vec3(airy(r, firstZero.r), airy(r, firstZero.g), airy(r, firstZero.b));
            }
        value /= n * n;
    }
    imageStore(out_psf, t, vec4(value, 1.0));
}
