#version 460
#extension GL_GOOGLE_include_directive : require
#include "ibl/localized.h"
#include "ibl/ibl_common.glsl"
#include "common/octahedral.glsl"
#include "common/brdf.glsl"
#include "common/sh.glsl"
#include "lighting/ambient.glsl"
// ibl.localized's resolve (one full-screen triangle): L = sum(C w) / sum(w) from the volume passes' accumulation,
// then split-sum specular L (f0 A + B) with the BRDF LUT, and diffuse = diffuse albedo x the probes' roughest
// mip along the normal (a cosine-lobe stand-in for irradiance / pi). Pixels that no probe weighs fall back to the
// sky exactly as lighting.deferred shades it without a volume (ambient.glsl), scaled by the sky fallback.
layout(set = 0, binding = 0) uniform Uniforms { LocalizedUniforms u; };
layout(set = 0, binding = 1) uniform sampler2D in_depth;
layout(set = 0, binding = 2) uniform sampler2D in_normal;
layout(set = 0, binding = 3) uniform sampler2D in_base_color;
layout(set = 0, binding = 6) uniform sampler2D in_radiance_sum;
layout(set = 0, binding = 7) uniform sampler2D in_irradiance_sum;
layout(set = 0, binding = 8) uniform sampler2D in_brdf_lut;
layout(set = 0, binding = 9) uniform samplerCube in_sky;
layout(set = 0, binding = 10) uniform sampler2D in_sky_sh;
#include "ibl/localized.glsl"

layout(location = 0) out vec4 outSpecular;
layout(location = 1) out vec4 outDiffuse;
layout(location = 2) out vec4 outRadiance;

void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    float z = texelFetch(in_depth, p, 0).r;
    if (z <= 0.0) {
        // The sky itself: no surface to light (lighting.deferred writes it as background).
        outSpecular = outDiffuse = outRadiance = vec4(0.0);
        return;
    }
    vec3 world = localizedWorld(gl_FragCoord.xy, vec2(textureSize(in_depth, 0)), z);
    vec4 g0 = texelFetch(in_normal, p, 0);
    vec4 g1 = texelFetch(in_base_color, p, 0);
    vec3 n = octDecode(g0.xy);
    float roughness = roughnessFromShininess(g0.w);
    vec3 v = normalize(u.cameraPos.xyz - world);
    vec3 f0 = specularF0(g1.rgb, g1.a);
    vec3 albedo = diffuseAlbedo(g1.rgb, g1.a);
    vec4 rad = texelFetch(in_radiance_sum, p, 0);
    vec4 irr = texelFetch(in_irradiance_sum, p, 0);
    if (rad.a > 0.0) {
        vec3 l = rad.rgb / rad.a;
        float NoV = clamp(dot(n, v), 1e-4, 1.0);
        vec2 ab = texture(in_brdf_lut, iblLutUv(NoV, roughness, vec2(textureSize(in_brdf_lut, 0)))).rg;
        vec3 brdf = f0 * ab.x + ab.y;
#ifdef VITRINE_MULTISCATTER_ENVIRONMENT
        brdf *= ggxMultiscatter(f0, NoV, ggxAlpha(roughness)); // the lobe's multiple scattering (`multiscatter`)
#endif
        outSpecular = vec4(min(l * brdf, vec3(kHalfMax)), 1.0);
        outDiffuse = vec4(min(albedo * irr.rgb / irr.a, vec3(kHalfMax)), 1.0);
        outRadiance = vec4(min(l, vec3(kHalfMax)), 1.0);
    } else {
        vec3 sh[9];
        for (int i = 0; i < 9; ++i) sh[i] = texelFetch(in_sky_sh, ivec2(i, 0), 0).rgb;
        vec3 sky = skySpecular(in_sky, sh, n, v, f0, roughness);
#ifdef VITRINE_MULTISCATTER_ENVIRONMENT
        sky *= ggxMultiscatter(f0, clamp(dot(n, v), 1e-4, 1.0), ggxAlpha(roughness));
#endif
        outSpecular = vec4(sky * u.params.z, 1.0);
        outDiffuse = vec4(skyDiffuse(sh, n, albedo) * u.params.z, 1.0);
        outRadiance = vec4(0.0);
    }
}
