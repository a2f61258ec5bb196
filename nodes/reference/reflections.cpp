// reference.reflections: the specular indirect term by tracing the GGX lobe (the twin of ssr.hiz + ssr.composite +
// ibl.localized).
//
// The term: at the pixel's primary surface (normal n, view v), the light reflected by the GGX/Smith/Schlick lobe
// of core/shading's BRDF from everything but the sun's disk,
//     S = cavity * integral over l of L_i(l) f_spec(v, l) (n.l) dl,
// L_i the radiance arriving along l as render.pathtrace estimates it (CpuRays::radiance: the sky, emitters, and
// every surface lit by sun, sky and emitters over max_bounces). The sun's specular highlight is the direct term
// (lighting.deferred's shadowed sun and render.pathtrace's next-event estimation), not this one. The cavity
// multiplies everything a surface reflects in render.pathtrace and lighting.deferred alike, so it is part of S.
//
// The real-time chain's term (ssr.composite's `specular_indirect` output, what it adds to the lit colour):
//     mix(I, E(f0, roughness, NoV) L_ssr vertexAO cavity, c),   I = L_probe (f0 A + B) vertexAO cavity ao_tint
// with E Karis' split-sum fit, (A, B) ibl.capture's LUT, L_probe ibl.localized's prefiltered probe radiance,
// ao_tint lighting.deferred's lerp(baseColor, 1, ao.alchemy). The vertex AO and screen-space AO are stand-ins for
// the occlusion that the traced L_i carries itself, so S has neither.
//
// Estimator: l = reflect(-v, h) with h drawn from the GGX distribution of visible normals (pdf D G1(v) / (4 NoV)),
// weight f_spec (n.l) / pdf = F G2 / G1(v) evaluated as core/shading's brdfCosineF0 (diffuse 0) over the pdf.
#include "nodes/reference/twin.hpp"
#include "core/graph/registry.hpp"
#include "core/shading/brdf.hpp"

#include <limits>

namespace vitrine {
namespace {

using namespace shading;

TwinSchema twin() {
    TwinSchema t;
    t.type = "reference.reflections";
    t.doc = "Ray-traced twin of ssr.hiz + ssr.composite + ibl.localized: the specular indirect term at each pixel's "
            "surface, cavity x the integral of L_i f_spec cos over the GGX lobe (core/shading's BRDF, sampled by "
            "visible normals, weight F G2 / G1), L_i render.pathtrace's estimate of the light arriving along the "
            "sampled ray (sky, emitters, every bounce; the sun's disk is the direct term's). The same quantity as "
            "ssr.composite's specular_indirect but for the vertex AO and screen-space AO, which are stand-ins for the "
            "occlusion the traced rays see.";
    t.colorDoc = "Specular indirect radiance (cd/m², rgb) at each pixel's primary surface; 0 where the camera ray "
                 "meets no surface; a = 1";
    t.what = "tracing reflections";
    t.version = 1;
    return t;
}

class Reflections final : public TwinNode {
public:
    Reflections() : TwinNode(twin()) {}

protected:
    glm::vec3 sample(const CpuRays& rays, int x, int y, uint32_t& rng) const override {
        glm::vec3 o, d;
        rays.cameraRay(x, y, primaryJitter(rng), o, d);
        CpuSurface s;
        if (!rays.intersect(o, d, std::numeric_limits<float>::infinity(), s)) return glm::vec3(0.0f);
        const glm::vec3 v = -d, n = s.normal, ng = s.geometricNormal;
        const float NoV = glm::dot(n, v);
        if (NoV <= 0.0f || s.cavity <= 0.0f) return glm::vec3(0.0f);
        const glm::vec3 f0 = specularF0With(s.baseColor, s.metallic, 0.04f, s.dielectric);
        const float f90 = specularF90(s.metallic, s.dielectric);
        const float alpha = ggxAlpha(s.roughness);
        const glm::mat3 frame = cpu_sampling::basisAround(n);
        const glm::vec3 h = frame * cpu_sampling::sampleGgxVndf(glm::transpose(frame) * v, alpha, CpuRays::next2(rng));
        const glm::vec3 l = glm::reflect(-v, h);
        // The path tracer's rule: no light from below the geometric surface.
        if (glm::dot(n, l) <= 0.0f || glm::dot(ng, l) <= 0.0f) return glm::vec3(0.0f);
        const float pdf = cpu_sampling::ggxVndfPdf(NoV, glm::clamp(glm::dot(n, h), 0.0f, 1.0f), alpha);
        if (!(pdf > 0.0f)) return glm::vec3(0.0f);
        const glm::vec3 weight = brdfCosineF0F90(n, v, l, glm::vec3(0.0f), f0, f90, s.roughness, multiscatter()) / pdf;
        return s.cavity * weight * rays.radiance(CpuRays::offset(s.position, ng, l), l, rng);
    }
};

const NodeRegistration kRegistration(twinSchema(twin()), [] { return std::make_unique<Reflections>(); });

} // namespace
} // namespace vitrine
