#pragma once

#include <algorithm>

#include <glm/glm.hpp>

// CPU mirror of shaders/common/brdf.glsl (same names, same maths, same units and pi
// convention: see the top of that file). Used by tests and CPU references.
namespace vitrine::shading {

inline constexpr float kPi = 3.14159265358979323846f;
inline constexpr float kMinGgxAlpha = 0.002f;

float roughnessFromShininess(float shininess);
float ggxAlpha(float roughness);
float ggxD(float NoH, float alpha);
float smithGgxVisibility(float NoV, float NoL, float alpha);
glm::vec3 schlickFresnel(glm::vec3 f0, float VoH);
glm::vec3 schlickFresnelF90(glm::vec3 f0, float f90, float VoH);
inline float lambertDiffuse() {
    return 1.0f / kPi;
}
glm::vec3 specularF0(glm::vec3 baseColor, float metallic);
glm::vec3 diffuseAlbedo(glm::vec3 baseColor, float metallic);
// KHR_materials_specular (shaders/common/brdf.glsl): the dielectric's Fresnel (F0 rgb, F90 a) from f0Ior and the
// extension's colour (rgb) and strength (a), and its blend with the metal's.
glm::vec4 dielectricSpecular(float f0Ior, glm::vec4 specular);
glm::vec3 specularF0With(glm::vec3 baseColor, float metallic, float f0Ior, glm::vec4 dielectric);
float specularF90(float metallic, glm::vec4 dielectric);
// The GGX lobe's directional albedo for F = 1 (common/ggx_albedo.h's fit) and the multiple-scattering compensation
// 1 + F0 (1 - E) / E [Turquin19] (common/brdf.glsl). `multiscatter` below: the lobe times it (the shaders'
// VITRINE_MULTISCATTER; the nodes' `multiscatter` param).
float ggxAlbedo(float NoV, float alpha);
glm::vec3 ggxMultiscatter(glm::vec3 f0, float NoV, float alpha);
glm::vec3 brdfCosineF0F90(glm::vec3 n, glm::vec3 v, glm::vec3 l, glm::vec3 diffuseColor, glm::vec3 f0, float f90,
                          float roughness, bool multiscatter = false);
glm::vec3 brdfCosineSpecular(glm::vec3 n, glm::vec3 v, glm::vec3 l, glm::vec3 baseColor, float metallic,
                             float roughness, glm::vec4 dielectric, bool multiscatter = false);
glm::vec3 shadeDirectionalSpecular(glm::vec3 n, glm::vec3 v, glm::vec3 l, glm::vec3 baseColor, float metallic,
                                   float roughness, glm::vec4 dielectric, glm::vec3 intensity);
// KHR_materials_clearcoat (shaders/common/brdf.glsl): the coat's Schlick Fresnel (F0 0.04), its GGX lobe times the
// cosine about the coat normal nc (without the strength), the layering base (1 - c Fc(nc.v)) + c coat, and the
// coated brdfCosineSpecular (coat = strength, perceptual roughness).
inline constexpr float kClearcoatF0 = 0.04f;
float clearcoatFresnel(float VoH);
float clearcoatSpecularCosine(glm::vec3 nc, glm::vec3 v, glm::vec3 l, float roughness);
glm::vec3 clearcoatLayer(glm::vec3 base, float clearcoat, float NcoV, glm::vec3 coat);
glm::vec3 brdfCosineClearcoat(glm::vec3 n, glm::vec3 nc, glm::vec3 v, glm::vec3 l, glm::vec3 baseColor, float metallic,
                              float roughness, glm::vec4 dielectric, glm::vec2 coat, bool multiscatter = false);
// KHR_materials_sheen (shaders/common/brdf.glsl): the Charlie distribution and the spec's fitted Charlie visibility
// of alpha = sheenAlpha(r), the lobe times the cosine (colour included), its directional albedo E from
// common/sheen_albedo.h (tools/make_sheen_albedo.py), the base's scaling 1 - max(sc) E, the layering base * scaling +
// sheen, and brdfCosineClearcoat with a sheen (rgb colour, a roughness) between the base and the coat.
inline constexpr float kMinSheenAlpha = 0.01f;
float sheenAlpha(float roughness);
float sheenCharlieD(float NoH, float alpha);
float sheenLambda(float cosTheta, float alpha);
float sheenVisibility(float NoV, float NoL, float alpha);
glm::vec3 sheenCosine(glm::vec3 n, glm::vec3 v, glm::vec3 l, glm::vec3 sheenColor, float roughness);
float sheenAlbedo(float NoV, float roughness);
float sheenScaling(glm::vec3 sheenColor, float NoV, float roughness);
inline bool hasSheen(glm::vec4 sheen) {
    return std::max(std::max(sheen.r, sheen.g), sheen.b) > 0.0f;
}
glm::vec3 sheenLayer(glm::vec3 base, float scaling, glm::vec3 sheen);
glm::vec3 brdfCosineSheen(glm::vec3 n, glm::vec3 nc, glm::vec3 v, glm::vec3 l, glm::vec3 baseColor, float metallic,
                          float roughness, glm::vec4 dielectric, glm::vec2 coat, glm::vec4 sheen,
                          bool multiscatter = false);
// brdfCosine with the diffuse colour and F0 given apart (shaders/common/brdf.glsl).
glm::vec3 brdfCosineF0(glm::vec3 n, glm::vec3 v, glm::vec3 l, glm::vec3 diffuseColor, glm::vec3 f0, float roughness);
// shaders/common/thin_transmission.glsl: light from behind a thin transmissive surface through its specular BTDF
// (the GGX lobe of the light mirrored through the surface), without the tint; 0 for light on v's side.
glm::vec3 thinTransmissionCosine(glm::vec3 n, glm::vec3 v, glm::vec3 l, glm::vec3 f0, float f90, float roughness);
glm::vec3 brdfCosine(glm::vec3 n, glm::vec3 v, glm::vec3 l, glm::vec3 baseColor, float metallic, float roughness);
// intensity = E / pi, E the light's illuminance (lux) on a surface facing it.
glm::vec3 shadeDirectional(glm::vec3 n, glm::vec3 v, glm::vec3 l, glm::vec3 baseColor, float metallic, float roughness,
                           glm::vec3 intensity);
float toksvigRoughness(float roughness, float normalLength);
// The perceptual roughness at which a glossy lobe lit by a delta light spreads over `footprint` metres at a point
// `distance` away (path-space regularisation for the lightmap bake; brdf.glsl's regularizedRoughness). 0: unchanged.
float regularizedRoughness(float roughness, float footprint, float distance);

// Split-sum environment BRDF by Karis' analytic fit ("mobile" approximation), as inlined in
// shaders/lighting/deferred.comp: returns (a, b) with directional albedo ~= F0 a + b for the GGX
// lobe of perceptual roughness `roughness` seen at NoV. Used by the GPU lighting tests' references.
glm::vec2 envBrdfApprox(float NoV, float roughness);

} // namespace vitrine::shading
