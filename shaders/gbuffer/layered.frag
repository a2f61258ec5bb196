#version 460
#extension GL_GOOGLE_include_directive : require
#define VITRINE_SCENE_FRAGMENT
#include "scene/scene.glsl"
#include "common/brdf.glsl"
#include "common/octahedral.glsl"
#include "gbuffer/unlit.glsl"
#include "gbuffer/clearcoat_pack.glsl"

// The G-buffer of MUSEUM_SPEC §2, written while the material layers are blended per pixel.
layout(location = 0) in vec3 vNormal;
layout(location = 1) in vec4 vTangent;
layout(location = 2) in vec2 vUv0;
layout(location = 3) in vec2 vUv1;
layout(location = 4) in vec4 vColor;
layout(location = 5) in vec4 vClip;
layout(location = 6) in vec4 vPrevClip;
layout(location = 7) in float vViewDepth;

layout(location = 0) out vec4 outNormal;   // octahedral normal xy, linear view depth, shininess
layout(location = 1) out vec4 outBase;     // base colour rgb, metallic
layout(location = 2) out vec4 outMaterial; // base colour alpha, 1 - specular strength, vertex AO, cavity
layout(location = 3) out vec2 outVelocity; // pixels, current minus previous position
layout(location = 4) out vec4 outEmissive; // rgb: emissive + baked diffuse radiance; a: 1 where lightmapped
layout(location = 5) out vec4 outSheen;    // KHR_materials_sheen: colour rgb, roughness (0: no sheen)

#ifdef VITRINE_GBUFFER_LIGHTMAP
// bake.lightmap's irradiance atlas (lux); draw.lightmap maps uv1 into this instance's region.
layout(set = 1, binding = 0) uniform sampler2D lightmapAtlas;
#endif

#define FLAG_TOKSVIG 1u
#define FLAG_LIGHTMAP 2u

void main() {
    UvGradients grads = uvGradients(vUv0, vUv1);
    GpuMaterial m = materials[draw.material];
    LayeredSurface s = evaluateLayers(m, vUv0, vUv1, grads);
    float coverage = s.albedo.a;
    if (m.info.z == 1u && coverage < m.emissive.a) discard;

    vec3 n = normalize(vNormal);
    vec3 t = vTangent.xyz - n * dot(n, vTangent.xyz);
    t = dot(t, t) > 1e-12 ? normalize(t) : vec3(1.0, 0.0, 0.0);
    vec3 b = cross(n, t) * (vTangent.w < 0.0 ? -1.0 : 1.0);
    float len = length(s.normal);
    vec3 nts = len > 1e-6 ? s.normal / len : vec3(0.0, 0.0, 1.0);
    vec3 N = normalize(t * nts.x + b * nts.y + n * nts.z);
    if (!gl_FrontFacing) N = -N;

    float shininess = clamp(s.shininess, 0.0, 1.0);
    if ((draw.flags & FLAG_TOKSVIG) != 0u) {
        // Toksvig [Toksvig04]: the averaged normal's shortening widens the lobe (common/brdf.glsl). The shortening
        // is the mip chain's (scene.glsl's normalLength), not the decoded vector's length, which 8-bit rounding
        // moves by up to 0.8 % on a flat map.
        shininess = 1.0 - toksvigRoughness(roughnessFromShininess(shininess), s.normalLength);
    }

    vec2 ndc = vClip.xy / vClip.w;
    vec2 prevNdc = vPrevClip.xy / vPrevClip.w;
    vec2 velocity = (ndc - prevNdc) * 0.5 * camera.params.zw;

    vec3 emissive = m.emissive.rgb;
    if (m.emissiveRef.info.x >= 0) emissive *= sampleRef(m.emissiveRef, vUv0, vUv1, grads).rgb;

    vec3 baseColor = s.albedo.rgb * vColor.rgb;
    float metallic = clamp(s.metallic, 0.0, 1.0);
    float cavity = clamp(s.cavity, 0.0, 1.0);
    float lightmapped = 0.0;
#ifdef VITRINE_GBUFFER_LIGHTMAP
    if ((draw.flags & FLAG_LIGHTMAP) != 0u) {
        // The baked diffuse (MUSEUM_SPEC §3): irradiance x Lambert, darkened by the cavity map the texels are
        // too coarse to see. lighting.deferred adds it instead of its ambient stand-ins.
        vec3 irradiance = textureLod(lightmapAtlas, vUv1 * draw.lightmap.xy + draw.lightmap.zw, 0.0).rgb;
        emissive += diffuseAlbedo(baseColor, metallic) * irradiance / kPi * cavity;
        lightmapped = 1.0;
    }
#endif

    outNormal = vec4(octEncode(N), vViewDepth, shininess);
    outBase = vec4(baseColor, metallic);
    // KHR_materials_specular's strength k (1 without it) as 1 - k in the spare 8-bit channel, so that 0 stays the
    // default; its colour has no room here and is left to the forward pass and the path tracers.
    float specular = clamp(materialSpecular(m, vUv0, vUv1, grads).a, 0.0, 1.0);
    outMaterial = vec4(coverage, 1.0 - specular, vColor.a, cavity);
    outVelocity = velocity;
    applyUnlit(m, outBase, outMaterial, emissive);
    // KHR_materials_clearcoat's strength and roughness packed with the lightmapped flag (gbuffer/clearcoat_pack.glsl);
    // an unlit surface has no coat.
    vec2 coat = m.optics.z > 0.5 ? vec2(0.0) : materialClearcoat(m, vUv0, vUv1, grads);
    outEmissive = vec4(emissive, packClearcoatAlpha(lightmapped > 0.5, coat));
    // KHR_materials_sheen in its own target, under the coat when there is one too; unlit has none, and a black sheen
    // is none (0, whatever its roughness).
    vec4 sheen = m.optics.z > 0.5 ? vec4(0.0) : clamp(materialSheen(m, vUv0, vUv1, grads), 0.0, 1.0);
    outSheen = hasSheen(sheen) ? sheen : vec4(0.0);
}
