// lighting.deferred term by term against core/shading's CPU maths: the sun's specular at grazing
// half-vector angles (where Schlick's Fresnel is far from F0), and, under a uniform coloured sky, the
// indirect specular (split-sum fit), the diffuse ambient with vertex AO and cavity, and the emissive
// channel, each compared with its own CPU value; under a sky with band-3 detail, the sky fallback's blur towards
// its SH with roughness; lit by a made-up linear irradiance volume, where the volume is looked up (a quarter of a
// cell in front of the surface). Tolerances are absolute or relative to the CPU value, never to what the GPU
// produced.
#include "tests/gpu/lighting_scene.hpp"

#include "core/graph/node.hpp"
#include "core/graph/registry.hpp"
#include "core/image/io.hpp"
#include "nodes/bake/baked_lighting.hpp"
#include "core/shading/brdf.hpp"
#include "core/shading/environment.hpp"
#include "core/shading/sh.hpp"
#include "shaders/sky/sky.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace vitrine::test {
namespace {

using nlohmann::json;
using namespace lighting;

class LightingTerms : public GpuTest {};

// A flat black dielectric ground lit by a sun 12° above the horizon in front of the camera: the glare
// between camera and sun is the sun's mirror reflection, where VoH = sin((view elevation + 12°) / 2),
// about 0.2 at its centre. Black base colour leaves the specular lobe alone, so each pixel is
// D V F E NoL with F = Schlick's at VoH; Schlick's exponent 4 instead of 5 makes F 22-34 % larger at
// VoH 0.2-0.3, no Fresnel (F = F0) 80 % smaller. The plane's normal is exact in the G-buffer and the
// output is RGBA16F, so the measured error is ~3e-3: the bound is 2 % of the CPU value. The ground's
// cavity (0.6) darkens the sun as well as the ambient (MUSEUM_SPEC §1), so the sun term carries it.
TEST_F(LightingTerms, GrazingSunSpecularFollowsCpuSchlickFresnel) {
    const int W = 64, H = 64;
    const float shininess = 0.55f, cavity = 0.6f; // 153 / 255: exact in the UNORM8 G-buffer
    const double sunElevation = 12.0 * kPi / 180.0;
    // sun_scale keeps the glare (~14000 cd/m² after scaling and cavity) inside RGBA16F and the shader's clamp.
    const double sunScale = 0.1;
    const float groundHalf = 40.0f;

    SceneBuilder b("grazing");
    std::vector<Tri> quad;
    addQuad(quad, glm::vec3(0.0f), glm::vec3(groundHalf, 0, 0), glm::vec3(0, 0, groundHalf), glm::vec3(0, 1, 0));
    uint32_t black = b.material("black", glm::vec3(0.0f), 0.0f, shininess);
    b.s.materials[black].layers[0].cavity = {cavity, 0.0f};
    b.node("ground", static_cast<int32_t>(b.mesh("ground", quad, black)));
    b.camera({0.0f, 1.0f, 0.0f}, {0.0f, 0.0f, -4.7f}, 0.8f);
    b.sun({0.0f, static_cast<float>(std::sin(sunElevation)), static_cast<float>(-std::cos(sunElevation))});
    auto glb = b.write();

    json nodes = baseNodes(glb);
    nodes["direct"] = lightingNode({{"sky_ambient", 0.0}, {"sun_scale", sunScale}}, false);
    auto out = runGraph(graph(nodes, {{"direct", "direct.color"}, {"sh", "sky.sh"}}, W, H));
    const Image& direct = out.at("direct");
    const glm::dvec3 l = glm::normalize(rgb(out.at("sh"), SKY_TEXEL_SUN_DIRECTION, 0));
    const glm::dvec3 sunE = rgb(out.at("sh"), SKY_TEXEL_SUN_ILLUMINANCE, 0) * sunScale;
    ASSERT_GT(sunE.g, 100.0);

    Pinhole cam(b.s, W, H);
    int checked = 0, grazing = 0;
    double worst = 0.0, worstGrazing = 0.0, minVoH = 1.0, brightest = 0.0;
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            glm::dvec3 d = cam.ray(x, y);
            if (d.y >= 0.0) continue;
            glm::dvec3 p = cam.position - cam.position.y / d.y * d;
            if (std::abs(p.x) > groundHalf - 1.0 || std::abs(p.z) > groundHalf - 1.0) continue; // sky beyond
            glm::dvec3 v = -d;
            glm::dvec3 expected = cpuSun({0, 1, 0}, v, l, glm::vec3(0.0f), 0.0f, shininess, sunE) * double(cavity);
            // Only where the lobe is bright enough for half precision to be far below the bound.
            if (expected.g < 1.0) continue;
            ++checked;
            glm::dvec3 got = rgb(direct, x, y);
            double e = relErr(got, expected);
            worst = std::max(worst, e);
            brightest = std::max(brightest, got.r);
            double voH = glm::dot(v, glm::normalize(v + l));
            if (voH <= 0.3) {
                ++grazing;
                minVoH = std::min(minVoH, voH);
                worstGrazing = std::max(worstGrazing, e);
            }
            EXPECT_LT(e, 0.02) << "pixel " << x << "," << y << " VoH " << voH << ": " << got.g << " vs " << expected.g;
        }
    std::printf("grazing sun: %d of %d ground pixels with VoH <= 0.3 (min %.3f, max relative error %.2g), all of "
                "them max relative error %.2g, brightest %.0f cd/m2\n",
                grazing, checked, minVoH, worstGrazing, worst, brightest);
    EXPECT_GE(grazing, 300);
    EXPECT_LT(minVoH, 0.22);
    EXPECT_LT(brightest, 40000.0); // nothing measured is near the shader's clamp
}

// The same glare on a ground with KHR_materials_specular strength k = 0.4 (G-buffer material.y = 0.6 = 153/255,
// exact): by the extension's closed form a black dielectric's specular is k x (F0 + (1 - F0)(1 - VoH)^5) D V with
// F0 = 0.04, i.e. k times the plain ground's, at every angle, so the expected value is 0.4 x the CPU value without the
// extension. Lowering F90 matters most at grazing VoH: F90 left at 1 would be 2.4x brighter there, k on F0 only
// ~10 % brighter; the bound is 2 % as above.
TEST_F(LightingTerms, SpecularExtensionStrengthScalesTheGrazingSunSpecular) {
    const int W = 64, H = 64;
    const float shininess = 0.55f, k = 0.4f;
    const double sunElevation = 12.0 * kPi / 180.0;
    const double sunScale = 0.1;
    const float groundHalf = 40.0f;

    SceneBuilder b("grazing_specular");
    std::vector<Tri> quad;
    addQuad(quad, glm::vec3(0.0f), glm::vec3(groundHalf, 0, 0), glm::vec3(0, 0, groundHalf), glm::vec3(0, 1, 0));
    uint32_t black = b.material("black", glm::vec3(0.0f), 0.0f, shininess);
    b.s.materials[black].specular = k; // written into the .glb as KHR_materials_specular and read back
    b.node("ground", static_cast<int32_t>(b.mesh("ground", quad, black)));
    b.camera({0.0f, 1.0f, 0.0f}, {0.0f, 0.0f, -4.7f}, 0.8f);
    b.sun({0.0f, static_cast<float>(std::sin(sunElevation)), static_cast<float>(-std::cos(sunElevation))});
    auto glb = b.write();

    json nodes = baseNodes(glb);
    nodes["direct"] = lightingNode({{"sky_ambient", 0.0}, {"sun_scale", sunScale}}, false);
    auto out = runGraph(graph(nodes, {{"direct", "direct.color"}, {"sh", "sky.sh"}}, W, H));
    const Image& direct = out.at("direct");
    const glm::dvec3 l = glm::normalize(rgb(out.at("sh"), SKY_TEXEL_SUN_DIRECTION, 0));
    const glm::dvec3 sunE = rgb(out.at("sh"), SKY_TEXEL_SUN_ILLUMINANCE, 0) * sunScale;

    Pinhole cam(b.s, W, H);
    int checked = 0, grazing = 0;
    double worst = 0.0;
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            glm::dvec3 d = cam.ray(x, y);
            if (d.y >= 0.0) continue;
            glm::dvec3 p = cam.position - cam.position.y / d.y * d;
            if (std::abs(p.x) > groundHalf - 1.0 || std::abs(p.z) > groundHalf - 1.0) continue;
            glm::dvec3 v = -d;
            glm::dvec3 expected = double(k) * cpuSun({0, 1, 0}, v, l, glm::vec3(0.0f), 0.0f, shininess, sunE);
            if (expected.g < 1.0) continue;
            ++checked;
            glm::dvec3 got = rgb(direct, x, y);
            double e = relErr(got, expected);
            worst = std::max(worst, e);
            if (glm::dot(v, glm::normalize(v + l)) <= 0.3) ++grazing;
            EXPECT_LT(e, 0.02) << "pixel " << x << "," << y << ": " << got.g << " vs " << expected.g;
        }
    std::printf("KHR_materials_specular k = 0.4 glare: %d pixels (%d with VoH <= 0.3), max relative error %.2g\n",
                checked, grazing, worst);
    EXPECT_GE(grazing, 200);
}

// KHR_materials_clearcoat in lighting.deferred: the grazing-sun ground again, black and rough (shininess 0.55) under a
// full coat (c = 1) of roughness 16/31, a value the G-buffer's 5-bit packing keeps exactly. Expected: core/shading's
// brdfCosineClearcoat (checked against the Khronos layering in shading.Brdf.ClearcoatMatchesTheKhronosLayering) x E,
// the coat's normal being the base's (the deferred path's limitation; a flat plane here, so no difference). The coat's
// smoother lobe makes a glare several times the base's, and at grazing incidence Fc(n.v) dims the base: the bound is
// 2 % as above, and the coat must matter (the uncoated ground is > 2x off somewhere).
TEST_F(LightingTerms, ClearcoatGroundMatchesTheCpuLayering) {
    const int W = 64, H = 64;
    const float shininess = 0.55f, coatRoughness = 16.0f / 31.0f;
    const double sunElevation = 12.0 * kPi / 180.0;
    const double sunScale = 0.1;
    const float groundHalf = 40.0f;

    SceneBuilder b("grazing_clearcoat");
    std::vector<Tri> quad;
    addQuad(quad, glm::vec3(0.0f), glm::vec3(groundHalf, 0, 0), glm::vec3(0, 0, groundHalf), glm::vec3(0, 1, 0));
    uint32_t black = b.material("black", glm::vec3(0.0f), 0.0f, shininess);
    b.s.materials[black].clearcoat = 1.0f; // written into the .glb as KHR_materials_clearcoat and read back
    b.s.materials[black].clearcoatRoughness = coatRoughness;
    b.node("ground", static_cast<int32_t>(b.mesh("ground", quad, black)));
    b.camera({0.0f, 1.0f, 0.0f}, {0.0f, 0.0f, -4.7f}, 0.8f);
    b.sun({0.0f, static_cast<float>(std::sin(sunElevation)), static_cast<float>(-std::cos(sunElevation))});
    auto glb = b.write();

    json nodes = baseNodes(glb);
    nodes["direct"] = lightingNode({{"sky_ambient", 0.0}, {"sun_scale", sunScale}}, false);
    auto out = runGraph(graph(nodes, {{"direct", "direct.color"}, {"sh", "sky.sh"}}, W, H));
    const Image& direct = out.at("direct");
    const glm::dvec3 l = glm::normalize(rgb(out.at("sh"), SKY_TEXEL_SUN_DIRECTION, 0));
    const glm::dvec3 sunE = rgb(out.at("sh"), SKY_TEXEL_SUN_ILLUMINANCE, 0) * sunScale;
    const glm::vec4 plain = shading::dielectricSpecular(0.04f, glm::vec4(1.0f));
    const float roughness = shading::roughnessFromShininess(shininess);

    Pinhole cam(b.s, W, H);
    int checked = 0;
    double worst = 0.0, coatMatters = 0.0;
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            glm::dvec3 d = cam.ray(x, y);
            if (d.y >= 0.0) continue;
            glm::dvec3 p = cam.position - cam.position.y / d.y * d;
            if (std::abs(p.x) > groundHalf - 1.0 || std::abs(p.z) > groundHalf - 1.0) continue;
            const glm::vec3 n(0, 1, 0), v(-d), lf(l);
            glm::dvec3 expected = glm::dvec3(shading::brdfCosineClearcoat(n, n, v, lf, glm::vec3(0.0f), 0.0f, roughness,
                                                                          plain, glm::vec2(1.0f, coatRoughness))) *
                                  sunE;
            if (expected.g < 1.0) continue;
            ++checked;
            glm::dvec3 got = rgb(direct, x, y);
            double e = relErr(got, expected);
            worst = std::max(worst, e);
            glm::dvec3 uncoated = cpuSun({0, 1, 0}, v, l, glm::vec3(0.0f), 0.0f, shininess, sunE);
            coatMatters = std::max(coatMatters, expected.g / std::max(uncoated.g, 1e-6));
            EXPECT_LT(e, 0.02) << "pixel " << x << "," << y << ": " << got.g << " vs " << expected.g;
        }
    std::printf("KHR_materials_clearcoat glare: %d pixels, max relative error %.2g, coated / uncoated up to %.1f\n",
                checked, worst, coatMatters);
    EXPECT_GE(checked, 300);
    EXPECT_GT(coatMatters, 2.0);
}

// KHR_materials_sheen in lighting.deferred: the grazing-sun ground of the coat test, dark grey and rough, under a
// sheen of colour (1, 128/255, 170/255) and roughness 136/255 (= 8/15), values the G-buffer's 8-bit sheen target keeps
// exactly, and, when `coat` is given, a clear coat over the sheen. Expected: core/shading's brdfCosineSheen (the lobe
// checked against the spec's formulas and its albedo table against quadrature in shading.Brdf.Sheen*, the layering in
// shading.Brdf.SheenLayeringKeepsEnergy) x E. Low sun and a camera looking along the ground: the Charlie lobe's
// grazing retro-reflection lights it several times the bare ground's. Bound 2 % as above. Returned: how much the
// sheen adds (the largest ratio to the same material without it) and how much the coat changes (with / without it).
struct SheenGround {
    int checked = 0;
    double worst = 0.0, sheenMatters = 0.0, coatMatters = 0.0;
};

SheenGround sheenGround(const char* name, glm::vec2 coat) {
    const int W = 64, H = 64;
    const float shininess = 0.3f;
    const glm::vec4 sheen(1.0f, 128.0f / 255.0f, 170.0f / 255.0f, 136.0f / 255.0f);
    const glm::vec3 base(51.0f / 255.0f);
    const double sunElevation = 12.0 * kPi / 180.0;
    const double sunScale = 0.1;
    const float groundHalf = 40.0f;

    SceneBuilder b(name);
    std::vector<Tri> quad;
    addQuad(quad, glm::vec3(0.0f), glm::vec3(groundHalf, 0, 0), glm::vec3(0, 0, groundHalf), glm::vec3(0, 1, 0));
    uint32_t m = b.material("velvet", base, 0.0f, shininess);
    b.s.materials[m].sheenColor = glm::vec3(sheen); // written into the .glb as KHR_materials_sheen and read back
    b.s.materials[m].sheenRoughness = sheen.a;
    b.s.materials[m].clearcoat = coat.x; // and KHR_materials_clearcoat where coat.x > 0
    b.s.materials[m].clearcoatRoughness = coat.y;
    b.node("ground", static_cast<int32_t>(b.mesh("ground", quad, m)));
    b.camera({0.0f, 1.0f, 0.0f}, {0.0f, 0.0f, -4.7f}, 0.8f);
    b.sun({0.0f, static_cast<float>(std::sin(sunElevation)), static_cast<float>(std::cos(sunElevation))});
    auto glb = b.write();

    json nodes = baseNodes(glb);
    nodes["direct"] = lightingNode({{"sky_ambient", 0.0}, {"sun_scale", sunScale}}, false);
    auto out = runGraph(graph(nodes, {{"direct", "direct.color"}, {"sh", "sky.sh"}}, W, H));
    const Image& direct = out.at("direct");
    const glm::dvec3 l = glm::normalize(rgb(out.at("sh"), SKY_TEXEL_SUN_DIRECTION, 0));
    const glm::dvec3 sunE = rgb(out.at("sh"), SKY_TEXEL_SUN_ILLUMINANCE, 0) * sunScale;
    const glm::vec4 plain = shading::dielectricSpecular(0.04f, glm::vec4(1.0f));
    const float roughness = shading::roughnessFromShininess(shininess);

    Pinhole cam(b.s, W, H);
    SheenGround r;
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            glm::dvec3 d = cam.ray(x, y);
            if (d.y >= 0.0) continue;
            glm::dvec3 p = cam.position - cam.position.y / d.y * d;
            if (std::abs(p.x) > groundHalf - 1.0 || std::abs(p.z) > groundHalf - 1.0) continue;
            const glm::vec3 n(0, 1, 0), v(-d), lf(l);
            auto cpu = [&](glm::vec2 c, glm::vec4 s) {
                return glm::dvec3(shading::brdfCosineSheen(n, n, v, lf, base, 0.0f, roughness, plain, c, s)) * sunE;
            };
            glm::dvec3 expected = cpu(coat, sheen);
            if (expected.g < 1.0) continue;
            ++r.checked;
            glm::dvec3 got = rgb(direct, x, y);
            double e = relErr(got, expected);
            r.worst = std::max(r.worst, e);
            r.sheenMatters = std::max(r.sheenMatters, expected.r / std::max(cpu(coat, glm::vec4(0.0f)).r, 1e-6));
            glm::dvec3 uncoated = cpu(glm::vec2(0.0f), sheen);
            r.coatMatters = std::max(r.coatMatters, std::max(expected.g / uncoated.g, uncoated.g / expected.g));
            EXPECT_LT(e, 0.02) << name << " pixel " << x << "," << y << ": " << got.r << " vs " << expected.r;
        }
    std::printf("%s: %d pixels, max relative error %.2g, with / without sheen up to %.2f, coat changes it up to "
                "%.2fx\n",
                name, r.checked, r.worst, r.sheenMatters, r.coatMatters);
    EXPECT_GE(r.checked, 300);
    return r;
}

TEST_F(LightingTerms, SheenGroundMatchesTheCpuLayering) {
    SheenGround r = sheenGround("grazing_sheen", glm::vec2(0.0f));
    EXPECT_GT(r.sheenMatters, 1.5);
}

// The same sheen under a clear coat of strength 16/31 and roughness 8/31 (values the 5-bit coat packing keeps): both
// lobes reach lighting.deferred through the G-buffer together (the sheen in its own target), layered as the path
// tracers and forward.transparent layer them. Both must matter: the sheen against the coat alone, the coat against
// the sheen alone.
TEST_F(LightingTerms, CoatOverSheenGroundMatchesTheCpuLayering) {
    SheenGround r = sheenGround("grazing_coat_over_sheen", glm::vec2(16.0f / 31.0f, 8.0f / 31.0f));
    EXPECT_GT(r.sheenMatters, 1.3);
    EXPECT_GT(r.coatMatters, 1.3);
}

// ---------------------------------------------------------------------------------------------

struct SphereMaterial {
    const char* name;
    glm::vec3 base;
    float metallic, shininess;
    float vertexAo, cavity; // multiples of 1/255, so the UNORM8 G-buffer stores them exactly
    glm::vec3 emissive;     // factor x strength, values R11G11B10 stores exactly
    glm::dvec3 centre;
};

// The sphere of `materials` (all of `radius`) that a ray from o along d meets first, or -1; t: the distance.
int nearestSphere(glm::dvec3 o, glm::dvec3 d, const SphereMaterial (&materials)[3], double radius, double& t) {
    int k = -1;
    t = 1e30;
    for (int i = 0; i < 3; ++i) {
        double ti = hitSphere(o, d, materials[i].centre, radius);
        if (ti > 0.0 && ti < t) t = ti, k = i;
    }
    return k;
}

// A uniform sky whose red is 4x its blue (an equirect .exr, no sun in it), around three spheres: a
// mirror metal (indirect specular is the cube map alone, so its colour shows directly), a rough
// dielectric with vertex AO 0.6 and cavity 0.4, and a black emitter. Under a uniform sky the cube map
// is C in every direction and the SH is C's constant term, so the CPU values are closed-form:
// indirect specular (F0 a + b) C occlusion with (a, b) from the split-sum fit, diffuse albedo C
// occlusion, emissive its G-buffer value x emissive_scale. Each is compared by itself:
// `specular_indirect` against the CPU specular, a node with sky_ambient 0 against the CPU emissive,
// and `color` against the CPU sum. Bounds, relative to the CPU value per channel: 2 % for terms that
// depend on the interpolated normal of a 96 x 48 UV sphere (measured: at most 1 %) and RGBA16F output;
// 0.5 % for the emissive, which passes through exactly representable values (measured: exact). The
// sky's red/blue ratio of 4 makes a channel swap 4x off on the mirror; AO and cavity off multiply the
// dielectric's ambient by 1.7 and 2.5.
TEST_F(LightingTerms, IndirectSpecularOcclusionAndEmissiveMatchCpuUnderColouredSky) {
    const int W = 128, H = 48;
    const double radius = 0.5, emissiveScale = 2.5, skyIntensity = 200.0;
    const glm::dvec3 skyColor = glm::dvec3(1.0, 0.5, 0.25) * skyIntensity;
    const SphereMaterial materials[] = {
        {"mirror_metal", glm::vec3(0.9f), 1.0f, 1.0f, 1.0f, 1.0f, glm::vec3(0.0f), {-1.1, 0.0, 0.0}},
        {"occluded_dielectric", glm::vec3(0.6f), 0.0f, 0.6f, 0.6f, 0.4f, glm::vec3(0.0f), {0.0, 0.0, 0.0}},
        {"emitter", glm::vec3(0.0f), 0.0f, 0.5f, 1.0f, 1.0f, glm::vec3(1.0f, 2.0f, 4.0f), {1.1, 0.0, 0.0}},
    };

    SceneBuilder b("coloured_sky");
    for (const SphereMaterial& m : materials) {
        uint32_t material = b.material(m.name, m.base, m.metallic, m.shininess);
        b.s.materials[material].layers[0].cavity = {m.cavity, 0.0f};
        // glTF's emissiveFactor is at most 1: the rest is KHR_materials_emissive_strength.
        float strength = std::max({m.emissive.x, m.emissive.y, m.emissive.z, 1.0f});
        b.s.materials[material].emissiveFactor = m.emissive / strength;
        b.s.materials[material].emissiveStrength = strength;
        std::vector<Tri> tris = sphereTris(static_cast<float>(radius), 96, 48);
        for (Tri& t : tris)
            t.a.color.a = t.b.color.a = t.c.color.a = m.vertexAo;
        b.node(m.name, static_cast<int32_t>(b.mesh(m.name, tris, material)), glm::vec3(m.centre));
    }
    b.camera({0.0f, 0.0f, 4.0f}, {0.0f, 0.0f, 0.0f}, 0.35f);
    auto glb = b.write();

    Image sky(64, 32);
    for (int y = 0; y < sky.height; ++y)
        for (int x = 0; x < sky.width; ++x) {
            float* p = sky.at(x, y);
            p[0] = 1.0f, p[1] = 0.5f, p[2] = 0.25f, p[3] = 1.0f;
        }
    const auto skyFile = glb.parent_path() / "uniform_orange_sky.exr";
    writeExr(skyFile, sky, ExrPixelType::Float);

    json nodes = baseNodes(glb);
    nodes["sky"] = {{"type", "sky.hdri"},
                    {"params", {{"path", skyFile.string()}, {"intensity", skyIntensity}, {"size", 16}}}};
    nodes["full"] = lightingNode({{"sky_ambient", 1.0}, {"emissive_scale", emissiveScale}}, false);
    nodes["emit"] = lightingNode({{"sky_ambient", 0.0}, {"emissive_scale", emissiveScale}}, false);
    auto out = runGraph(graph(
        nodes, {{"full", "full.color"}, {"spec", "full.specular_indirect"}, {"emit", "emit.color"}, {"sh", "sky.sh"}},
        W, H));
    const Image& sh = out.at("sh");
    const shading::Sh9 skySh = readSh(sh);
    // The set-up itself: no sun found in a uniform sky, and its SH is the constant C.
    ASSERT_EQ(glm::length(rgb(sh, SKY_TEXEL_SUN_ILLUMINANCE, 0)), 0.0);
    for (glm::dvec3 dir : {glm::dvec3(0, 1, 0), glm::dvec3(1, 0, 0), glm::dvec3(0, -0.6, 0.8)})
        ASSERT_LT(relErr(shading::shRadiance(skySh, dir), skyColor), 5e-3);

    Pinhole cam(b.s, W, H);
    int samples[3] = {0, 0, 0};
    double worstSpec[3] = {0, 0, 0}, worstFull[3] = {0, 0, 0}, worstEmit[3] = {0, 0, 0}, worstBackground = 0.0;
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            glm::dvec3 d = cam.ray(x, y);
            double t;
            const int k = nearestSphere(cam.position, d, materials, radius, t);
            if (k < 0) {
                // The sky seen behind the spheres is the cube map itself.
                double e = relErr(rgb(out.at("full"), x, y), skyColor);
                worstBackground = std::max(worstBackground, e);
                EXPECT_LT(e, 0.005) << "sky, pixel " << x << "," << y;
                continue;
            }
            const SphereMaterial& m = materials[k];
            glm::dvec3 n = glm::normalize(cam.position + t * d - m.centre), v = -d;
            if (glm::dot(n, v) < 0.3) continue; // away from the silhouette
            ++samples[k];

            // CPU values, with the G-buffer's storage precision applied to the material inputs.
            const glm::vec3 base = unorm8(m.base);
            // The G-buffer writes the Toksvig-widened roughness: for an unfiltered normal that only floors
            // it at sqrt(kMinGgxAlpha) = 0.045, which moves the mirror's fit by 2.5 %.
            const double roughness = shading::toksvigRoughness(shading::roughnessFromShininess(m.shininess), 1.0f);
            const double occlusion = unorm8(m.vertexAo) * unorm8(m.cavity);
            const float noV = std::clamp(static_cast<float>(glm::dot(n, v)), 1e-4f, 1.0f);
            const glm::dvec3 r = glm::reflect(-v, n);
            glm::dvec3 skyR =
                glm::mix(skyColor, glm::max(shading::shRadiance(skySh, r), 0.0), std::clamp(roughness * 2.0, 0.0, 1.0));
            glm::vec2 ab = shading::envBrdfApprox(noV, static_cast<float>(roughness));
            glm::dvec3 specular =
                (glm::dvec3(shading::specularF0(base, m.metallic)) * double(ab.x) + double(ab.y)) * skyR * occlusion;
            glm::dvec3 diffuse = glm::dvec3(shading::diffuseAlbedo(base, m.metallic)) *
                                 glm::max(shading::shIrradiance(skySh, n), 0.0) / kPi * occlusion;
            glm::dvec3 emissive = glm::dvec3(m.emissive) * emissiveScale;

            double es = relErr(rgb(out.at("spec"), x, y), specular);
            double ef = relErr(rgb(out.at("full"), x, y), specular + diffuse + emissive);
            worstSpec[k] = std::max(worstSpec[k], es);
            worstFull[k] = std::max(worstFull[k], ef);
            EXPECT_LT(es, 0.02) << m.name << " indirect specular, pixel " << x << "," << y << ": "
                                << rgb(out.at("spec"), x, y).r << " vs " << specular.r;
            EXPECT_LT(ef, 0.02) << m.name << " colour, pixel " << x << "," << y << ": " << rgb(out.at("full"), x, y).r
                                << " vs " << (specular + diffuse + emissive).r;
            // sky_ambient 0 and no sun: only the emissive is left.
            glm::dvec3 emitted = rgb(out.at("emit"), x, y);
            double ee = glm::length(emissive) > 0.0 ? relErr(emitted, emissive) : glm::length(emitted);
            worstEmit[k] = std::max(worstEmit[k], ee);
            EXPECT_LT(ee, 0.005) << m.name << " emissive, pixel " << x << "," << y << ": " << emitted.r << ","
                                 << emitted.g << "," << emitted.b;
        }
    for (int k = 0; k < 3; ++k) {
        std::printf("%s: %d pixels, indirect specular max relative error %.2g, colour %.2g, emissive alone %.2g\n",
                    materials[k].name, samples[k], worstSpec[k], worstFull[k], worstEmit[k]);
        EXPECT_GE(samples[k], 300) << materials[k].name;
    }
    std::printf("sky behind the spheres: max relative error %.2g\n", worstBackground);
}

// The sky fallback's blur: with neither volume nor probes, a surface's indirect specular is the sky cube map along
// the mirror direction blended towards the sky's SH radiance there by min(2 x roughness, 1) (ambient.glsl), a
// stand-in for the prefiltered lobe. A sky whose every channel is a cubic of one axis (1.5 + x³, 1.5 + y³,
// 1.5 + z³: a band-3 part SH9 cannot hold, up to 0.4 of 1.5) makes the two differ by up to 27 %; three metal spheres
// of roughness 0.045, 0.2 and 0.3 weigh them 0.09, 0.4 and 0.6. The cube map is compared with the analytic sky, the SH
// is sky.sh's own (read back); the bound is 2 % of the CPU value, which a blend twice as fast, or none, exceeds.
glm::dvec3 cubicSky(glm::dvec3 d) { return glm::dvec3(1.5) + d * d * d; }

TEST_F(LightingTerms, SkyFallbackBlursTowardsItsShWithRoughness) {
    const int W = 128, H = 48;
    const double radius = 0.5, skyIntensity = 100.0;
    const SphereMaterial materials[] = {
        {"mirror", glm::vec3(0.9f), 1.0f, 1.0f, 1.0f, 1.0f, glm::vec3(0.0f), {-1.1, 0.0, 0.0}},
        {"glossy", glm::vec3(0.9f), 1.0f, 0.8f, 1.0f, 1.0f, glm::vec3(0.0f), {0.0, 0.0, 0.0}},
        {"rough", glm::vec3(0.9f), 1.0f, 0.7f, 1.0f, 1.0f, glm::vec3(0.0f), {1.1, 0.0, 0.0}},
    };
    SceneBuilder b("cubic_sky");
    for (const SphereMaterial& m : materials) {
        uint32_t material = b.material(m.name, m.base, m.metallic, m.shininess);
        b.node(m.name, static_cast<int32_t>(b.mesh(m.name, sphereTris(static_cast<float>(radius), 96, 48), material)),
               glm::vec3(m.centre));
    }
    b.camera({0.0f, 0.0f, 4.0f}, {0.0f, 0.0f, 0.0f}, 0.35f);
    auto glb = b.write();

    Image sky(256, 128);
    for (int y = 0; y < sky.height; ++y)
        for (int x = 0; x < sky.width; ++x) {
            glm::dvec3 c = cubicSky(shading::equirectDirection((x + 0.5) / sky.width, (y + 0.5) / sky.height));
            float* p = sky.at(x, y);
            p[0] = float(c.r), p[1] = float(c.g), p[2] = float(c.b), p[3] = 1.0f;
        }
    const auto skyFile = glb.parent_path() / "cubic_sky.exr";
    writeExr(skyFile, sky, ExrPixelType::Float);
    json nodes = baseNodes(glb);
    nodes["sky"] = {{"type", "sky.hdri"},
                    {"params", {{"path", skyFile.string()}, {"intensity", skyIntensity}, {"size", 64}}}};
    nodes["lighting"] = lightingNode({{"sky_ambient", 1.0}}, false);
    auto out = runGraph(graph(nodes, {{"spec", "lighting.specular_indirect"}, {"sh", "sky.sh"}}, W, H));
    const shading::Sh9 skySh = readSh(out.at("sh"));
    ASSERT_EQ(glm::length(rgb(out.at("sh"), SKY_TEXEL_SUN_ILLUMINANCE, 0)), 0.0); // no sun found in it

    Pinhole cam(b.s, W, H);
    int samples[3] = {0, 0, 0};
    double worst[3] = {0, 0, 0}, unblurred[3] = {0, 0, 0};
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            glm::dvec3 d = cam.ray(x, y);
            double t;
            const int k = nearestSphere(cam.position, d, materials, radius, t);
            if (k < 0) continue;
            const SphereMaterial& m = materials[k];
            glm::dvec3 n = glm::normalize(cam.position + t * d - m.centre), v = -d;
            if (glm::dot(n, v) < 0.3) continue; // away from the silhouette
            ++samples[k];
            const double roughness = shading::toksvigRoughness(shading::roughnessFromShininess(m.shininess), 1.0f);
            const float noV = std::clamp(static_cast<float>(glm::dot(n, v)), 1e-4f, 1.0f);
            const glm::dvec3 r = glm::reflect(-v, n);
            const glm::dvec3 cube = cubicSky(r) * skyIntensity, shR = glm::max(shading::shRadiance(skySh, r), 0.0);
            const glm::vec2 ab = shading::envBrdfApprox(noV, static_cast<float>(roughness));
            const glm::dvec3 brdf = glm::dvec3(shading::specularF0(unorm8(m.base), m.metallic)) * double(ab.x) + double(ab.y);
            const glm::dvec3 expected = brdf * glm::mix(cube, shR, std::clamp(roughness * 2.0, 0.0, 1.0));
            const double e = relErr(rgb(out.at("spec"), x, y), expected);
            worst[k] = std::max(worst[k], e);
            unblurred[k] = std::max(unblurred[k], relErr(brdf * cube, expected));
            EXPECT_LT(e, 0.02) << m.name << ", pixel " << x << "," << y << ": " << rgb(out.at("spec"), x, y).r << ","
                               << rgb(out.at("spec"), x, y).g << "," << rgb(out.at("spec"), x, y).b << " vs "
                               << expected.r << "," << expected.g << "," << expected.b;
        }
    for (int k = 0; k < 3; ++k) {
        std::printf("%s: %d pixels, indirect specular max relative error %.2g (the cube map alone would be off by up "
                    "to %.2g)\n",
                    materials[k].name, samples[k], worst[k], unblurred[k]);
        EXPECT_GE(samples[k], 300) << materials[k].name;
    }
    EXPECT_GT(unblurred[2], 0.1); // the set-up can see the blur
}

// --- The irradiance volume's lookup (issue 26) ------------------------------------------------------------------

// test.linear_volume: what bake.lightmap hands lighting.deferred (its `volume` texture and `layout` grid), made up: a
// 5^3 grid of probes 1 m apart around the origin whose SH9 coefficients are each linear in the probe's position:
// band 0 red along x, green along y, blue along z; the eight higher coefficients small, each its own colour and
// sign, so that a coefficient read from the wrong texel changes the light. Trilinear interpolation of a linear
// function is exact, so the SH a point reads is that same function at the point it looks up.
constexpr double kVolumeSpacing = 1.0;
const glm::dvec3 kVolumeOrigin(-2.0), kVolumeSlope(0.5, 0.4, -0.45);
shading::Sh9 linearVolumeSh(glm::dvec3 p) {
    shading::Sh9 sh{};
    sh.c[0] = glm::dvec3(1.0) + kVolumeSlope * p;
    const double scale = 1.0 + 0.1 * (p.x + p.y - p.z);
    for (int k = 1; k < 9; ++k)
        sh.c[k] = scale * 0.012 * glm::dvec3(k % 3 == 0 ? k : -k, k % 2 == 0 ? 0.5 * k : 4.0, 9 - k);
    return sh;
}

class LinearVolume final : public Node {
public:
    void setup(SetupContext& ctx) override {
        auto layout = std::make_shared<BakedLightingObject>();
        layout->volumeOrigin = glm::vec3(kVolumeOrigin);
        layout->volumeSpacing = static_cast<float>(kVolumeSpacing);
        layout->volumeCounts = glm::uvec3(kCount);
        ctx.setObject("layout", layout);
        ImageDesc& vol = ctx.output("volume");
        vol.width = 9 * kCount;
        vol.height = kCount * kCount;
    }
    void execute(ExecuteContext& ctx) override {
        Image volume(9 * kCount, kCount * kCount);
        for (int z = 0; z < kCount; ++z)
            for (int y = 0; y < kCount; ++y)
                for (int x = 0; x < kCount; ++x) {
                    const shading::Sh9 sh = linearVolumeSh(kVolumeOrigin + kVolumeSpacing * glm::dvec3(x, y, z));
                    for (int k = 0; k < 9; ++k) {
                        float* px = volume.at(9 * x + k, y + kCount * z);
                        px[0] = float(sh.c[k].r);
                        px[1] = float(sh.c[k].g);
                        px[2] = float(sh.c[k].b);
                        px[3] = 1.0f;
                    }
                }
        ctx.upload("volume", volume);
    }

private:
    static constexpr int kCount = 5;
};

NodeSchema linearVolumeSchema() {
    NodeSchema s;
    s.type = "test.linear_volume";
    s.doc = "test-only node of test_gpu";
    OutputPort volume;
    volume.name = "volume";
    volume.format = VK_FORMAT_R32G32B32A32_SFLOAT;
    volume.usage = Usage::TransferDst;
    volume.doc = "test output";
    OutputPort layout;
    layout.name = "layout";
    layout.kind = PortKind::Buffer;
    layout.doc = "test output";
    s.outputs = {volume, layout};
    return s;
}
const NodeRegistration kLinearVolume(linearVolumeSchema(), [] { return std::make_unique<LinearVolume>(); });

// A matte sphere (radius 0.8 at the origin) lit by test.linear_volume alone: each pixel's diffuse_indirect is the
// diffuse albedo x the SH irradiance of the volume read a quarter of a cell along the normal in front of the surface
// point (bake/irradiance_volume.glsl), i.e. of linearVolumeSh(p + 0.25 s n), evaluated here with core/shading's
// SH. Read at p itself the sphere's rim is off by up to 0.25 x slope / band 0 (~10 %), read behind it
// twice that; the bound is 1 %.
TEST_F(LightingTerms, IrradianceVolumeIsReadInFrontOfTheSurface) {
    const int W = 96, H = 96;
    const double radius = 0.8;
    const glm::vec3 base(0.6f);
    SceneBuilder b("linear_volume");
    uint32_t material = b.material("matte", base, 0.0f, 0.5f);
    b.node("ball", static_cast<int32_t>(b.mesh("ball", sphereTris(static_cast<float>(radius), 96, 48), material)));
    b.camera({0.6f, 0.9f, 3.5f}, {0.0f, 0.0f, 0.0f}, 0.55f);
    auto glb = b.write();
    json nodes = baseNodes(glb);
    nodes["volume"] = {{"type", "test.linear_volume"}};
    nodes["lighting"] = lightingNode({{"sky_ambient", 1.0}}, false);
    nodes["lighting"]["in"]["volume"] = "volume.volume";
    nodes["lighting"]["in"]["baked"] = "volume.layout";
    auto out = runGraph(graph(nodes, {{"diffuse", "lighting.diffuse_indirect"}}, W, H));
    const Image& diffuse = out.at("diffuse");

    Pinhole cam(b.s, W, H);
    const glm::dvec3 albedo(shading::diffuseAlbedo(unorm8(base), 0.0f));
    int pixels = 0;
    double worst = 0.0, worstAtP = 0.0;
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            glm::dvec3 d = cam.ray(x, y);
            double t = hitSphere(cam.position, d, glm::dvec3(0.0), radius);
            if (t <= 0.0) continue;
            glm::dvec3 p = cam.position + t * d, n = glm::normalize(p);
            if (glm::dot(n, -d) < 0.2) continue; // away from the silhouette
            auto expectedAt = [&](glm::dvec3 q) {
                const shading::Sh9 sh = linearVolumeSh(q);
                return albedo * glm::max(shading::shIrradiance(sh, n), 0.0) / kPi;
            };
            const glm::dvec3 expected = expectedAt(p + n * (0.25 * kVolumeSpacing));
            const double e = relErr(rgb(diffuse, x, y), expected);
            ++pixels;
            worst = std::max(worst, e);
            worstAtP = std::max(worstAtP, relErr(expectedAt(p), expected));
            EXPECT_LT(e, 0.01) << "pixel " << x << "," << y << ": " << rgb(diffuse, x, y).r << ","
                               << rgb(diffuse, x, y).g << "," << rgb(diffuse, x, y).b << " vs " << expected.r << ","
                               << expected.g << "," << expected.b;
        }
    std::printf("irradiance volume: %d sphere pixels, largest relative error %.2g (a lookup at the surface point "
                "itself would differ by up to %.2g)\n",
                pixels, worst, worstAtP);
    EXPECT_GT(pixels, 2000);
    EXPECT_GT(worstAtP, 0.05); // the set-up can see the offset
}

} // namespace
} // namespace vitrine::test
