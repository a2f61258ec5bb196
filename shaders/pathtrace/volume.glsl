// KHR_materials_volume in render.pathtrace: a transmissive material with a thicknessFactor > 0 is the boundary of a
// closed volume (the extension asks for a closed mesh), and the path tracer refracts at its real surfaces instead of
// reading the thickness as forward.transparent does: into the volume through the front face, out of it through the
// back face (which is then never culled), with Beer's law attenuationColor^(d / attenuationDistance) over the
// distance d the path travels inside. Rough boundaries scatter by GGX microfacets on both crossings, so what is seen
// through rough thick glass is blurred by the geometry the light really crosses.
//
// nodes/render/pathtrace_cpu.cpp crossBoundary is the CPU twin, line for line.
#ifndef PATHTRACE_VOLUME_GLSL
#define PATHTRACE_VOLUME_GLSL
#extension GL_GOOGLE_include_directive : require
#include "pathtrace/sampling.glsl"

// G2(v, l) / G1(v) of height-correlated Smith GGX, l on either side of n (cosines as absolute values): the weight of
// a direction through a microfacet drawn from v's visible normals (Heitz 2018), reflected or refracted.
float ggxMaskingRatio(float NoV, float NoL, float alpha) {
    float a2 = alpha * alpha;
    float lv = sqrt(a2 + (1.0 - a2) * NoV * NoV), ll = sqrt(a2 + (1.0 - a2) * NoL * NoL);
    return NoL * (NoV + lv) / max(NoL * lv + NoV * ll, 1e-12);
}

// A direction across a rough dielectric boundary seen from v (n the shading normal, ng the geometric one, both on v's
// side), eta the IOR on v's side over the IOR on the far side. The microfacet h is drawn from v's visible normals;
// the path goes through h by Snell's law, or is reflected by h where no light crosses it (total internal reflection)
// or, with `fresnel`, with the probability P of Schlick's F (f0, f90 of `dielectric`) taken at the cosine on the
// boundary's outer side (the rarer medium), so that a crossing and its reverse see the same F. weight: G2 / G1(v),
// times F / P or (1 - F) / (1 - P) with `fresnel`. across: the path crossed. False when l ends on the wrong side of
// the geometric normal (the path ends there).
bool crossBoundary(vec3 n, vec3 ng, vec3 v, float roughness, vec4 dielectric, float eta, bool fresnel, vec3 u,
                   out vec3 l, out vec3 weight, out bool across) {
    float alpha = ggxAlpha(roughness);
    mat3 frame = basisAround(n);
    vec3 h = frame * sampleGgxVndf(transpose(frame) * v, alpha, u.yz);
    float VoH = clamp(dot(v, h), 0.0, 1.0);
    float sin2T = eta * eta * (1.0 - VoH * VoH);
    across = sin2T < 1.0;
    weight = vec3(1.0);
    if (across && fresnel) {
        vec3 F = schlickFresnelF90(dielectric.rgb, dielectric.a, eta < 1.0 ? VoH : sqrt(1.0 - sin2T));
        float p = clamp(luminance(F), 1e-3, 1.0 - 1e-3);
        across = u.x >= p;
        weight = across ? (vec3(1.0) - F) / (1.0 - p) : F / p;
    }
    l = across ? refract(-v, h, eta) : reflect(-v, h);
    float side = dot(ng, l);
    if (across ? side >= 0.0 : side <= 0.0) return false;
    weight *= ggxMaskingRatio(clamp(dot(n, v), 1e-4, 1.0), abs(dot(n, l)), alpha);
    return true;
}

#endif
