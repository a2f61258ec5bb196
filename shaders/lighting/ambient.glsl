// The sky's ambient terms, for lighting.deferred and forward.transparent: diffuse from the SH irradiance,
// specular from the sky cube map along the mirror direction times the split-sum environment BRDF (Karis' analytic
// fit here; lighting.deferred weighs by ibl.environment's LUT where connected). A sky with mips is a GGX-prefiltered
// chain (ibl.environment) read at the mip of the roughness; a sky of one level is blurred towards its SH radiance
// with roughness. Both before occlusion.
#ifndef LIGHTING_AMBIENT_GLSL
#define LIGHTING_AMBIENT_GLSL
#include "common/brdf.glsl"
#include "common/sh.glsl"
#include "ibl/ibl_common.glsl"

const float kHalfMax = 60000.0; // keep RGBA16F outputs finite (sun glints on mirrors)

vec3 skyDiffuse(vec3 sh[9], vec3 n, vec3 diffuseColor) {
    return diffuseColor * max(shIrradiance(sh, n), vec3(0.0)) / kPi;
}

// Karis' analytic fit of the split-sum environment BRDF (mobile approximation): the factor an environment's
// radiance along the mirror direction is scaled by.
vec3 environmentBrdf(vec3 f0, float roughness, float NoV) {
    vec4 c0 = vec4(-1.0, -0.0275, -0.572, 0.022);
    vec4 c1 = vec4(1.0, 0.0425, 1.04, -0.04);
    vec4 rr = roughness * c0 + c1;
    float a004 = min(rr.x * rr.x, exp2(-9.28 * NoV)) * rr.x + rr.y;
    vec2 ab = vec2(-1.04, 1.04) * a004 + rr.zw;
    return f0 * ab.x + ab.y;
}

// With Fresnel towards f90 (KHR_materials_specular): the split sum's B term scales with f90, f0 A + f90 B, written
// as f0 A + B - (1 - f90) B (B = environmentBrdf of f0 = 0) so that f90 = 1 is environmentBrdf to the bit.
vec3 environmentBrdfF90(vec3 f0, float f90, float roughness, float NoV) {
    return environmentBrdf(f0, roughness, NoV) - (1.0 - f90) * environmentBrdf(vec3(0.0), roughness, NoV);
}

// The split sum's BRDF factor from a LUT (ibl.environment's or ibl.capture's): f0 A + f90 B.
vec3 environmentBrdfLut(sampler2D lut, vec3 f0, float f90, float roughness, float NoV) {
    vec2 ab = texture(lut, iblLutUv(NoV, roughness, vec2(textureSize(lut, 0)))).rg;
    return f0 * ab.x + f90 * ab.y;
}

// The sky's radiance along r as the lobe of `roughness` gathers it: a prefiltered chain (more than one level) at
// the roughness' mip, else the sky blurred towards its SH radiance.
vec3 skyRadiance(samplerCube sky, vec3 sh[9], vec3 r, float roughness) {
    int levels = textureQueryLevels(sky);
    if (levels > 1) return textureLod(sky, r, iblMipForRoughness(roughness, float(levels))).rgb;
    return mix(textureLod(sky, r, 0.0).rgb, max(shRadiance(sh, r), vec3(0.0)), clamp(roughness * 2.0, 0.0, 1.0));
}

// The sky's specular with the BRDF factor `brdf` (environmentBrdf, environmentBrdfF90 or environmentBrdfLut).
vec3 skySpecularWith(samplerCube sky, vec3 sh[9], vec3 n, vec3 v, vec3 brdf, float roughness) {
    return brdf * min(skyRadiance(sky, sh, reflect(-v, n), roughness), vec3(kHalfMax));
}
vec3 skySpecular(samplerCube sky, vec3 sh[9], vec3 n, vec3 v, vec3 f0, float roughness) {
    float NoV = clamp(dot(n, v), 1e-4, 1.0);
    return skySpecularWith(sky, sh, n, v, environmentBrdf(f0, roughness, NoV), roughness);
}
vec3 skySpecularF90(samplerCube sky, vec3 sh[9], vec3 n, vec3 v, vec3 f0, float f90, float roughness) {
    float NoV = clamp(dot(n, v), 1e-4, 1.0);
    return skySpecularWith(sky, sh, n, v, environmentBrdfF90(f0, f90, roughness, NoV), roughness);
}

// The same with an SH environment (bake.lightmap's irradiance volume): its low-frequency radiance along the
// mirror direction, the room's own light as a stand-in until localized cube maps.
vec3 volumeSpecularWith(vec3 volume[9], vec3 n, vec3 v, vec3 brdf) {
    return brdf * min(max(shRadiance(volume, reflect(-v, n)), vec3(0.0)), vec3(kHalfMax));
}
vec3 volumeSpecular(vec3 volume[9], vec3 n, vec3 v, vec3 f0, float roughness) {
    float NoV = clamp(dot(n, v), 1e-4, 1.0);
    vec3 r = reflect(-v, n);
    return environmentBrdf(f0, roughness, NoV) * min(max(shRadiance(volume, r), vec3(0.0)), vec3(kHalfMax));
}
vec3 volumeSpecularF90(vec3 volume[9], vec3 n, vec3 v, vec3 f0, float f90, float roughness) {
    float NoV = clamp(dot(n, v), 1e-4, 1.0);
    vec3 r = reflect(-v, n);
    return environmentBrdfF90(f0, f90, roughness, NoV) * min(max(shRadiance(volume, r), vec3(0.0)), vec3(kHalfMax));
}

#endif
