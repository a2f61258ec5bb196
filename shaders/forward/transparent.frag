#version 460
#extension GL_GOOGLE_include_directive : require
#define VITRINE_SCENE_FRAGMENT
// The scene's texture array is walked with a uniform loop index (scene/scene.glsl): indexing it with the material's
// texture index in a fragment shader that also samples a cube map crashed lavapipe (Mesa 22.3) when the draw was
// compiled. The walk costs a loop over the scene's textures per textured parameter; untextured glass pays nothing.
#define VITRINE_SCENE_DIVERGENT_TEXTURES
#include "scene/scene.glsl"
#include "common/brdf.glsl"
#include "forward/transparent.h"
#include "lighting/ambient.glsl"
#include "bake/irradiance_volume.glsl"
#include "common/mip_atlas.glsl"
#include "common/thin_transmission.glsl"

// Set 0: the node's uniforms and inputs; set 1: the scene (VITRINE_SCENE_SET, defined by the node).
// forward.transparent: alpha-blended and transmissive (thin glass) surfaces over the lit opaque colour, lit by
// the terms of lighting.deferred (sun with cascaded shadows, point and spot lights, the sky's ambient diffuse
// and Fresnel-weighted reflection, emissive). Dual-source blending: dst' = outColor + dst × outTransmit, so a
// pane can tint what lies behind it per channel:
//   outColor    = alpha × lit colour (reflection, the diffuse left by transmission, emission)
//   outTransmit = (1 − alpha) + alpha × transmission × (1 − F(NoV)) × base colour × volume attenuation
// With no transmission this is the usual "over" of the lit colour with its coverage alpha. With a `background`
// (color.pyramid of the opaque colour), transmission instead reads what lies behind from it, as the glTF Sample
// Viewer reads its transmission framebuffer: refracted through the volume's thickness and blurred by roughness;
// outTransmit is then 1 − alpha and that light is in outColor.
layout(set = 0, binding = 0) uniform Uniforms { TransparentUniforms u; };
#define VITRINE_LIGHTS u.lights
#define VITRINE_SHADOW u.shadow
#include "lighting/sun_shadow.glsl"
#include "lighting/punctual.glsl"
layout(set = 0, binding = 1) uniform sampler2D in_shadow_map;
layout(set = 0, binding = 2) uniform sampler2D in_sky_sh;
layout(set = 0, binding = 3) uniform samplerCube in_sky;
layout(set = 0, binding = 5) uniform sampler2D in_volume; // bound to another image, never read, without a volume
layout(set = 0, binding = 6) uniform sampler2D in_background; // the same without a background
layout(set = 0, binding = 7) uniform sampler2D in_brdf_lut; // the same without a LUT (volumeCounts.w 0)

layout(location = 0) in vec3 vNormal;
layout(location = 1) in vec4 vTangent;
layout(location = 2) in vec2 vUv0;
layout(location = 3) in vec2 vUv1;
layout(location = 4) in vec4 vColor;
layout(location = 5) in vec4 vClip;
layout(location = 6) in vec4 vPrevClip;
layout(location = 7) in float vViewDepth;

// thinTransmissionCosine x E of every point and spot light (shadePunctual's lights, behind the surface).
vec3 shadePunctualTransmitted(vec3 p, vec3 n, vec3 v, vec3 f0, float f90, float roughness) {
    vec3 sum = vec3(0.0);
    for (uint i = 0u; i < VITRINE_LIGHTS.count.x; ++i) {
        vec3 l;
        vec3 e = punctualIlluminance(VITRINE_LIGHTS.lights[i], p, l);
        sum += thinTransmissionCosine(n, v, l, f0, f90, roughness) * e;
    }
    return sum;
}

layout(location = 0, index = 0) out vec4 outColor;
layout(location = 0, index = 1) out vec4 outTransmit;

void main() {
    UvGradients grads = uvGradients(vUv0, vUv1);
    GpuMaterial m = materials[draw.material];
    LayeredSurface s = evaluateLayers(m, vUv0, vUv1, grads);
    if (m.info.z == 1u && s.albedo.a < m.emissive.a) discard;
    float alpha = m.info.z == 2u ? clamp(s.albedo.a, 0.0, 1.0) : 1.0;

    vec3 N = shadingNormal(vNormal, vTangent, s.normal, gl_FrontFacing);
    vec2 ndc = gl_FragCoord.xy / camera.params.zw * 2.0 - 1.0;
    vec4 wh = camera.invViewProj * vec4(ndc, gl_FragCoord.z, 1.0);
    vec3 world = wh.xyz / wh.w;
    vec3 v = normalize(camera.position.xyz - world);

    vec3 baseColor = s.albedo.rgb * vColor.rgb;
    float metallic = clamp(s.metallic, 0.0, 1.0);
    float roughness = roughnessFromShininess(clamp(s.shininess, 0.0, 1.0));
    float cavity = clamp(s.cavity, 0.0, 1.0);
    vec3 emissive = m.emissive.rgb;
    if (m.emissiveRef.info.x >= 0) emissive *= sampleRef(m.emissiveRef, vUv0, vUv1, grads).rgb;

    // KHR_materials_transmission takes the dielectric's diffuse; F0 from KHR_materials_ior, scaled and tinted by
    // KHR_materials_specular (F90 too).
    float transmission = m.optics.x * (1.0 - metallic);
    vec4 dielectric = dielectricSpecular(m.optics.y, materialSpecular(m, vUv0, vUv1, grads));
    vec3 f0 = specularF0With(baseColor, metallic, m.optics.y, dielectric);
    float f90 = specularF90(metallic, dielectric);
    vec3 diffuseColor = baseColor * (1.0 - metallic) * (1.0 - transmission);

    vec3 sh[9];
    for (int i = 0; i < 9; ++i) sh[i] = texelFetch(in_sky_sh, ivec2(i, 0), 0).rgb;
    vec3 sunE = texelFetch(in_sky_sh, ivec2(9, 0), 0).rgb * u.params.z;
    vec3 l = normalize(texelFetch(in_sky_sh, ivec2(10, 0), 0).xyz);

    float visibility = u.params.y > 0.5 ? sunVisibility(in_shadow_map, world, N, vViewDepth) : 1.0;
    vec3 direct = brdfCosineF0F90(N, v, l, diffuseColor, f0, f90, roughness) * sunE * visibility * cavity;
    direct += shadePunctual(world, N, v, diffuseColor, f0, f90, roughness) * cavity;
    // The same indirect terms as lighting.deferred: bake.lightmap's irradiance volume where it is connected
    // (transparent surfaces have no lightmap), else the sky scaled by sky_ambient.
    vec3 volume[9];
    bool baked = volumeSh(in_volume, u.volumeOrigin, u.volumeCounts.xyz, world, N, volume);
    float occlusion = baked ? vColor.a * cavity : u.params.x * vColor.a * cavity;
    vec3 diffuse = skyDiffuse(baked ? volume : sh, N, diffuseColor) * occlusion;
    // The split sum's BRDF factor: the LUT where connected (as lighting.deferred), else Karis' analytic fit.
    bool brdfLut = u.volumeCounts.w != 0u;
    float NoVc = clamp(dot(N, v), 1e-4, 1.0);
    vec3 brdf = brdfLut ? environmentBrdfLut(in_brdf_lut, f0, f90, roughness, NoVc)
                        : environmentBrdfF90(f0, f90, roughness, NoVc);
#ifdef VITRINE_MULTISCATTER_ENVIRONMENT
    brdf *= ggxMultiscatter(f0, NoVc, ggxAlpha(roughness)); // the lobe's multiple scattering (`multiscatter`)
#endif
    vec3 specular = (baked ? volumeSpecularWith(volume, N, v, brdf) : skySpecularWith(in_sky, sh, N, v, brdf, roughness)) *
                    occlusion;
    vec3 lit = direct + diffuse + specular + emissive * u.params.w;

    // Thin glass: what the surface does not reflect passes through, tinted by the base colour.
    vec3 tint = transmission * baseColor;
    // KHR_materials_volume as the Sample Viewer: the light crosses the volume along transmissionRay, the unit
    // refracted direction (Snell's law at the IOR) times the thickness times the node's scale, the lengths of its
    // model matrix's columns (getVolumeTransmissionRay; thickness x scale long for a uniform scale), and a medium
    // keeps attenuationColor^(length / attenuationDistance) of it (Beer's law, applyVolumeAttenuation). Thickness 0
    // (thin-walled) crosses nothing; an infinite distance (volume.a 0) attenuates nothing.
    float sqrtF0 = sqrt(m.optics.y); // 1/ior = (1 - sqrt(F0)) / (1 + sqrt(F0)), and 0 for KHR_materials_ior's 0
    float thickness = materialThickness(m, vUv0, vUv1, grads);
    vec3 transmissionRay = vec3(0.0);
    if (thickness > 0.0) {
        mat4 model = instances[draw.instance].world;
        vec3 modelScale = vec3(length(model[0].xyz), length(model[1].xyz), length(model[2].xyz));
        transmissionRay = normalize(refract(-v, N, (1.0 - sqrtF0) / (1.0 + sqrtF0))) * thickness * modelScale;
        if (m.volume.a > 0.0) tint *= pow(m.volume.rgb, vec3(length(transmissionRay) / m.volume.a));
    }
    vec3 through = (vec3(1.0) - schlickFresnelF90(f0, f90, dot(N, v))) * tint;
    // The sun and the lights behind the surface, through its transmission lobe (the sun's shadow looked up from the
    // far side), tinted as what passes; layered under the sheen and the coat with the rest.
    if (any(greaterThan(tint, vec3(0.0)))) {
        // (no shadow lookup for a sun in front: its lobe is 0 there)
        float behind = u.params.y > 0.5 && dot(N, l) < 0.0 ? sunVisibility(in_shadow_map, world, -N, vViewDepth) : 1.0;
        vec3 transmitted = thinTransmissionCosine(N, v, l, f0, f90, roughness) * sunE * behind;
        transmitted += shadePunctualTransmitted(world, N, v, f0, f90, roughness);
        lit += tint * transmitted;
    }
    // KHR_materials_sheen over the reflected light (as lighting.deferred: emission not scaled, the sky or volume
    // through the lobe's albedo times the irradiance) and over what passes through.
    vec4 sheen = materialSheen(m, vUv0, vUv1, grads);
    if (hasSheen(sheen)) {
        float NoV = dot(N, v);
        float scaling = sheenScaling(sheen.rgb, NoV, sheen.a);
        vec3 sheenLight = sheenCosine(N, v, l, sheen.rgb, sheen.a) * sunE * visibility * cavity;
        sheenLight += shadePunctualSheen(world, N, v, sheen) * cavity;
        sheenLight += skyDiffuse(baked ? volume : sh, N, sheen.rgb * sheenAlbedo(NoV, sheen.a)) * occlusion;
        vec3 emitted = emissive * u.params.w;
        lit = sheenLayer(lit - emitted, scaling, sheenLight) + emitted;
        through *= scaling;
    }
    // KHR_materials_clearcoat over all of it, with the coat's own normal: the base (and what passes through) seen
    // through the coat, 1 - c Fc(nc.v), plus the coat's reflection of the sun, the lights and the sky.
    vec2 coat = materialClearcoat(m, vUv0, vUv1, grads);
    if (coat.x > 0.0) {
        vec3 nc = shadingNormal(vNormal, vTangent, materialClearcoatNormal(m, vUv0, vUv1, grads), gl_FrontFacing);
        vec3 coatLight = vec3(clearcoatSpecularCosine(nc, v, l, coat.y)) * sunE * visibility * cavity;
        coatLight += shadePunctualClearcoat(world, nc, v, coat.y) * cavity;
        float NcoVc = clamp(dot(nc, v), 1e-4, 1.0);
        vec3 coatBrdf = brdfLut ? environmentBrdfLut(in_brdf_lut, vec3(kClearcoatF0), 1.0, coat.y, NcoVc)
                                : environmentBrdf(vec3(kClearcoatF0), coat.y, NcoVc);
        coatLight += (baked ? volumeSpecularWith(volume, nc, v, coatBrdf)
                            : skySpecularWith(in_sky, sh, nc, v, coatBrdf, coat.y)) *
                     occlusion;
        float NcoV = dot(nc, v);
        lit = clearcoatLayer(lit, coat.x, NcoV, coatLight);
        through = clearcoatLayer(through, coat.x, NcoV, vec3(0.0));
    }
    if (m.optics.z > 0.5) { // KHR_materials_unlit: the colour is the radiance, as through the G-buffer's emissive
        lit = baseColor * u.params.w;
        through = vec3(0.0);
    }
    // What lies behind, with a background: the opaque colour where the transmission ray leaves the volume,
    // projected to the screen (straight behind for thin-walled glass), blurred as the Sample Viewer blurs it. Its
    // getTransmissionSample reads a 1024^2 framebuffer at level log2(1024) x r with r = roughness x clamp(2 ior - 2,
    // 0, 1) (applyIorToRoughness: no blur at IOR 1, all of it from 1.5 on), a footprint of 2^(10 r) / 1024 of the
    // screen; the same share of this pyramid's larger side is level log2(side) - 10 (1 - r). It replaces the
    // dual-source tint of the pixel behind.
    if (u.background.x != 0u && any(greaterThan(through, vec3(0.0)))) {
        vec4 clip = camera.viewProj * vec4(world + transmissionRay, 1.0);
        vec2 uv = clip.xy / clip.w * 0.5 + 0.5;
        ivec2 size0 = ivec2(u.background.yz);
        float iorScale = clamp(4.0 * sqrtF0 / max(1.0 - sqrtF0, 1e-6), 0.0, 1.0); // 2 ior - 2, ior = (1 + sqrtF0) / (1 - sqrtF0)
        float lod = log2(float(max(size0.x, size0.y))) - 10.0 * (1.0 - roughness * iorScale);
        lit += through * mipSample(in_background, size0, int(u.background.w), uv, lod).rgb;
        through = vec3(0.0);
    }
    outColor = vec4(min(lit, vec3(kHalfMax)) * alpha, alpha);
    outTransmit = vec4(vec3(1.0 - alpha) + alpha * through, 1.0);
}
