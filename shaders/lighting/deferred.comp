#version 460
#extension GL_GOOGLE_include_directive : require
#include "lighting/deferred.h"
#include "common/brdf.glsl"
#include "common/octahedral.glsl"
#include "common/sh.glsl"
#include "bake/irradiance_volume.glsl"

// Deferred lighting (MUSEUM_SPEC §1, §3): Cook-Torrance GGX/Smith/Schlick + Lambert for the sun with
// cascaded PCF shadows, then the indirect light:
//   - lightmapped pixels (G-buffer emissive a = 1) carry their baked diffuse in the emissive channel;
//   - others take diffuse from bake.lightmap's irradiance volume when it is connected;
//   - without either, the open sky's SH irradiance scaled by `sky_ambient` stands in;
// indirect specular: the volume's SH radiance along the mirror direction where there is a volume (the room's
// own light, until IBL probes), else the sky blurred towards its SH by roughness. Cavity and vertex AO
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

const float kHalfMax = 60000.0; // keep the RGBA16F output finite (sun glints on mirrors)

float shadowTap(ivec2 texel, float depth) {
    ivec2 size = textureSize(in_shadow_map, 0);
    texel = clamp(texel, ivec2(0), size - 1);
    return depth <= texelFetch(in_shadow_map, texel, 0).r ? 1.0 : 0.0;
}

// Bilinear-weighted PCF: every tap compares 2x2 texels and interpolates the results; taps on a grid
// of radius u.shadow.lightDir.w texels around the point.
float sunVisibility(vec3 p, vec3 n, float viewDepth) {
    int count = int(u.shadow.params.x);
    int c = 0;
    while (c < count - 1 && viewDepth > u.shadow.splits[c]) ++c;
    if (viewDepth > u.shadow.splits[count - 1]) return 1.0;
    vec3 offsetP = p + n * u.shadow.params.w * u.shadow.texelWorld[c];
    vec4 s = u.shadow.worldToShadow[c] * vec4(offsetP, 1.0);
    float atlas = u.shadow.params.y;
    vec2 st = s.xy * atlas - 0.5;
    float depth = s.z;
    int r = int(ceil(u.shadow.lightDir.w));
    float sum = 0.0, weight = 0.0;
    for (int y = -r; y <= r; ++y)
        for (int x = -r; x <= r; ++x) {
            vec2 q = st + vec2(x, y);
            ivec2 base = ivec2(floor(q));
            vec2 f = q - vec2(base);
            float a = mix(shadowTap(base, depth), shadowTap(base + ivec2(1, 0), depth), f.x);
            float b = mix(shadowTap(base + ivec2(0, 1), depth), shadowTap(base + ivec2(1, 1), depth), f.x);
            sum += mix(a, b, f.y);
            weight += 1.0;
        }
    return sum / weight;
}

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
        return;
    }

    vec4 g0 = texelFetch(in_normal, p, 0);
    vec4 g1 = texelFetch(in_base_color, p, 0);
    vec4 g2 = texelFetch(in_material, p, 0);
    vec4 emissiveLm = texelFetch(in_emissive, p, 0);
    vec3 emissive = emissiveLm.rgb;
    bool lightmapped = emissiveLm.a > 0.5;
    vec3 n = octDecode(g0.xy);
    float viewDepth = g0.z;
    float roughness = roughnessFromShininess(g0.w);
    vec3 baseColor = g1.rgb;
    float metallic = g1.a;
    float vertexAo = g2.z;
    float cavity = g2.w;

    vec3 sh[9];
    for (int i = 0; i < 9; ++i) sh[i] = texelFetch(in_sky_sh, ivec2(i, 0), 0).rgb;
    vec3 sunE = texelFetch(in_sky_sh, ivec2(9, 0), 0).rgb * u.params.z; // lux, perpendicular to the sun
    vec3 l = normalize(texelFetch(in_sky_sh, ivec2(10, 0), 0).xyz);

    // Sun: E / pi is the light's intensity in the pi convention of brdf.glsl.
    float visibility = u.params.y > 0.5 ? sunVisibility(world, n, viewDepth) : 1.0;
    vec3 direct = shadeDirectional(n, v, l, baseColor, metallic, roughness, sunE / kPi) * visibility * cavity;

    // Indirect light: baked (lightmap in the emissive channel, or the irradiance volume), else the sky's SH
    // irradiance and the sky along the mirror direction blurred towards its SH radiance with roughness, both
    // scaled by the stand-in occlusion.
    float NoV = clamp(dot(n, v), 1e-4, 1.0);
    vec3 r = reflect(-v, n);
    vec3 volume[9];
    bool baked = volumeSh(in_volume, u.volumeOrigin, u.volumeCounts.xyz, world, n, volume);
    float occlusion = baked ? vertexAo * cavity : u.params.x * vertexAo * cavity;
    vec3 diffuse = vec3(0.0);
    if (!lightmapped)
        diffuse = diffuseAlbedo(baseColor, metallic) * max(shIrradiance(baked ? volume : sh, n), vec3(0.0)) / kPi * occlusion;
    vec3 skyR = baked ? max(shRadiance(volume, r), vec3(0.0))
                      : mix(textureLod(in_sky, r, 0.0).rgb, max(shRadiance(sh, r), vec3(0.0)), clamp(roughness * 2.0, 0.0, 1.0));
    // Karis' analytic fit of the split-sum environment BRDF (mobile approximation).
    vec4 c0 = vec4(-1.0, -0.0275, -0.572, 0.022);
    vec4 c1 = vec4(1.0, 0.0425, 1.04, -0.04);
    vec4 rr = roughness * c0 + c1;
    float a004 = min(rr.x * rr.x, exp2(-9.28 * NoV)) * rr.x + rr.y;
    vec2 ab = vec2(-1.04, 1.04) * a004 + rr.zw;
    vec3 specular = (specularF0(baseColor, metallic) * ab.x + ab.y) * min(skyR, vec3(kHalfMax)) * occlusion;

    vec3 color = direct + diffuse + specular + emissive * u.params.w;
    imageStore(out_color, p, vec4(min(color, vec3(kHalfMax)), 1.0));
    imageStore(out_specular_indirect, p, vec4(min(specular, vec3(kHalfMax)), 1.0));
}
