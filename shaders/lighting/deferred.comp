#version 460
#extension GL_GOOGLE_include_directive : require
#include "lighting/deferred.h"
#include "common/brdf.glsl"
#include "common/octahedral.glsl"
#include "common/sh.glsl"
#include "lighting/ambient.glsl"
#include "bake/irradiance_volume.glsl"

// Deferred lighting (MUSEUM_SPEC §1, §3): Cook-Torrance GGX/Smith/Schlick + Lambert for the sun with
// cascaded PCF shadows and unshadowed point and spot lights, then the indirect light:
//   - lightmapped pixels (G-buffer emissive a = 1) carry their baked diffuse in the emissive channel;
//   - others take diffuse from bake.lightmap's irradiance volume when it is connected;
//   - without either, the open sky's SH irradiance scaled by `sky_ambient` stands in;
// indirect specular: ibl.localized's where connected, else the volume's SH radiance along the mirror direction
// where there is a volume, else the sky (ibl.environment's prefiltered mip of the roughness, or a sky of one level
// blurred towards its SH), weighed by ibl.environment's split-sum LUT or Karis' fit. Cavity and vertex AO
// darken the ambient terms; emissive is added.
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0) uniform sampler2D in_normal;
layout(binding = 1) uniform sampler2D in_base_color;
layout(binding = 2) uniform sampler2D in_material;
layout(binding = 3) uniform sampler2D in_emissive;
layout(binding = 4) uniform sampler2D in_depth;
layout(binding = 5) uniform sampler2D in_shadow_map;
layout(binding = 6) uniform sampler2D in_sky_sh;
layout(binding = 7) uniform samplerCube in_sky;
layout(binding = 8) writeonly uniform image2D out_color;
layout(binding = 9) writeonly uniform image2D out_specular_indirect;
layout(binding = 10) uniform Uniforms { DeferredUniforms u; };
layout(binding = 11) uniform sampler2D in_volume;
layout(binding = 12) uniform sampler2D in_ao;
layout(binding = 13) uniform sampler2D in_ibl_specular;
layout(binding = 14) uniform sampler2D in_ibl_diffuse;
layout(binding = 15) writeonly uniform image2D out_diffuse_indirect;
layout(binding = 16) uniform sampler2D in_sheen;
layout(binding = 17) uniform sampler2D in_brdf_lut; // ibl.environment's split-sum LUT (flag 8)
#define VITRINE_LIGHTS u.lights
#define VITRINE_SHADOW u.shadow
#include "lighting/sun_shadow.glsl"
#include "lighting/punctual.glsl"
#include "gbuffer/clearcoat_pack.glsl"

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = imageSize(out_color);
    if (any(greaterThanEqual(p, size))) return;
    vec2 uv = (vec2(p) + 0.5) / vec2(size);
    float z = texelFetch(in_depth, p, 0).r;
    vec4 clip = vec4(uv * 2.0 - 1.0, z, 1.0);
    vec4 wh = u.invViewProj * vec4(clip.xy, max(z, 1e-7), 1.0);
    vec3 world = wh.xyz / wh.w;
    vec3 v = normalize(u.cameraPos.xyz - world);

    if (z <= 0.0) {
        // Nothing drawn: the sky seen through windows and skylights.
        vec3 sky = textureLod(in_sky, -v, 0.0).rgb;
        imageStore(out_color, p, vec4(min(sky, vec3(kHalfMax)), 1.0));
        imageStore(out_specular_indirect, p, vec4(0.0));
        imageStore(out_diffuse_indirect, p, vec4(0.0));
        return;
    }

    vec4 g0 = texelFetch(in_normal, p, 0);
    vec4 g1 = texelFetch(in_base_color, p, 0);
    vec4 g2 = texelFetch(in_material, p, 0);
    vec4 emissiveLm = texelFetch(in_emissive, p, 0);
    vec3 emissive = emissiveLm.rgb;
    bool lightmapped;
    // KHR_materials_clearcoat (strength, roughness) packed with the flag; the coat shades with the base normal n.
    // KHR_materials_sheen (colour, roughness) from its own target, layered under the coat.
    vec2 coat = unpackClearcoatAlpha(emissiveLm.a, lightmapped);
    vec4 sheen = texelFetch(in_sheen, p, 0);
    vec3 n = octDecode(g0.xy);
    float viewDepth = g0.z;
    float roughness = roughnessFromShininess(g0.w);
    vec3 baseColor = g1.rgb;
    float metallic = g1.a;
    float vertexAo = g2.z;
    float cavity = g2.w;
    // KHR_materials_specular's strength k (G-buffer material.y = 1 - k): the dielectric's F0 0.04 k, F90 k.
    vec4 dielectric = dielectricSpecular(0.04, vec4(vec3(1.0), 1.0 - g2.y));

    vec3 sh[9];
    for (int i = 0; i < 9; ++i) sh[i] = texelFetch(in_sky_sh, ivec2(i, 0), 0).rgb;
    vec3 sunE = texelFetch(in_sky_sh, ivec2(9, 0), 0).rgb * u.params.z; // lux, perpendicular to the sun
    vec3 l = normalize(texelFetch(in_sky_sh, ivec2(10, 0), 0).xyz);

    // Sun: E / pi is the light's intensity in the pi convention of brdf.glsl.
    float visibility = u.params.y > 0.5 ? sunVisibility(in_shadow_map, world, n, viewDepth) : 1.0;
    vec3 direct =
        shadeDirectionalSpecular(n, v, l, baseColor, metallic, roughness, dielectric, sunE / kPi) * visibility * cavity;

    // Indirect light: baked (lightmap in the emissive channel, or the irradiance volume), else the sky's SH
    // irradiance and the sky along the mirror direction, scaled by the stand-in occlusion.
    vec3 volume[9];
    bool baked = volumeSh(in_volume, u.volumeOrigin, u.volumeCounts.xyz, world, n, volume);
    float occlusion = baked ? vertexAo * cavity : u.params.x * vertexAo * cavity;
    vec3 diffuse = vec3(0.0);
    if (!lightmapped) diffuse = skyDiffuse(baked ? volume : sh, n, diffuseAlbedo(baseColor, metallic)) * occlusion;
    vec3 f0 = specularF0With(baseColor, metallic, 0.04, dielectric);
    float f90 = specularF90(metallic, dielectric);
    // The split sum's BRDF factor: the LUT where connected (what the environment's lobe reflects, as ibl.localized
    // weighs the probes), else Karis' analytic fit.
    bool brdfLut = (u.volumeCounts.w & 8u) != 0u;
    float NoVc = clamp(dot(n, v), 1e-4, 1.0);
    vec3 brdf = brdfLut ? environmentBrdfLut(in_brdf_lut, f0, f90, roughness, NoVc)
                        : environmentBrdfF90(f0, f90, roughness, NoVc);
#ifdef VITRINE_MULTISCATTER_ENVIRONMENT
    brdf *= ggxMultiscatter(f0, NoVc, ggxAlpha(roughness)); // the lobe's multiple scattering (`multiscatter`)
#endif
    vec3 specular = (baked ? volumeSpecularWith(volume, n, v, brdf)
                           : skySpecularWith(in_sky, sh, n, v, brdf, roughness)) *
                    occlusion;
    // ibl.localized (when connected) replaces the stand-ins: its probes carry the room's own light and occlusion,
    // so only the material's vertex AO and cavity darken it.
    if ((u.volumeCounts.w & 1u) != 0u) specular = texelFetch(in_ibl_specular, p, 0).rgb * vertexAo * cavity;
    if (!lightmapped && !baked && (u.volumeCounts.w & 2u) != 0u)
        diffuse = texelFetch(in_ibl_diffuse, p, 0).rgb * vertexAo * cavity;
    // KHR_lights_punctual point and spot lights (unshadowed), with the cavity as the sun has it.
    direct += shadePunctual(world, n, v, diffuseAlbedo(baseColor, metallic), f0, f90, roughness) * cavity;

    // Screen-space AO on the indirect terms only (MUSEUM_SPEC §5), tinted by the base colour like a little GI; a
    // lightmapped pixel's emissive channel is its baked diffuse (and any emission with it).
    if ((u.volumeCounts.w & 4u) != 0u) {
        vec3 tint = mix(baseColor, vec3(1.0), textureLod(in_ao, uv, 0.0).r);
        diffuse *= tint;
        specular *= tint;
        if (lightmapped) emissive *= tint;
    }
    // Lightmapped pixels carry emission and baked diffuse together: emissive_scale leaves them as baked.
    vec3 color = direct + diffuse + specular + emissive * (lightmapped ? 1.0 : u.params.w);
    // The sheen over the reflected light (a lightmapped pixel's baked diffuse with it, emission not): the base
    // scaled by 1 - max(sc) E(n.v), plus the sheen's reflection of the sun and the lights, and of the sky or the
    // volume approximated as the lobe's albedo sc E times the irradiance (a Charlie-prefiltered sky is not made).
    if (hasSheen(sheen)) {
        float NoV = dot(n, v);
        float scaling = sheenScaling(sheen.rgb, NoV, sheen.a);
        vec3 sheenDirect = sheenCosine(n, v, l, sheen.rgb, sheen.a) * sunE * visibility * cavity;
        sheenDirect += shadePunctualSheen(world, n, v, sheen) * cavity;
        vec3 sheenAmbient = skyDiffuse(baked ? volume : sh, n, sheen.rgb * sheenAlbedo(NoV, sheen.a)) * occlusion;
        vec3 emitted = lightmapped ? vec3(0.0) : emissive * u.params.w;
        color = sheenLayer(color - emitted, scaling, sheenDirect + sheenAmbient) + emitted;
        specular *= scaling;
        diffuse = sheenLayer(diffuse, scaling, sheenAmbient);
        if (lightmapped) emissive *= scaling;
    }
    // The clear coat over all of it: the base seen through the coat, 1 - c Fc(n.v), plus the coat's own
    // reflection of the sun, the lights and the sky (F0 0.04), with the cavity and occlusion the base has.
    if (coat.x > 0.0) {
        vec3 coatDirect = vec3(clearcoatSpecularCosine(n, v, l, coat.y)) * sunE * visibility * cavity;
        coatDirect += shadePunctualClearcoat(world, n, v, coat.y) * cavity;
        vec3 coatBrdf = brdfLut ? environmentBrdfLut(in_brdf_lut, vec3(kClearcoatF0), 1.0, coat.y, NoVc)
                                : environmentBrdf(vec3(kClearcoatF0), coat.y, NoVc);
        vec3 coatSpecular = (baked ? volumeSpecularWith(volume, n, v, coatBrdf)
                                   : skySpecularWith(in_sky, sh, n, v, coatBrdf, coat.y)) *
                            occlusion;
        float NoV = dot(n, v);
        color = clearcoatLayer(color, coat.x, NoV, coatDirect + coatSpecular);
        specular = clearcoatLayer(specular, coat.x, NoV, coatSpecular);
        diffuse = clearcoatLayer(diffuse, coat.x, NoV, vec3(0.0));
        emissive = clearcoatLayer(emissive, coat.x, NoV, vec3(0.0));
    }
    imageStore(out_color, p, vec4(min(color, vec3(kHalfMax)), 1.0));
    imageStore(out_specular_indirect, p, vec4(min(specular, vec3(kHalfMax)), 1.0));
    // The indirect diffuse alone (the twin of reference.diffuse_indirect): a lightmapped pixel's is its emissive
    // channel, baked diffuse and the surface's own emission together.
    vec3 diffuseIndirect = diffuse + (lightmapped ? emissive : vec3(0.0));
    imageStore(out_diffuse_indirect, p, vec4(min(diffuseIndirect, vec3(kHalfMax)), 1.0));
}
