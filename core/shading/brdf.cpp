#include "core/shading/brdf.hpp"
#include "shaders/common/ggx_albedo.h"
#include "shaders/common/sheen_albedo.h"

#include <algorithm>
#include <cmath>

namespace vitrine::shading {

float roughnessFromShininess(float shininess) {
    return std::clamp(1.0f - shininess, 0.0f, 1.0f);
}

float ggxAlpha(float roughness) {
    return std::max(roughness * roughness, kMinGgxAlpha);
}

float ggxD(float NoH, float alpha) {
    float a2 = alpha * alpha;
    float d = NoH * NoH * (a2 - 1.0f) + 1.0f;
    return a2 / (kPi * d * d);
}

float smithGgxVisibility(float NoV, float NoL, float alpha) {
    float a2 = alpha * alpha;
    float lambdaV = NoL * std::sqrt(NoV * NoV * (1.0f - a2) + a2);
    float lambdaL = NoV * std::sqrt(NoL * NoL * (1.0f - a2) + a2);
    return 0.5f / std::max(lambdaV + lambdaL, 1e-12f);
}

glm::vec3 schlickFresnel(glm::vec3 f0, float VoH) {
    float m = 1.0f - std::clamp(VoH, 0.0f, 1.0f);
    float m5 = m * m * m * m * m;
    return f0 + (glm::vec3(1.0f) - f0) * m5;
}

// As brdf.glsl: the plain value minus (1 - f90) Fc, an exact 0 at f90 = 1.
glm::vec3 schlickFresnelF90(glm::vec3 f0, float f90, float VoH) {
    float m = 1.0f - std::clamp(VoH, 0.0f, 1.0f);
    float m5 = m * m * m * m * m;
    return schlickFresnel(f0, VoH) - (1.0f - f90) * m5;
}

glm::vec4 dielectricSpecular(float f0Ior, glm::vec4 specular) {
    return glm::vec4(specular.a * glm::min(f0Ior * glm::vec3(specular), glm::vec3(1.0f)), specular.a);
}

glm::vec3 specularF0With(glm::vec3 baseColor, float metallic, float f0Ior, glm::vec4 dielectric) {
    return glm::mix(glm::vec3(f0Ior), baseColor, metallic) -
           (1.0f - metallic) * (glm::vec3(f0Ior) - glm::vec3(dielectric));
}

float specularF90(float metallic, glm::vec4 dielectric) {
    return dielectric.a + (1.0f - dielectric.a) * metallic;
}

glm::vec3 specularF0(glm::vec3 baseColor, float metallic) {
    return glm::mix(glm::vec3(0.04f), baseColor, metallic);
}

glm::vec3 diffuseAlbedo(glm::vec3 baseColor, float metallic) {
    return baseColor * (1.0f - metallic);
}

float ggxAlbedo(float NoV, float alpha) {
    float x = 2.0f * (std::sqrt(std::clamp(NoV, 0.01f, 1.0f)) - 0.1f) / 0.9f - 1.0f;
    float y = 2.0f * std::clamp(std::sqrt(alpha), std::sqrt(kMinGgxAlpha), 1.0f) - 1.0f;
    return std::clamp(VITRINE_GGX_ALBEDO(x, y), 0.05f, 1.0f);
}

glm::vec3 ggxMultiscatter(glm::vec3 f0, float NoV, float alpha) {
    float e = ggxAlbedo(NoV, alpha);
    return glm::vec3(1.0f) + f0 * ((1.0f - e) / e);
}

glm::vec3 brdfCosineF0F90(glm::vec3 n, glm::vec3 v, glm::vec3 l, glm::vec3 diffuseColor, glm::vec3 f0, float f90,
                          float roughness, bool multiscatter) {
    float NoL = glm::dot(n, l), NoV = glm::dot(n, v);
    if (NoL <= 0.0f || NoV <= 0.0f) return glm::vec3(0.0f);
    glm::vec3 h = glm::normalize(v + l);
    float NoH = std::clamp(glm::dot(n, h), 0.0f, 1.0f);
    float VoH = std::clamp(glm::dot(v, h), 0.0f, 1.0f);
    float alpha = ggxAlpha(roughness);
    glm::vec3 spec = ggxD(NoH, alpha) * smithGgxVisibility(NoV, NoL, alpha) * schlickFresnelF90(f0, f90, VoH);
    if (multiscatter) spec *= ggxMultiscatter(f0, NoV, alpha);
    return (diffuseColor * lambertDiffuse() + spec) * NoL;
}

glm::vec3 brdfCosineF0(glm::vec3 n, glm::vec3 v, glm::vec3 l, glm::vec3 diffuseColor, glm::vec3 f0, float roughness) {
    float NoL = glm::dot(n, l), NoV = glm::dot(n, v);
    if (NoL <= 0.0f || NoV <= 0.0f) return glm::vec3(0.0f);
    glm::vec3 h = glm::normalize(v + l);
    float NoH = std::clamp(glm::dot(n, h), 0.0f, 1.0f);
    float VoH = std::clamp(glm::dot(v, h), 0.0f, 1.0f);
    float alpha = ggxAlpha(roughness);
    glm::vec3 spec = ggxD(NoH, alpha) * smithGgxVisibility(NoV, NoL, alpha) * schlickFresnel(f0, VoH);
    return (diffuseColor * lambertDiffuse() + spec) * NoL;
}

glm::vec3 brdfCosineSpecular(glm::vec3 n, glm::vec3 v, glm::vec3 l, glm::vec3 baseColor, float metallic,
                             float roughness, glm::vec4 dielectric, bool multiscatter) {
    return brdfCosineF0F90(n, v, l, diffuseAlbedo(baseColor, metallic),
                           specularF0With(baseColor, metallic, 0.04f, dielectric), specularF90(metallic, dielectric),
                           roughness, multiscatter);
}

glm::vec3 brdfCosine(glm::vec3 n, glm::vec3 v, glm::vec3 l, glm::vec3 baseColor, float metallic, float roughness) {
    return brdfCosineF0(n, v, l, diffuseAlbedo(baseColor, metallic), specularF0(baseColor, metallic), roughness);
}

glm::vec3 shadeDirectional(glm::vec3 n, glm::vec3 v, glm::vec3 l, glm::vec3 baseColor, float metallic, float roughness,
                           glm::vec3 intensity) {
    return brdfCosine(n, v, l, baseColor, metallic, roughness) * (kPi * intensity);
}

float clearcoatFresnel(float VoH) {
    float m = 1.0f - std::clamp(VoH, 0.0f, 1.0f);
    float m2 = m * m;
    return kClearcoatF0 + (1.0f - kClearcoatF0) * (m2 * m2 * m);
}

float clearcoatSpecularCosine(glm::vec3 nc, glm::vec3 v, glm::vec3 l, float roughness) {
    float NoL = glm::dot(nc, l), NoV = glm::dot(nc, v);
    if (NoL <= 0.0f || NoV <= 0.0f) return 0.0f;
    glm::vec3 h = glm::normalize(v + l);
    float NoH = std::clamp(glm::dot(nc, h), 0.0f, 1.0f);
    float VoH = std::clamp(glm::dot(v, h), 0.0f, 1.0f);
    float alpha = ggxAlpha(roughness);
    return ggxD(NoH, alpha) * smithGgxVisibility(NoV, NoL, alpha) * clearcoatFresnel(VoH) * NoL;
}

glm::vec3 clearcoatLayer(glm::vec3 base, float clearcoat, float NcoV, glm::vec3 coat) {
    return base * (1.0f - clearcoat * clearcoatFresnel(NcoV)) + clearcoat * coat;
}

glm::vec3 brdfCosineClearcoat(glm::vec3 n, glm::vec3 nc, glm::vec3 v, glm::vec3 l, glm::vec3 baseColor, float metallic,
                              float roughness, glm::vec4 dielectric, glm::vec2 coat, bool multiscatter) {
    glm::vec3 base = brdfCosineSpecular(n, v, l, baseColor, metallic, roughness, dielectric, multiscatter);
    return clearcoatLayer(base, coat.x, glm::dot(nc, v), glm::vec3(clearcoatSpecularCosine(nc, v, l, coat.y)));
}

float sheenAlpha(float roughness) {
    return std::max(roughness * roughness, kMinSheenAlpha);
}

float sheenCharlieD(float NoH, float alpha) {
    float invAlpha = 1.0f / alpha;
    float sin2 = std::max(1.0f - NoH * NoH, 0.0f);
    return (2.0f + invAlpha) * std::pow(sin2, 0.5f * invAlpha) / (2.0f * kPi);
}

namespace {
float mixf(float a, float b, float t) {
    return a * (1.0f - t) + b * t;
}
float sheenLambdaL(float x, float alpha) {
    float t = (1.0f - alpha) * (1.0f - alpha);
    float a = mixf(21.5473f, 25.3245f, t);
    float b = mixf(3.82987f, 3.32435f, t);
    float c = mixf(0.19823f, 0.16801f, t);
    float d = mixf(-1.97760f, -1.27393f, t);
    float e = mixf(-4.32054f, -4.85967f, t);
    return a / (1.0f + b * std::pow(x, c)) + d * x + e;
}
} // namespace

float sheenLambda(float cosTheta, float alpha) {
    return cosTheta < 0.5f ? std::exp(sheenLambdaL(cosTheta, alpha))
                           : std::exp(2.0f * sheenLambdaL(0.5f, alpha) - sheenLambdaL(1.0f - cosTheta, alpha));
}

float sheenVisibility(float NoV, float NoL, float alpha) {
    return 1.0f / ((1.0f + sheenLambda(NoV, alpha) + sheenLambda(NoL, alpha)) * 4.0f * NoV * NoL);
}

glm::vec3 sheenCosine(glm::vec3 n, glm::vec3 v, glm::vec3 l, glm::vec3 sheenColor, float roughness) {
    float NoL = glm::dot(n, l), NoV = glm::dot(n, v);
    if (NoL <= 0.0f || NoV <= 0.0f) return glm::vec3(0.0f);
    float NoH = std::clamp(glm::dot(n, glm::normalize(v + l)), 0.0f, 1.0f);
    float alpha = sheenAlpha(roughness);
    return sheenColor * (sheenCharlieD(NoH, alpha) * sheenVisibility(NoV, NoL, alpha) * NoL);
}

float sheenAlbedo(float NoV, float roughness) {
    float x = 2.0f * std::sqrt(std::clamp(NoV, 0.0f, 1.0f)) - 1.0f;
    float y = 2.0f * std::clamp(roughness, 0.1f, 1.0f) - 1.0f;
    return std::exp(VITRINE_SHEEN_ALBEDO_LOG(x, y));
}

float sheenScaling(glm::vec3 sheenColor, float NoV, float roughness) {
    float m = std::max(std::max(sheenColor.r, sheenColor.g), sheenColor.b);
    return std::max(1.0f - m * sheenAlbedo(NoV, roughness), 0.0f);
}

glm::vec3 sheenLayer(glm::vec3 base, float scaling, glm::vec3 sheen) {
    return base * scaling + sheen;
}

glm::vec3 brdfCosineSheen(glm::vec3 n, glm::vec3 nc, glm::vec3 v, glm::vec3 l, glm::vec3 baseColor, float metallic,
                          float roughness, glm::vec4 dielectric, glm::vec2 coat, glm::vec4 sheen, bool multiscatter) {
    glm::vec3 base = brdfCosineSpecular(n, v, l, baseColor, metallic, roughness, dielectric, multiscatter);
    if (hasSheen(sheen)) {
        glm::vec3 c(sheen);
        base = sheenLayer(base, sheenScaling(c, glm::dot(n, v), sheen.a), sheenCosine(n, v, l, c, sheen.a));
    }
    return clearcoatLayer(base, coat.x, glm::dot(nc, v), glm::vec3(clearcoatSpecularCosine(nc, v, l, coat.y)));
}

glm::vec3 shadeDirectionalSpecular(glm::vec3 n, glm::vec3 v, glm::vec3 l, glm::vec3 baseColor, float metallic,
                                   float roughness, glm::vec4 dielectric, glm::vec3 intensity) {
    return brdfCosineSpecular(n, v, l, baseColor, metallic, roughness, dielectric) * (kPi * intensity);
}

float regularizedRoughness(float roughness, float footprint, float distance) {
    if (footprint <= 0.0f) return roughness;
    const float alpha = std::min(footprint / (2.0f * std::max(distance, 1e-4f)), 1.0f);
    return std::max(roughness, std::sqrt(alpha));
}

float toksvigRoughness(float roughness, float normalLength) {
    float na = std::clamp(normalLength, 1e-4f, 1.0f);
    float alpha = ggxAlpha(roughness);
    float s = 2.0f / (alpha * alpha) - 2.0f;
    float ft = na / (na + s * (1.0f - na));
    float alpha2 = 2.0f / (ft * s + 2.0f);
    return std::sqrt(std::sqrt(alpha2));
}

glm::vec2 envBrdfApprox(float NoV, float roughness) {
    const glm::vec4 c0(-1.0f, -0.0275f, -0.572f, 0.022f);
    const glm::vec4 c1(1.0f, 0.0425f, 1.04f, -0.04f);
    glm::vec4 r = roughness * c0 + c1;
    float a004 = std::min(r.x * r.x, std::exp2(-9.28f * NoV)) * r.x + r.y;
    return glm::vec2(-1.04f, 1.04f) * a004 + glm::vec2(r.z, r.w);
}

glm::vec3 thinTransmissionCosine(glm::vec3 n, glm::vec3 v, glm::vec3 l, glm::vec3 f0, float f90, float roughness) {
    float NoL = -glm::dot(n, l), NoV = glm::dot(n, v);
    if (NoL <= 0.0f || NoV <= 0.0f) return glm::vec3(0.0f);
    glm::vec3 lm = l + 2.0f * NoL * n;
    glm::vec3 h = glm::normalize(v + lm);
    float alpha = ggxAlpha(roughness);
    float NoH = std::clamp(glm::dot(n, h), 0.0f, 1.0f), VoH = std::clamp(glm::dot(v, h), 0.0f, 1.0f);
    return (glm::vec3(1.0f) - schlickFresnelF90(f0, f90, VoH)) * ggxD(NoH, alpha) *
           smithGgxVisibility(NoV, NoL, alpha) * NoL;
}

} // namespace vitrine::shading
