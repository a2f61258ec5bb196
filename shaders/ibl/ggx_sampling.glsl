// GGX importance sampling shared by the prefilter and the BRDF LUT [Karis13].
#ifndef IBL_GGX_SAMPLING_GLSL
#define IBL_GGX_SAMPLING_GLSL
#include "common/brdf.glsl"

// Point i of an n-point Hammersley set in [0, 1)^2.
vec2 hammersley(uint i, uint n) {
    uint b = bitfieldReverse(i);
    return vec2((float(i) + 0.5) / float(n), float(b) * 2.3283064365386963e-10);
}

// A half vector drawn with density D(h) (n.h) around n for GGX of width alpha.
vec3 importanceSampleGgx(vec2 xi, float alpha, vec3 n) {
    float a2 = alpha * alpha;
    float phi = 2.0 * kPi * xi.y;
    float cosTheta = sqrt((1.0 - xi.x) / (1.0 + (a2 - 1.0) * xi.x));
    float sinTheta = sqrt(max(1.0 - cosTheta * cosTheta, 0.0));
    vec3 h = vec3(sinTheta * cos(phi), sinTheta * sin(phi), cosTheta);
    vec3 up = abs(n.z) < 0.999 ? vec3(0.0, 0.0, 1.0) : vec3(1.0, 0.0, 0.0);
    vec3 tx = normalize(cross(up, n));
    vec3 ty = cross(n, tx);
    return tx * h.x + ty * h.y + n * h.z;
}

#endif
