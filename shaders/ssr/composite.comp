#version 460
#extension GL_GOOGLE_include_directive : require
#include "ssr/composite.h"
#include "common/brdf.glsl"
#include "common/octahedral.glsl"
#include "lighting/ambient.glsl"
#include "ibl/ibl_common.glsl"

// SSR composite (MUSEUM_SPEC §5 step 3): the lit colour carries the indirect specular I = E(f0, roughness, NoV)
// L_env occlusion (lighting.deferred's specular_indirect, E the split-sum environment BRDF); SSR brings the
// reflected radiance L_ssr with a confidence c, premultiplied (ssr.hiz writes (c L_ssr, c), so its bilinear
// upsampling here and the temporal mean before are linear, and a neighbour that found nothing does not darken L_ssr).
// The BRDF factor E that weighs I weighs it too: the split-sum LUT's f0 A + f90 B where I comes from ibl.localized
// (brdf_lut connected: the LUT the probes were weighed with), else Karis' fit, as lighting.deferred weighs the sky.
// S also carries the surface's own micro-occlusion (vertex AO, cavity; not the sky stand-in's, SSR sees the real
// surroundings):
//   S = E L_ssr vertexAo cavity,   final = color - I + mix(I, S, c) = color - I + I (1 - c) + E (c L_ssr) vertexAo cavity.
// The term that replaced I, mix(I, S, c), is written alone too (specular_indirect: the twin of reference.reflections).
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0) uniform sampler2D in_color;
layout(binding = 1) uniform sampler2D in_specular_indirect;
layout(binding = 2) uniform sampler2D in_reflection;
layout(binding = 3) uniform sampler2D in_normal;
layout(binding = 4) uniform sampler2D in_base_color;
layout(binding = 5) uniform sampler2D in_material;
layout(binding = 6) uniform sampler2D in_depth;
layout(binding = 7) writeonly uniform image2D out_color;
layout(binding = 8) uniform Uniforms { SsrCompositeUniforms u; };
layout(binding = 9) writeonly uniform image2D out_specular_indirect;
layout(binding = 10) uniform sampler2D in_brdf_lut;

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = imageSize(out_color);
    if (any(greaterThanEqual(p, size))) return;
    vec4 color = texelFetch(in_color, p, 0);
    float z = texelFetch(in_depth, p, 0).r;
    if (z <= 0.0) {
        imageStore(out_color, p, color);
        imageStore(out_specular_indirect, p, vec4(0.0));
        return;
    }
    vec2 uv = (vec2(p) + 0.5) / vec2(size);
    // ssr.hiz's pixel q stands for full-resolution pixel q * scale: sample where this pixel falls among them.
    vec2 ssrSize = vec2(textureSize(in_reflection, 0));
    vec4 ssr = textureLod(in_reflection, (vec2(p) * ssrSize / vec2(size) + 0.5) / ssrSize, 0.0);
    vec4 wh = u.invViewProj * vec4(uv * 2.0 - 1.0, z, 1.0);
    vec3 v = normalize(u.cameraPos.xyz - wh.xyz / wh.w);
    vec4 g0 = texelFetch(in_normal, p, 0);
    vec4 g1 = texelFetch(in_base_color, p, 0);
    vec4 g2 = texelFetch(in_material, p, 0);
    vec3 n = octDecode(g0.xy);
    float NoV = clamp(dot(n, v), 1e-4, 1.0);
    vec4 dielectric = dielectricSpecular(0.04, vec4(vec3(1.0), 1.0 - g2.y)); // KHR_materials_specular, as deferred
    vec3 f0 = specularF0With(g1.rgb, g1.a, 0.04, dielectric);
    float f90 = specularF90(g1.a, dielectric), roughness = roughnessFromShininess(g0.w);
    vec3 brdf;
    if (u.config.x != 0u) {
        vec2 ab = texture(in_brdf_lut, iblLutUv(NoV, roughness, vec2(textureSize(in_brdf_lut, 0)))).rg;
        brdf = f0 * ab.x + f90 * ab.y;
    } else {
        brdf = environmentBrdfF90(f0, f90, roughness, NoV);
    }
#ifdef VITRINE_MULTISCATTER_ENVIRONMENT
    brdf *= ggxMultiscatter(f0, NoV, ggxAlpha(roughness)); // the lobe's multiple scattering (`multiscatter`)
#endif
    vec3 indirect = texelFetch(in_specular_indirect, p, 0).rgb;
    float c = clamp(ssr.a, 0.0, 1.0);
    vec3 specular = indirect * (1.0 - c) + brdf * ssr.rgb * (g2.z * g2.w); // the term alone
    vec3 final = color.rgb - indirect + specular;
    imageStore(out_specular_indirect, p, vec4(min(max(specular, vec3(0.0)), vec3(kHalfMax)), 1.0));
    imageStore(out_color, p, vec4(min(max(final, vec3(0.0)), vec3(kHalfMax)), color.a));
}
