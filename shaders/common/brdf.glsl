#ifndef VITRINE_BRDF_GLSL
#define VITRINE_BRDF_GLSL

// The shading model of MUSEUM_SPEC §1, used by every lighting node; CPU mirror:
// core/shading/brdf.hpp. Cook-Torrance specular (GGX NDF, height-correlated Smith GGX
// visibility, Schlick Fresnel) plus Lambert diffuse, metallic workflow [Karis13].
//
// Units and the pi convention. Radiance is in cd/m^2 (the RGB's Rec.709 luminance), illuminance
// in lux. A directional light is given by its "intensity" I = E / pi, where E is the
// illuminance it produces on a surface facing it (lux); the shading multiplies I by pi again:
//     L_out = f(l, v) * (pi * I) * NoL = f(l, v) * E * NoL.
// So a white Lambertian surface facing a light of intensity I has radiance I, and a light whose
// intensity was derived by hand from sky luminance is entered divided by pi. The sky nodes
// output E (lux, texel 9 of their `sh` texture): pass E / pi as the intensity.

#ifndef VITRINE_PI
#define VITRINE_PI
const float kPi = 3.14159265358979323846;
#endif

// Smallest GGX alpha (roughness ~0.045): keeps D finite in fp32 and highlights at least a
// fraction of a pixel wide.
const float kMinGgxAlpha = 0.002;

// The G-buffer stores shininess = 1 - roughness (perceptual roughness, UE4's parameter).
float roughnessFromShininess(float shininess) { return clamp(1.0 - shininess, 0.0, 1.0); }
float ggxAlpha(float roughness) { return max(roughness * roughness, kMinGgxAlpha); }

// GGX / Trowbridge-Reitz NDF, normalised so that the integral of D(h) NoH over the hemisphere is 1.
float ggxD(float NoH, float alpha) {
    float a2 = alpha * alpha;
    float d = NoH * NoH * (a2 - 1.0) + 1.0;
    return a2 / (kPi * d * d);
}

// Height-correlated Smith GGX visibility V = G2 / (4 NoL NoV) [Heitz14].
float smithGgxVisibility(float NoV, float NoL, float alpha) {
    float a2 = alpha * alpha;
    float lambdaV = NoL * sqrt(NoV * NoV * (1.0 - a2) + a2);
    float lambdaL = NoV * sqrt(NoL * NoL * (1.0 - a2) + a2);
    return 0.5 / max(lambdaV + lambdaL, 1e-12);
}

vec3 schlickFresnel(vec3 f0, float VoH) {
    float m = 1.0 - clamp(VoH, 0.0, 1.0);
    float m2 = m * m;
    return f0 + (1.0 - f0) * (m2 * m2 * m);
}

// The *F90 functions below (KHR_materials_specular) are written as the plain function minus (1 - f90) x its part
// that f90 scales: f0 + (f90 - f0) Fc = [f0 + (1 - f0) Fc] - (1 - f90) Fc. At f90 = 1 the correction is an exact 0,
// so a material without the extension gets the plain function's value to the bit, however the device fuses
// multiply-adds (the museum goldens hold the default path to that).
vec3 schlickFresnelF90(vec3 f0, float f90, float VoH) {
    float m = 1.0 - clamp(VoH, 0.0, 1.0);
    float m2 = m * m;
    return schlickFresnel(f0, VoH) - (1.0 - f90) * (m2 * m2 * m);
}

float lambertDiffuse() { return 1.0 / kPi; }

// Metallic workflow: dielectrics reflect 4 % at normal incidence, metals their base colour.
vec3 specularF0(vec3 baseColor, float metallic) { return mix(vec3(0.04), baseColor, metallic); }
vec3 diffuseAlbedo(vec3 baseColor, float metallic) { return baseColor * (1.0 - metallic); }

// KHR_materials_specular: a dielectric's Fresnel F0 and F90 (rgb, a) from its reflectance at normal incidence
// f0Ior (((ior - 1)/(ior + 1))^2, or the fixed 0.04 of specularF0) and the extension's colour c and strength k
// (`specular` rgb, a): F0 = k min(f0Ior c, 1), F90 = k, i.e. the Khronos dielectric_brdf's
// specular_weight x fresnel. Without the extension (c = 1, k = 1) it is (f0Ior, 1): Schlick as before.
vec4 dielectricSpecular(float f0Ior, vec4 specular) {
    return vec4(specular.a * min(f0Ior * specular.rgb, vec3(1.0)), specular.a);
}
// The metallic blend of it: F0 = mix(dielectric F0, base colour, metallic) (metals reflect their base colour),
// written as mix(f0Ior, ...) minus the dielectric's departure from f0Ior (0 without the extension: see above).
vec3 specularF0With(vec3 baseColor, float metallic, float f0Ior, vec4 dielectric) {
    return mix(vec3(f0Ior), baseColor, metallic) - (1.0 - metallic) * (vec3(f0Ior) - dielectric.rgb);
}
// F90 = k + (1 - k) metallic: exactly 1 without the extension.
float specularF90(float metallic, vec4 dielectric) { return dielectric.a + (1.0 - dielectric.a) * metallic; }

// Multiple scattering between the microfacets [Turquin19]. The lobe D V F is single scattering: light that would
// leave the surface after two or more bounces between facets is lost, 1 - E(NoV) of it for F = 1 (E the lobe's
// directional albedo; 69 % lost at roughness 1 seen from above, nothing for a mirror), so rough metals come out
// dark. The compensation scales the lobe by 1 + F0 (1 - E) / E: a white metal's lobe then reflects all the light it
// gets at every roughness, a dielectric's (F0 0.04) a few per cent more. E is common/ggx_albedo.h's fit of the
// quadrature (tools/make_ggx_albedo.py; within 1.9 %). The lobe is compensated where VITRINE_MULTISCATTER is defined
// (every light: render.pathtrace's and the twins' `multiscatter`, lighting.deferred's and forward.transparent's
// `multiscatter` "all"), the split sum's environment term where VITRINE_MULTISCATTER_ENVIRONMENT is (their
// "environment" and "all"; "environment" alone is the glTF Sample Viewer's model [Fdez-Aguera19]), so that the shading
// without them is the single-scattering lobe to the bit. The clear coat's lobe (F0 0.04) is left single scattering.
#include "common/ggx_albedo.h"
float ggxAlbedo(float NoV, float alpha) {
    float x = 2.0 * (sqrt(clamp(NoV, 0.01, 1.0)) - 0.1) / 0.9 - 1.0;
    float y = 2.0 * clamp(sqrt(alpha), sqrt(kMinGgxAlpha), 1.0) - 1.0;
    return clamp(VITRINE_GGX_ALBEDO(x, y), 0.05, 1.0);
}
vec3 ggxMultiscatter(vec3 f0, float NoV, float alpha) {
    float e = ggxAlbedo(NoV, alpha);
    return 1.0 + f0 * ((1.0 - e) / e);
}

// Specular lobe f_s(l, v) = D V F, without the cosine (times ggxMultiscatter with VITRINE_MULTISCATTER); the plain
// one is the F90 one at f90 = 1 (the same value to the bit, see schlickFresnelF90), so the lobe is written once.
vec3 ggxSpecularF90(float NoV, float NoL, float NoH, float VoH, float alpha, vec3 f0, float f90) {
    vec3 s = ggxD(NoH, alpha) * smithGgxVisibility(NoV, NoL, alpha) * schlickFresnelF90(f0, f90, VoH);
#ifdef VITRINE_MULTISCATTER
    s *= ggxMultiscatter(f0, NoV, alpha);
#endif
    return s;
}
vec3 ggxSpecular(float NoV, float NoL, float NoH, float VoH, float alpha, vec3 f0) {
    return ggxSpecularF90(NoV, NoL, NoH, VoH, alpha, f0, 1.0);
}

// The full BRDF times the cosine, f(l, v) NoL, for unit vectors n (surface), v (to the eye),
// l (to the light). Zero when l or v is below the surface.
// The same with the diffuse colour and F0 given apart (a dielectric's F0 from its IOR; transmission
// taking part of the diffuse): brdfCosine is brdfCosineF0 of diffuseAlbedo() and specularF0().
vec3 brdfCosineF0(vec3 n, vec3 v, vec3 l, vec3 diffuseColor, vec3 f0, float roughness) {
    float NoL = dot(n, l);
    float NoV = dot(n, v);
    if (NoL <= 0.0 || NoV <= 0.0) return vec3(0.0);
    vec3 h = normalize(v + l);
    float NoH = clamp(dot(n, h), 0.0, 1.0);
    float VoH = clamp(dot(v, h), 0.0, 1.0);
    vec3 spec = ggxSpecular(NoV, NoL, NoH, VoH, ggxAlpha(roughness), f0);
    return (diffuseColor * lambertDiffuse() + spec) * NoL;
}

// With Fresnel towards f90 (KHR_materials_specular; f90 = 1 gives brdfCosineF0's value). The diffuse lobe is not
// weighted by 1 - F: vitrine's model adds the two lobes (MUSEUM_SPEC §1), with or without the extension.
vec3 brdfCosineF0F90(vec3 n, vec3 v, vec3 l, vec3 diffuseColor, vec3 f0, float f90, float roughness) {
    float NoL = dot(n, l);
    float NoV = dot(n, v);
    if (NoL <= 0.0 || NoV <= 0.0) return vec3(0.0);
    vec3 h = normalize(v + l);
    float NoH = clamp(dot(n, h), 0.0, 1.0);
    float VoH = clamp(dot(v, h), 0.0, 1.0);
    vec3 spec = ggxSpecularF90(NoV, NoL, NoH, VoH, ggxAlpha(roughness), f0, f90);
    return (diffuseColor * lambertDiffuse() + spec) * NoL;
}

vec3 brdfCosine(vec3 n, vec3 v, vec3 l, vec3 baseColor, float metallic, float roughness) {
    return brdfCosineF0(n, v, l, diffuseAlbedo(baseColor, metallic), specularF0(baseColor, metallic), roughness);
}

// brdfCosine of a surface whose dielectric Fresnel is `dielectric` (dielectricSpecular over the F0 0.04 of
// specularF0: F0 rgb, F90 a).
vec3 brdfCosineSpecular(vec3 n, vec3 v, vec3 l, vec3 baseColor, float metallic, float roughness, vec4 dielectric) {
    return brdfCosineF0F90(n, v, l, diffuseAlbedo(baseColor, metallic),
                           specularF0With(baseColor, metallic, 0.04, dielectric), specularF90(metallic, dielectric),
                           roughness);
}

// Outgoing radiance (cd/m^2) from one directional light of intensity I = E / pi (see the top
// of this file): brdfCosine * pi * I.
vec3 shadeDirectional(vec3 n, vec3 v, vec3 l, vec3 baseColor, float metallic, float roughness, vec3 intensity) {
    return brdfCosine(n, v, l, baseColor, metallic, roughness) * (kPi * intensity);
}
vec3 shadeDirectionalSpecular(vec3 n, vec3 v, vec3 l, vec3 baseColor, float metallic, float roughness, vec4 dielectric,
                              vec3 intensity) {
    return brdfCosineSpecular(n, v, l, baseColor, metallic, roughness, dielectric) * (kPi * intensity);
}

// KHR_materials_clearcoat [Khronos]: a dielectric coat of ior 1.5 (F0 0.04, F90 1) and strength c over the whole
// material, with its own normal nc (clearcoatNormalTexture, else the interpolated vertex normal) and roughness:
//     f = f_base (1 - c Fc(nc.v)) + c D V Fc(v.h)   (the glTF Sample Viewer's layering of the spec's fresnel_coat)
// Fc is Schlick's with F0 = 0.04.
const float kClearcoatF0 = 0.04;
float clearcoatFresnel(float VoH) {
    float m = 1.0 - clamp(VoH, 0.0, 1.0);
    float m2 = m * m;
    return kClearcoatF0 + (1.0 - kClearcoatF0) * (m2 * m2 * m);
}

// The coat's specular lobe times its cosine, c-less: D V Fc (nc.l), GGX of alpha = roughness^2 about nc. Zero when l
// or v is below the coat.
float clearcoatSpecularCosine(vec3 nc, vec3 v, vec3 l, float roughness) {
    float NoL = dot(nc, l);
    float NoV = dot(nc, v);
    if (NoL <= 0.0 || NoV <= 0.0) return 0.0;
    vec3 h = normalize(v + l);
    float NoH = clamp(dot(nc, h), 0.0, 1.0);
    float VoH = clamp(dot(v, h), 0.0, 1.0);
    float alpha = ggxAlpha(roughness);
    return ggxD(NoH, alpha) * smithGgxVisibility(NoV, NoL, alpha) * clearcoatFresnel(VoH) * NoL;
}

// The layering: `base` (the uncoated material's reflected light, or its BRDF) seen through a coat of strength
// `clearcoat` whose normal makes NcoV with the view, plus `coat` (the coat's own reflected light, c-less).
vec3 clearcoatLayer(vec3 base, float clearcoat, float NcoV, vec3 coat) {
    return base * (1.0 - clearcoat * clearcoatFresnel(NcoV)) + clearcoat * coat;
}

// brdfCosineSpecular under a clear coat: coat = (strength, perceptual roughness), nc the coat's unit normal.
vec3 brdfCosineClearcoat(vec3 n, vec3 nc, vec3 v, vec3 l, vec3 baseColor, float metallic, float roughness,
                         vec4 dielectric, vec2 coat) {
    vec3 base = brdfCosineSpecular(n, v, l, baseColor, metallic, roughness, dielectric);
    return clearcoatLayer(base, coat.x, dot(nc, v), vec3(clearcoatSpecularCosine(nc, v, l, coat.y)));
}

// KHR_materials_sheen [Khronos]: a retro-reflective dust / fibre lobe over the base (under a clear coat), of colour
// sc (sheenColor, linear) and perceptual roughness r (sheenRoughness), about the base shading normal n:
//     f = sc D V + (1 - max(sc) E(n.v, r)) f_base
// D the Charlie distribution [Estevez & Kulla 2017] of alpha = r^2 (never below kMinSheenAlpha), V the spec's
// fitted Charlie visibility (its lambda curve; Neubelt-Pettineo's 1 / (4 (NoL + NoV - NoL NoV)) reflects up to 2.7x
// the light at grazing angles and was not taken), no Fresnel. E is the lobe's directional albedo for sc = 1, the
// integral of D V (n.l) over the hemisphere, integrated and fitted by tools/make_sheen_albedo.py
// (common/sheen_albedo.h, sheenAlbedo): the albedo scaling of the spec (its view-side term, as the Sample Viewer),
// clamped at 0 where the fitted lobe reflects more than the light it gets (E > 1: r < 0.26 within 3 degrees of
// grazing, NoV < 0.05).
#include "common/sheen_albedo.h"
const float kMinSheenAlpha = 0.01;
float sheenAlpha(float roughness) { return max(roughness * roughness, kMinSheenAlpha); }

// Charlie: D(h) = (2 + 1/alpha) sin(theta_h)^(1/alpha) / (2 pi); its integral of D NoH over the hemisphere is 1.
float sheenCharlieD(float NoH, float alpha) {
    float invAlpha = 1.0 / alpha;
    float sin2 = max(1.0 - NoH * NoH, 0.0);
    return (2.0 + invAlpha) * pow(sin2, 0.5 * invAlpha) / (2.0 * kPi);
}

// The spec's Charlie lambda: exp(L(x)) below x = 0.5, exp(2 L(0.5) - L(1 - x)) above, L(x) = a / (1 + b x^c) + d x + e
// with a..e blended by (1 - alpha)^2 between its two fits.
float sheenLambdaL(float x, float alpha) {
    float t = (1.0 - alpha) * (1.0 - alpha);
    float a = mix(21.5473, 25.3245, t);
    float b = mix(3.82987, 3.32435, t);
    float c = mix(0.19823, 0.16801, t);
    float d = mix(-1.97760, -1.27393, t);
    float e = mix(-4.32054, -4.85967, t);
    return a / (1.0 + b * pow(x, c)) + d * x + e;
}
float sheenLambda(float cosTheta, float alpha) {
    return cosTheta < 0.5 ? exp(sheenLambdaL(cosTheta, alpha))
                          : exp(2.0 * sheenLambdaL(0.5, alpha) - sheenLambdaL(1.0 - cosTheta, alpha));
}
// V = 1 / ((1 + lambda(NoV) + lambda(NoL)) 4 NoV NoL).
float sheenVisibility(float NoV, float NoL, float alpha) {
    return 1.0 / ((1.0 + sheenLambda(NoV, alpha) + sheenLambda(NoL, alpha)) * 4.0 * NoV * NoL);
}

// The sheen lobe times the cosine, sc D V (n.l); zero when l or v is below the surface.
vec3 sheenCosine(vec3 n, vec3 v, vec3 l, vec3 sheenColor, float roughness) {
    float NoL = dot(n, l);
    float NoV = dot(n, v);
    if (NoL <= 0.0 || NoV <= 0.0) return vec3(0.0);
    float NoH = clamp(dot(n, normalize(v + l)), 0.0, 1.0);
    float alpha = sheenAlpha(roughness);
    return sheenColor * (sheenCharlieD(NoH, alpha) * sheenVisibility(NoV, NoL, alpha) * NoL);
}

// E(NoV, r): common/sheen_albedo.h's fit, exp of a polynomial in 2 sqrt(NoV) - 1 and 2 max(r, 0.1) - 1.
float sheenAlbedo(float NoV, float roughness) {
    float x = 2.0 * sqrt(clamp(NoV, 0.0, 1.0)) - 1.0;
    float y = 2.0 * clamp(roughness, 0.1, 1.0) - 1.0;
    return exp(VITRINE_SHEEN_ALBEDO_LOG(x, y));
}

// The base's weight under the sheen, 1 - max(sc) E(n.v, r) (never negative).
float sheenScaling(vec3 sheenColor, float NoV, float roughness) {
    float m = max(max(sheenColor.r, sheenColor.g), sheenColor.b);
    return max(1.0 - m * sheenAlbedo(NoV, roughness), 0.0);
}
bool hasSheen(vec4 sheen) { return max(max(sheen.r, sheen.g), sheen.b) > 0.0; }

// The layering: `base` (the material's reflected light, or its BRDF) under a sheen of scaling `scaling`
// (sheenScaling), plus `sheen` (the sheen's own reflected light, colour included).
vec3 sheenLayer(vec3 base, float scaling, vec3 sheen) { return base * scaling + sheen; }

// brdfCosineClearcoat with a sheen (rgb colour, a perceptual roughness) between the base and the coat; the default
// path (sheen 0) is brdfCosineClearcoat's value to the bit.
vec3 brdfCosineSheen(vec3 n, vec3 nc, vec3 v, vec3 l, vec3 baseColor, float metallic, float roughness, vec4 dielectric,
                     vec2 coat, vec4 sheen) {
    vec3 base = brdfCosineSpecular(n, v, l, baseColor, metallic, roughness, dielectric);
    if (hasSheen(sheen))
        base = sheenLayer(base, sheenScaling(sheen.rgb, dot(n, v), sheen.a), sheenCosine(n, v, l, sheen.rgb, sheen.a));
    return clearcoatLayer(base, coat.x, dot(nc, v), vec3(clearcoatSpecularCosine(nc, v, l, coat.y)));
}

// Toksvig [Toksvig04]: a normal averaged over a footprint (mip-mapped without renormalising)
// has length |Na| < 1; treat the spread as a Gaussian of angular variance (1 - |Na|) / |Na| and
// widen the lobe. Mapping: GGX alpha to the Blinn-Phong exponent s = 2 / alpha^2 - 2,
// Toksvig's factor ft = |Na| / (|Na| + s (1 - |Na|)), s' = ft s, back with
// alpha'^2 = 2 / (s' + 2). For small alpha this is alpha'^2 ~= alpha^2 + 2 (1 - |Na|) / |Na|.
// Returns the widened perceptual roughness (never below sqrt(kMinGgxAlpha)).
float toksvigRoughness(float roughness, float normalLength) {
    float na = clamp(normalLength, 1e-4, 1.0);
    float alpha = ggxAlpha(roughness);
    float s = 2.0 / (alpha * alpha) - 2.0;
    float ft = na / (na + s * (1.0 - na));
    float alpha2 = 2.0 / (ft * s + 2.0);
    return sqrt(sqrt(alpha2));
}

// Path-space regularisation [Kaplanyan & Dachsbacher 2013] of a glossy lobe lit by a delta light (the sun), for
// estimators that store their result at a finite resolution (the lightmap bake). A near-mirror lobe lit by the sun
// is a caustic seen from the previous vertex of the path, `distance` away: found only by the rare directions that
// land in the sun's tiny reflection, each with an enormous weight (one path in tens of thousands carries 40x a
// texel's light). Widened so that the reflection spreads over `footprint` metres at the previous vertex (its
// half-vector spread alpha widens the reflected lobe by about 2 alpha radians), the caustic keeps its energy and
// its place to within the footprint, and its rare huge paths become many ordinary ones. footprint 0: unchanged.
float regularizedRoughness(float roughness, float footprint, float distance) {
    if (footprint <= 0.0) return roughness;
    float alpha = min(footprint / (2.0 * max(distance, 1e-4)), 1.0);
    return max(roughness, sqrt(alpha));
}

#endif
