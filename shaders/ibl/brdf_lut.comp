#version 460
#extension GL_GOOGLE_include_directive : require
#define IBL_BRDF_LUT_SHADER
#include "ibl/capture.h"
#include "ibl/ggx_sampling.glsl"
#include "pathtrace/sampling.glsl"

// The split-sum BRDF LUT [Karis13]: texel (i, j) is NoV = i / (size - 1), perceptual roughness
// j / (size - 1) (ibl_common.glsl's iblLutUv addresses texel centres), and holds (A, B) with
//   integral of f(l, v) (n.l) dl = f0 A + B
// for brdf.glsl's GGX D, height-correlated Smith visibility and Schlick Fresnel F = f0 + (1 - f0) Fc.
// Half vectors come from the distribution of normals visible from v [Heitz18]: the density of l is
// G1(v) D(h) / (4 (n.v)), so the estimator of f (n.l) / pdf(l) is F G2(v, l) / G1(v) = F Vis 4 (n.v)(n.l) / G1(v),
// bounded at grazing views where sampling D(h) (n.h) (Karis' recipe) leaves a spiky integrand.
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
    float a2 = alpha * alpha;
    float g1 = 2.0 * NoV / (NoV + sqrt(a2 + (1.0 - a2) * NoV * NoV));
    vec2 ab = vec2(0.0);
    for (uint i = 0u; i < lut.samples; ++i) {
        vec3 h = sampleGgxVndf(v, alpha, hammersley(i, lut.samples));
        float VoH = dot(v, h);
        vec3 l = 2.0 * VoH * h - v;
        float NoL = l.z;
        if (NoL <= 0.0 || VoH <= 0.0) continue;
        float w = smithGgxVisibility(NoV, NoL, alpha) * 4.0 * NoV * NoL / g1;
        float m = 1.0 - VoH;
        float fc = m * m * m * m * m;
        ab += vec2((1.0 - fc) * w, fc * w);
    }
    ab /= float(lut.samples);
    imageStore(out_brdf_lut, g, vec4(ab, 0.0, 0.0));
}
