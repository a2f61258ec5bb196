#version 460
#extension GL_GOOGLE_include_directive : require
#define IBL_BRDF_LUT_SHADER
#include "ibl/capture.h"
#include "ibl/ggx_sampling.glsl"

// The split-sum BRDF LUT [Karis13]: texel (i, j) is NoV = i / (size - 1), perceptual roughness
// j / (size - 1) (ibl_common.glsl's iblLutUv addresses texel centres), and holds (A, B) with
//   integral of f(l, v) (n.l) dl = f0 A + B
// for brdf.glsl's GGX D, height-correlated Smith visibility and Schlick Fresnel F = f0 + (1 - f0) Fc:
// with h ~ D(h) (n.h), the estimator of f (n.l) / pdf(l) is Vis (n.l) 4 (v.h) / (n.h) times F.
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0, rg32f) uniform writeonly image2D out_brdf_lut;

void main() {
    ivec2 g = ivec2(gl_GlobalInvocationID.xy);
    int size = int(lut.size);
    if (g.x >= size || g.y >= size) return;
    float NoV = max(float(g.x) / float(size - 1), 1e-3);
    float roughness = float(g.y) / float(size - 1);
    float alpha = ggxAlpha(roughness);
    vec3 v = vec3(sqrt(1.0 - NoV * NoV), 0.0, NoV);
    vec3 n = vec3(0.0, 0.0, 1.0);
    vec2 ab = vec2(0.0);
    for (uint i = 0u; i < lut.samples; ++i) {
        vec3 h = importanceSampleGgx(hammersley(i, lut.samples), alpha, n);
        float VoH = dot(v, h);
        vec3 l = 2.0 * VoH * h - v;
        float NoL = l.z;
        float NoH = h.z;
        if (NoL <= 0.0 || VoH <= 0.0) continue;
        float w = smithGgxVisibility(NoV, NoL, alpha) * NoL * 4.0 * VoH / NoH;
        float m = 1.0 - VoH;
        float fc = m * m * m * m * m;
        ab += vec2((1.0 - fc) * w, fc * w);
    }
    ab /= float(lut.samples);
    imageStore(out_brdf_lut, g, vec4(ab, 0.0, 0.0));
}
