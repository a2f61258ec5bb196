// KHR_materials_transmission's specular BTDF for thin walls, shared by forward.transparent and render.pathtrace
// (core/shading/brdf.cpp thinTransmissionCosine is its CPU twin): light from behind a surface, scattered towards v
// by its rough surface, is the GGX lobe of the light mirrored through the surface to the viewer's side
// (lm = l - 2 (n.l) n): (1 - F(v.h)) D(n.h) Vis(n.v, n.lm), times the cosine n.lm as a reflected light's n.l.
// 0 for light on the viewer's side. Without the tint (transmission x base colour x the volume's attenuation).
#ifndef COMMON_THIN_TRANSMISSION_GLSL
#define COMMON_THIN_TRANSMISSION_GLSL
#include "common/brdf.glsl"

vec3 thinTransmissionCosine(vec3 n, vec3 v, vec3 l, vec3 f0, float f90, float roughness) {
    float NoL = -dot(n, l), NoV = dot(n, v);
    if (NoL <= 0.0 || NoV <= 0.0) return vec3(0.0);
    vec3 lm = l + 2.0 * NoL * n;
    vec3 h = normalize(v + lm);
    float alpha = ggxAlpha(roughness);
    float NoH = clamp(dot(n, h), 0.0, 1.0), VoH = clamp(dot(v, h), 0.0, 1.0);
    return (vec3(1.0) - schlickFresnelF90(f0, f90, VoH)) * ggxD(NoH, alpha) * smithGgxVisibility(NoV, NoL, alpha) * NoL;
}

#endif
