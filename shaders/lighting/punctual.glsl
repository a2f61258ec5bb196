// KHR_lights_punctual point and spot lights (unshadowed), for lighting.deferred and forward.transparent:
// inverse-square falloff with glTF's range window and the spot's angular attenuation, through brdfCosine.
#ifndef LIGHTING_PUNCTUAL_GLSL
#define LIGHTING_PUNCTUAL_GLSL
#include "common/brdf.glsl"
#include "lighting/lights.h"
#ifndef VITRINE_LIGHTS
#error "define VITRINE_LIGHTS (the PunctualLights to shade with) before including lighting/punctual.glsl"
#endif

// The illuminance (lux, rgb) light L gives at p on a surface facing it, and the unit direction to it.
vec3 punctualIlluminance(PunctualLightGpu L, vec3 p, out vec3 toLight) {
    vec3 d = L.position.xyz - p;
    float d2 = max(dot(d, d), 1e-8);
    toLight = d * inversesqrt(d2);
    float window = clamp(1.0 - d2 * d2 * L.position.w * L.position.w, 0.0, 1.0);
    float falloff = window * window / d2;
    if (L.direction.w > 0.5) {
        float cd = dot(L.direction.xyz, -toLight);
        float a = clamp(cd * L.cone.x + L.cone.y, 0.0, 1.0);
        falloff *= a * a;
    }
    return L.intensity.rgb * falloff;
}

// Radiance (cd/m²) at p from every light: brdfCosine × E, the π convention of brdf.glsl (intensity E / π).
// VITRINE_LIGHTS names the shader's PunctualLights (a uniform member; not copied into an argument).
// f90: Schlick's reflectance at grazing incidence (1 but where KHR_materials_specular lowers it).
vec3 shadePunctual(vec3 p, vec3 n, vec3 v, vec3 diffuseColor, vec3 f0, float f90, float roughness) {
    vec3 sum = vec3(0.0);
    for (uint i = 0u; i < VITRINE_LIGHTS.count.x; ++i) {
        vec3 l;
        vec3 e = punctualIlluminance(VITRINE_LIGHTS.lights[i], p, l);
        sum += brdfCosineF0F90(n, v, l, diffuseColor, f0, f90, roughness) * e;
    }
    return sum;
}

// The clear coat's share of every light (KHR_materials_clearcoat): its lobe about the coat normal nc, without the
// coat's strength (common/brdf.glsl clearcoatSpecularCosine).
vec3 shadePunctualClearcoat(vec3 p, vec3 nc, vec3 v, float roughness) {
    vec3 sum = vec3(0.0);
    for (uint i = 0u; i < VITRINE_LIGHTS.count.x; ++i) {
        vec3 l;
        vec3 e = punctualIlluminance(VITRINE_LIGHTS.lights[i], p, l);
        sum += clearcoatSpecularCosine(nc, v, l, roughness) * e;
    }
    return sum;
}

// The sheen's share of every light (KHR_materials_sheen): its lobe about n, colour included, without the base's
// scaling (common/brdf.glsl sheenCosine).
vec3 shadePunctualSheen(vec3 p, vec3 n, vec3 v, vec4 sheen) {
    vec3 sum = vec3(0.0);
    for (uint i = 0u; i < VITRINE_LIGHTS.count.x; ++i) {
        vec3 l;
        vec3 e = punctualIlluminance(VITRINE_LIGHTS.lights[i], p, l);
        sum += sheenCosine(n, v, l, sheen.rgb, sheen.a) * e;
    }
    return sum;
}

#endif
