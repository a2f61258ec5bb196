// shadow.directional + lighting.deferred against CPU references: which ground points the sun reaches
// (a ray cast on the CPU against the occluder), the direct sun term against core/shading's CPU BRDF on
// an analytic sphere, and the sky's diffuse ambient against the CPU SH irradiance of the read-back
// coefficients. Scenes are built in code, written with exportGlb() and loaded through scene.gltf
// (the sun travels in the file), so the whole path from glTF to radiance is what is measured.
#include "tests/gpu/lighting_scene.hpp"

#include "core/shading/brdf.hpp"
#include "core/shading/octahedral.hpp"
#include "core/shading/sh.hpp"
#include "shaders/sky/sky.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

namespace vitrine::test {
namespace {

using nlohmann::json;
using namespace lighting;

// Ray / axis-aligned box (slabs): the entry distance, or infinity when missed.
double hitBox(glm::dvec3 o, glm::dvec3 d, glm::dvec3 lo, glm::dvec3 hi) {
    double t0 = 0.0, t1 = std::numeric_limits<double>::infinity();
    for (int a = 0; a < 3; ++a) {
        if (std::abs(d[a]) < 1e-12) {
            if (o[a] < lo[a] || o[a] > hi[a]) return std::numeric_limits<double>::infinity();
            continue;
        }
        double ta = (lo[a] - o[a]) / d[a], tb = (hi[a] - o[a]) / d[a];
        t0 = std::max(t0, std::min(ta, tb));
        t1 = std::min(t1, std::max(ta, tb));
    }
    return t0 <= t1 ? t0 : std::numeric_limits<double>::infinity();
}

class Lighting : public GpuTest {};

// ---------------------------------------------------------------------------------------------
// 1. Shadows

TEST_F(Lighting, SunShadowFallsWhereTheOccluderBlocksTheSun) {
    const int W = 96, H = 96;
    const glm::vec3 ground(0.6f), boxColor(0.3f);
    const float groundShininess = 0.3f;
    const glm::dvec3 boxHalf(1.0, 0.1, 1.0), boxCentre(0.0, 1.5, 0.0);
    const float groundHalf = 15.0f;

    SceneBuilder b("shadow");
    std::vector<Tri> quad;
    addQuad(quad, glm::vec3(0.0f), glm::vec3(groundHalf, 0, 0), glm::vec3(0, 0, groundHalf), glm::vec3(0, 1, 0));
    b.node("ground", static_cast<int32_t>(b.mesh("ground", quad, b.material("ground", ground, 0.0f, groundShininess))));
    b.node(
        "occluder",
        static_cast<int32_t>(b.mesh("occluder", boxTris(glm::vec3(boxHalf)), b.material("box", boxColor, 0.0f, 0.5f))),
        glm::vec3(boxCentre));
    b.camera({-4.0f, 7.0f, 3.0f}, {-0.8f, 0.0f, -0.4f}, 0.9f);
    b.sun({0.7f, 1.0f, 0.25f});
    auto glb = b.write();

    json nodes = baseNodes(glb);
    nodes["shadow"] = {{"type", "shadow.directional"},
                       {"in", {{"scene", "scene.scene"}, {"camera", "scene.camera"}}},
                       {"params", {{"resolution", 512}, {"cascades", 2}, {"distance", 20.0}}}};
    nodes["lit"] = lightingNode({{"sky_ambient", 0.0}}, true);
    nodes["unshadowed"] = lightingNode({{"sky_ambient", 0.0}, {"shadows", false}}, true);
    auto out =
        runGraph(graph(nodes, {{"lit", "lit.color"}, {"unshadowed", "unshadowed.color"}, {"sh", "sky.sh"}}, W, H));
    const Image& lit = out.at("lit");
    const Image& unshadowed = out.at("unshadowed");
    ASSERT_EQ(lit.width, W);

    const glm::dvec3 l = glm::normalize(rgb(out.at("sh"), SKY_TEXEL_SUN_DIRECTION, 0));
    const glm::dvec3 sunE = rgb(out.at("sh"), SKY_TEXEL_SUN_ILLUMINANCE, 0);
    EXPECT_LT(glm::length(l - glm::dvec3(b.s.sun.toSun)), 1e-5); // the scene's sun, through the .glb
    ASSERT_GT(sunE.g, 1000.0);

    // Ground points more than `margin` from the shadow's edge (the far cascade, which holds the whole
    // ground in view, has texels of ~5.5 cm: 2 x its ~14 m bounding sphere / 512; PCF reaches 3 texels
    // and the normal offset 1.5, so the penumbra is under ~0.2 m wide): occluded when the sun ray hits the box shrunk
    // by the margin, lit when it misses the box grown by it.
    const double margin = 0.3;
    const glm::dvec3 grow(margin, margin, margin), shrink(margin, 0.0, margin);
    Pinhole cam(b.s, W, H);
    int occluded = 0, open = 0;
    double darkest = 0.0, worstLit = 0.0, worstUnshadowed = 0.0, minLit = 1e30;
    for (int y = 0; y < H; ++y)
        for (int x = 0; x < W; ++x) {
            glm::dvec3 d = cam.ray(x, y);
            if (d.y >= 0.0) continue;
            double t = -cam.position.y / d.y;
            glm::dvec3 p = cam.position + t * d;
            if (std::abs(p.x) > groundHalf - 1.0 || std::abs(p.z) > groundHalf - 1.0) continue;
            // The camera sees the ground here, not the box (nor its edge).
            if (hitBox(cam.position, d, boxCentre - boxHalf - 0.05, boxCentre + boxHalf + 0.05) < t) continue;
            bool blocked = hitBox(p, l, boxCentre - boxHalf + shrink, boxCentre + boxHalf - shrink) < 1e30;
            bool clear = hitBox(p, l, boxCentre - boxHalf - grow, boxCentre + boxHalf + grow) ==
                         std::numeric_limits<double>::infinity();
            if (!blocked && !clear) continue;
            glm::dvec3 expected = cpuSun({0, 1, 0}, -d, l, ground, 0.0f, groundShininess, sunE);
            glm::dvec3 got = rgb(lit, x, y), gotOff = rgb(unshadowed, x, y);
            worstUnshadowed = std::max(worstUnshadowed, relErr(gotOff, expected));
            EXPECT_LT(relErr(gotOff, expected), 0.01) << "shadows off, pixel " << x << "," << y;
            if (blocked) {
                ++occluded;
                darkest = std::max(darkest, got.g / expected.g);
                EXPECT_LT(got.g, 0.05 * expected.g) << "occluded pixel " << x << "," << y;
            } else {
                ++open;
                minLit = std::min(minLit, got.g / expected.g);
                worstLit = std::max(worstLit, relErr(got, expected));
                EXPECT_LT(relErr(got, expected), 0.01) << "lit pixel " << x << "," << y;
            }
        }
    std::printf("shadow: %d occluded pixels (brightest %.3g of the unshadowed value), %d lit pixels (max relative "
                "error %.2g, darkest %.4f), shadows off: max relative error %.2g\n",
                occluded, darkest, open, worstLit, minLit, worstUnshadowed);
    EXPECT_GE(occluded, 30);
    EXPECT_GE(open, 300);
}

// ---------------------------------------------------------------------------------------------
// 2. Sun and sky ambient on a sphere

struct SphereCase {
    const char* name;
    glm::vec3 base;
    float metallic, shininess;
    const char* multiscatter = "off"; // lighting.deferred's param; "all": the closed form is the compensated lobe's
};

// Tolerances. Direct, 3 % per channel: the G-buffer normal is the interpolated normal of a 128 x 64
// UV sphere stored octahedrally in RGBA16F (measured within 1.5e-3 rad of the analytic one; half
// precision alone allows 1.1e-3), which moves NoL by up to 1.5e-3 / 0.2 ≈ 0.8 % at the NoL >= 0.2
// cut and the GGX lobe of the metal (alpha 0.12) by ~2 x 1.5e-3 / alpha ≈ 2.5 % at worst; the output
// is RGBA16F (5e-4); base colour and metallic are UNORM8 (emulated by unorm8()). Ambient: the
// difference of two RGBA16F pixels, so 1 % of the pixel, and 3 % of itself where it is non-zero.
TEST_F(Lighting, SphereMatchesCpuBrdfAndShAmbient) {
    const int W = 96, H = 96;
    const double radius = 1.0;
    // sun_scale keeps the metal's highlight well inside RGBA16F (the shader clamps at 60000).
    const double sunScale = 0.03;
    for (const SphereCase& mat : {SphereCase{"rough_dielectric", {0.8f, 0.5f, 0.25f}, 0.0f, 0.25f},
                                  SphereCase{"smooth_metal", {0.95f, 0.64f, 0.54f}, 1.0f, 0.65f},
                                  SphereCase{"rough_metal_multiscatter", {0.95f, 0.64f, 0.54f}, 1.0f, 0.35f, "all"}}) {
        SCOPED_TRACE(mat.name);
        SceneBuilder b(std::string("sphere_") + mat.name);
        b.node("sphere", static_cast<int32_t>(b.mesh("sphere", sphereTris(static_cast<float>(radius), 128, 64),
                                                     b.material(mat.name, mat.base, mat.metallic, mat.shininess))));
        b.camera({0.0f, 0.4f, 3.2f}, {0.0f, 0.0f, 0.0f}, 0.8f);
        b.sun({0.55f, 0.75f, 0.6f});
        auto glb = b.write();

        json nodes = baseNodes(glb);
        const bool ms = std::string(mat.multiscatter) == "all";
        nodes["direct"] =
            lightingNode({{"sky_ambient", 0.0}, {"sun_scale", sunScale}, {"multiscatter", mat.multiscatter}}, false);
        nodes["full"] =
            lightingNode({{"sky_ambient", 1.0}, {"sun_scale", sunScale}, {"multiscatter", mat.multiscatter}}, false);
        auto out = runGraph(graph(nodes,
                                  {{"direct", "direct.color"},
                                   {"full", "full.color"},
                                   {"spec", "full.specular_indirect"},
                                   {"direct_spec", "direct.specular_indirect"},
                                   {"sh", "sky.sh"},
                                   {"normal", "gbuffer.normal"}},
                                  W, H));
        const Image& sh = out.at("sh");
        const glm::dvec3 l = glm::normalize(rgb(sh, SKY_TEXEL_SUN_DIRECTION, 0));
        const glm::dvec3 sunE = rgb(sh, SKY_TEXEL_SUN_ILLUMINANCE, 0) * sunScale;
        const shading::Sh9 sky = readSh(sh);
        const glm::vec3 albedo = shading::diffuseAlbedo(unorm8(mat.base), mat.metallic);

        Pinhole cam(b.s, W, H);
        int samples = 0;
        double worstDirect = 0.0, worstAmbient = 0.0, worstAmbientRel = 0.0, worstNormal = 0.0, worstLeak = 0.0;
        double brightest = 0.0, compensation = 1.0;
        for (int y = 0; y < H; ++y)
            for (int x = 0; x < W; ++x) {
                glm::dvec3 d = cam.ray(x, y);
                double bq = glm::dot(cam.position, d), c = glm::dot(cam.position, cam.position) - radius * radius;
                double disc = bq * bq - c;
                if (disc <= 0.0) continue;
                glm::dvec3 p = cam.position + (-bq - std::sqrt(disc)) * d;
                glm::dvec3 n = glm::normalize(p), v = -d;
                // Away from the silhouette (tessellation, edge pixels) and the terminator (where the
                // relative error of a small value grows).
                if (glm::dot(n, v) < 0.3 || glm::dot(n, l) < 0.2) continue;
                ++samples;
                glm::dvec3 gbufferN(
                    shading::octDecode(glm::vec2(out.at("normal").at(x, y)[0], out.at("normal").at(x, y)[1])));
                worstNormal = std::max(worstNormal, std::acos(std::min(1.0, glm::dot(gbufferN, n))));

                glm::dvec3 expected = cpuSun(n, v, l, mat.base, mat.metallic, mat.shininess, sunE);
                if (ms) { // the lobe with its multiple scattering (core/shading), for the sun as for the sky
                    const glm::dvec3 single = expected;
                    expected = glm::dvec3(shading::brdfCosineSpecular(
                                   glm::vec3(n), glm::vec3(v), glm::vec3(l), unorm8(mat.base), mat.metallic,
                                   shading::roughnessFromShininess(mat.shininess),
                                   shading::dielectricSpecular(0.04f, glm::vec4(1.0f)), true)) *
                               sunE;
                    compensation = std::max(compensation, expected.g / single.g);
                }
                glm::dvec3 direct = rgb(out.at("direct"), x, y);
                double e = relErr(direct, expected);
                worstDirect = std::max(worstDirect, e);
                EXPECT_LT(e, 0.03) << "direct, pixel " << x << "," << y << ": " << direct.r << " vs " << expected.r;
                worstLeak = std::max(worstLeak, glm::length(rgb(out.at("direct_spec"), x, y)));

                // Ambient diffuse = full - direct - indirect specular.
                glm::dvec3 ambient = rgb(out.at("full"), x, y) - direct - rgb(out.at("spec"), x, y);
                glm::dvec3 expectedAmbient = glm::dvec3(albedo) * glm::max(shading::shIrradiance(sky, n), 0.0) / kPi;
                // Relative to the pixel's total: the difference of RGBA16F values is only as exact
                // as the larger of them.
                double scale = std::max(glm::length(rgb(out.at("full"), x, y)), 1e-30);
                double ea = glm::length(ambient - expectedAmbient) / scale;
                worstAmbient = std::max(worstAmbient, ea);
                EXPECT_LT(ea, 0.01) << "ambient, pixel " << x << "," << y << ": " << ambient.r << " vs "
                                    << expectedAmbient.r << " (full " << rgb(out.at("full"), x, y).r << ", direct "
                                    << direct.r << ", specular " << rgb(out.at("spec"), x, y).r << ")";
                if (mat.metallic == 0.0f) {
                    double er = relErr(ambient, expectedAmbient);
                    worstAmbientRel = std::max(worstAmbientRel, er);
                    EXPECT_LT(er, 0.03) << "ambient, pixel " << x << "," << y;
                }
                brightest = std::max(brightest, std::max(rgb(out.at("full"), x, y).r, rgb(out.at("full"), x, y).g));
            }
        std::printf(
            "%s: %d sphere pixels (brightest %.0f cd/m2), direct max relative error %.2g, ambient diffuse "
            "max error %.2g of the pixel (%.2g of itself), G-buffer normal max %.2g rad from the analytic one\n",
            mat.name, samples, brightest, worstDirect, worstAmbient, worstAmbientRel, worstNormal);
        EXPECT_GE(samples, 500);
        if (ms) {
            std::printf("%s: the compensation reaches x%.3f of the single-scattering sun\n", mat.name, compensation);
            EXPECT_GT(compensation, 1.1); // so the 3 % bound sees it
        }
        EXPECT_LT(brightest, 40000.0); // well below the shader's clamp (60000), so nothing measured is clipped
        EXPECT_EQ(worstLeak, 0.0);     // sky_ambient = 0: no indirect specular
    }
}

} // namespace
} // namespace vitrine::test
