// reference.diffuse_indirect: the indirect diffuse term by path tracing (the twin of bake.lightmap's lightmaps and
// irradiance volume, and of ibl.localized's diffuse where neither reaches).
//
// The term: at the pixel's primary surface (shading normal n), the irradiance from everything but the sun's direct
// light,
//     E = integral over the hemisphere of L_i(l) (n.l) dl   (lux),
// L_i the radiance arriving along l as render.pathtrace estimates it (CpuRays::radiance: the sky, emitters, and
// every surface lit by sun, sky and emitters over max_bounces). That is what bake.lightmap stores per texel and per
// probe ("sky, emitters and every bounce of sun, sky and emitters ... the sun's direct light is left to the frame's
// shadowed sun"). The sun is a delta light reached only by next-event estimation, so leaving out next-event
// estimation at the first surface leaves out exactly its direct light.
//
// The radiance it adds to the pixel (output `radiance`, the default) is the Lambert term of core/shading's BRDF,
//     D = cavity diffuseAlbedo(baseColor, metallic) E / pi,
// the same expression gbuffer.layered writes for lightmapped pixels (diffuseAlbedo irradiance / pi cavity, in the
// emissive channel) and lighting.deferred for the irradiance volume (x vertex AO x cavity); its `diffuse_indirect`
// output is that term (with ao.alchemy's tint, and a lightmapped surface's own emission, when there is any). The
// vertex AO and screen-space AO are stand-ins for the occlusion the traced rays see, so D has neither.
//
// Estimator: l drawn by the cosine (pdf n.l / pi): E = pi L_i(l), D = cavity diffuseAlbedo L_i(l).
#include "nodes/reference/twin.hpp"
#include "core/graph/registry.hpp"
#include "core/shading/brdf.hpp"

#include <limits>

namespace vitrine {
namespace {

using namespace shading;

TwinSchema twin() {
    TwinSchema t;
    t.type = "reference.diffuse_indirect";
    t.doc = "Ray-traced twin of bake.lightmap's lightmaps and irradiance volume: the indirect diffuse term at each "
            "pixel's surface, from the irradiance E by cosine-weighted rays, L_i render.pathtrace's estimate of the "
            "light arriving along each ray (sky, emitters, every bounce of sun, sky and emitters; the sun's direct "
            "light is left out, as the bake leaves it to the shadowed sun). Output `radiance`: cavity x "
            "diffuseAlbedo x E / pi (what lighting.deferred's diffuse_indirect holds, but for vertex AO and "
            "screen-space AO, which are stand-ins for the occlusion the traced rays see); `irradiance`: E (lux).";
    t.colorDoc = "The indirect diffuse radiance (cd/m², rgb; output radiance) or irradiance (lux; output "
                 "irradiance) at each pixel's primary surface; 0 where the camera ray meets no surface; a = 1";
    t.what = "tracing indirect diffuse";
    t.version = 1;
    return t;
}

NodeSchema schema() {
    NodeSchema s = twinSchema(twin());
    s.params.push_back({"output",
                        ParamType::Enum,
                        "radiance",
                        {},
                        {},
                        {"radiance", "irradiance"},
                        "radiance: the diffuse radiance the term adds to the pixel (cavity diffuseAlbedo E / pi, "
                        "cd/m²); irradiance: E itself (lux, what bake.lightmap stores)"});
    return s;
}

class DiffuseIndirect final : public TwinNode {
public:
    DiffuseIndirect() : TwinNode(twin()) {}

protected:
    void readParams(const Params& p) override { mIrradiance = p.getString("output") == "irradiance"; }
    void hashParams(scene::Hasher& h, const Params& p) const override { h.string(p.getString("output")); }

    glm::vec3 sample(const CpuRays& rays, int x, int y, uint32_t& rng) const override {
        glm::vec3 o, d;
        rays.cameraRay(x, y, primaryJitter(rng), o, d);
        CpuSurface s;
        if (!rays.intersect(o, d, std::numeric_limits<float>::infinity(), s)) return glm::vec3(0.0f);
        const glm::vec3 n = s.normal, ng = s.geometricNormal;
        const glm::vec3 l = cpu_sampling::basisAround(n) * cpu_sampling::sampleCosine(CpuRays::next2(rng));
        // The path tracer's rule: no light from below the geometric surface.
        if (glm::dot(ng, l) <= 0.0f) return glm::vec3(0.0f);
        const glm::vec3 L = rays.radiance(CpuRays::offset(s.position, ng, l), l, rng);
        if (mIrradiance) return kPi * L;
        // f cos / pdf of the Lambert lobe = diffuseAlbedo (1 / pi) (n.l) / ((n.l) / pi).
        return s.cavity * diffuseAlbedo(s.baseColor, s.metallic) * (lambertDiffuse() * kPi) * L;
    }

private:
    bool mIrradiance = false;
};

const NodeRegistration kRegistration(schema(), [] { return std::make_unique<DiffuseIndirect>(); });

} // namespace
} // namespace vitrine
