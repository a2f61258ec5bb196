// BRDF checks with independent maths: the NDF's normalisation, the directional albedo of the
// GGX-Smith lobe (F = 1) by a deterministic quadrature written here from Heitz's Lambda form of
// the height-correlated masking, the pi convention, Schlick's Fresnel against values worked out by
// hand and against the exact Fresnel equations, the split-sum fit of deferred.comp against values
// worked out by hand and the mirror limit, and the Toksvig mapping.
#include "core/shading/brdf.hpp"
#include "tests/unit/shading/furnace.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace vitrine::shading {
namespace {

TEST(Brdf, GgxNdfProjectedAreaIsOne) {
    for (float alpha : {0.002f, 0.05f, 0.3f, 0.7f, 1.0f}) {
        // integral of D(h) cos(theta_h) over the hemisphere, in the substitution of furnace.hpp
        double sum = test::integrateHalfVectors(alpha, [&](double cosH, double) {
            return static_cast<double>(ggxD(static_cast<float>(cosH), alpha)) * cosH;
        });
        EXPECT_NEAR(sum, 1.0, 2e-3) << "alpha " << alpha;
    }
}

TEST(Brdf, SpecularAlbedoMatchesIndependentQuadratureAndNeverExceedsOne) {
    for (double noV : {0.05, 0.3, 0.7, 1.0})
        for (double roughness : {0.05, 0.25, 0.5, 0.8, 1.0}) {
            const float alpha = ggxAlpha(static_cast<float>(roughness));
            double reference = test::specularAlbedo(noV, alpha);
            // The same integral through the code under test (CPU mirror of brdf.glsl).
            double viaCode = test::integrateSpecular(noV, alpha, [&](double nl, double nh, double) {
                return static_cast<double>(ggxD(static_cast<float>(nh), alpha) *
                                           smithGgxVisibility(static_cast<float>(noV), static_cast<float>(nl), alpha));
            });
            EXPECT_NEAR(viaCode, reference, 2e-3) << "NoV " << noV << " roughness " << roughness;
            EXPECT_LE(reference, 1.0 + 1e-3);
        }
    EXPECT_GT(test::specularAlbedo(1.0, ggxAlpha(0.05f)),
              0.99); // a near-mirror reflects everything at normal incidence
}

TEST(Brdf, LambertFurnaceIsOne) {
    // integral of (1/pi) cos over the hemisphere, by the midpoint rule in theta
    const int n = 4096;
    double sum = 0.0;
    for (int i = 0; i < n; ++i) {
        double th = (i + 0.5) * (1.5707963267948966 / n);
        sum += lambertDiffuse() * std::cos(th) * std::sin(th) * (1.5707963267948966 / n) * 2.0 * 3.141592653589793;
    }
    EXPECT_NEAR(sum, 1.0, 1e-6);
}

TEST(Brdf, DirectionalLightFollowsThePiConvention) {
    // Rough white dielectric lit and seen head-on: diffuse 1/pi, specular D V F with
    // D = 1/pi, V = 1/4, F = 0.04 (alpha = 1). Radiance = (1/pi + 0.01/pi) * pi * I = 1.01 I.
    glm::vec3 n(0, 0, 1), intensity(2.0f, 3.0f, 5.0f);
    glm::vec3 L = shadeDirectional(n, n, n, glm::vec3(1.0f), 0.0f, 1.0f, intensity);
    for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(L[c], 1.01f * intensity[c], 1e-5f * intensity[c]);
    // Metal: no diffuse, F0 = base colour.
    glm::vec3 M = shadeDirectional(n, n, n, glm::vec3(0.5f), 1.0f, 1.0f, glm::vec3(1.0f));
    EXPECT_NEAR(M.x, 0.5f * 0.25f, 1e-6f);
    EXPECT_EQ(roughnessFromShininess(0.8f), 1.0f - 0.8f);
}

// Exact unpolarised reflectance of a smooth dielectric of refractive index `ior` seen from air, at
// cos(theta) = c: the mean of the s- and p-polarised Fresnel equations.
double exactDielectricFresnel(double c, double ior) {
    double sinT = std::sqrt(std::max(0.0, 1.0 - c * c)) / ior, cosT = std::sqrt(1.0 - sinT * sinT);
    double rs = (c - ior * cosT) / (c + ior * cosT), rp = (cosT - ior * c) / (cosT + ior * c);
    return 0.5 * (rs * rs + rp * rp);
}

TEST(Brdf, SchlickFresnelMatchesHandComputedValues) {
    // 0.04 + 0.96 (1 - c)^5: (1 - c)^5 is 1e-5, 0.03125, 0.16807, 0.32768, 0.59049 at c = 0.9 .. 0.1.
    struct Case {
        float cosTheta;
        float expected;
    };
    for (Case k : {Case{1.0f, 0.04f}, Case{0.9f, 0.0400096f}, Case{0.5f, 0.07f}, Case{0.3f, 0.2013472f},
                   Case{0.2f, 0.3545728f}, Case{0.1f, 0.6068704f}, Case{0.0f, 1.0f}})
        EXPECT_NEAR(schlickFresnel(glm::vec3(0.04f), k.cosTheta).y, k.expected, 1e-6f) << "cos " << k.cosTheta;
    // Metal (copper-like F0) at c = 0.5: F0 + (1 - F0) 0.03125 per channel.
    glm::vec3 metal = schlickFresnel(glm::vec3(0.95f, 0.64f, 0.54f), 0.5f);
    EXPECT_NEAR(metal.x, 0.9515625f, 1e-6f);
    EXPECT_NEAR(metal.y, 0.65125f, 1e-6f);
    EXPECT_NEAR(metal.z, 0.554375f, 1e-6f);
}

TEST(Brdf, SchlickFresnelIsWithinItsApproximationErrorOfExactFresnelForIor15) {
    // IOR 1.5 has F0 = (0.5 / 2.5)^2 = 0.04. Schlick's error (exponent 5) is at most 0.036 over the
    // whole range and 6.5 % of the exact value for cos in [0.1, 0.3]; exponent 4 is off by 0.10 and by
    // 17-30 % there, so the bounds (0.05 and 10 %) tell the two apart.
    double worstAbs = 0.0, worstGrazing = 0.0;
    for (int i = 0; i <= 100; ++i) {
        double c = i / 100.0, exact = exactDielectricFresnel(c, 1.5);
        double schlick = schlickFresnel(glm::vec3(0.04f), static_cast<float>(c)).x;
        worstAbs = std::max(worstAbs, std::abs(schlick - exact));
        EXPECT_NEAR(schlick, exact, 0.05) << "cos " << c;
        if (c >= 0.1 && c <= 0.3) {
            worstGrazing = std::max(worstGrazing, std::abs(schlick - exact) / exact);
            EXPECT_NEAR(schlick, exact, 0.10 * exact) << "cos " << c;
        }
    }
    std::printf("Schlick vs exact Fresnel (IOR 1.5): max error %.4f, %.3f of the exact value for cos in [0.1, 0.3]\n",
                worstAbs, worstGrazing);
}

TEST(Brdf, GrazingDirectionalLightUsesSchlickAtTheHalfVector) {
    // Black rough dielectric (alpha = 1), light and view mirrored about the normal at cos = 0.2, so
    // h = n and VoH = NoV = NoL = 0.2: D = 1/pi, V = 0.5 / (NoL + NoV) = 1.25, F = 0.3545728 (above).
    // Radiance for I = 1: D V F NoL pi = 1.25 x 0.3545728 x 0.2 = 0.0886432.
    const float c = 0.2f, s = std::sqrt(1.0f - c * c);
    glm::vec3 n(0, 0, 1), v(s, 0, c), l(-s, 0, c);
    glm::vec3 L = shadeDirectional(n, v, l, glm::vec3(0.0f), 0.0f, 1.0f, glm::vec3(1.0f));
    EXPECT_NEAR(L.y, 0.0886432f, 1e-5f);
}

TEST(Brdf, EnvBrdfApproxMatchesHandComputedValuesAndTheMirrorLimit) {
    // Karis' fit worked out by hand: rr = r (-1, -0.0275, -0.572, 0.022) + (1, 0.0425, 1.04, -0.04),
    // a004 = min(rr.x^2, 2^(-9.28 NoV)) rr.x + rr.y, (a, b) = (rr.z - 1.04 a004, rr.w + 1.04 a004).
    struct Case {
        float noV, roughness, a, b;
    };
    for (Case k : {// r = 0, NoV = 1: a004 = 2^-9.28 + 0.0425 = 0.0441086
                   Case{1.0f, 0.0f, 0.9941271f, 0.0058729f},
                   // r = 0.5, NoV = 0.5: rr = (0.5, 0.02875, 0.754, -0.029), 2^-4.64 = 0.0401071 < 0.25,
                   // a004 = 0.0401071 x 0.5 + 0.02875 = 0.0488035
                   Case{0.5f, 0.5f, 0.7032443f, 0.0217557f},
                   // r = 1: rr.x = 0, so a004 = rr.y = 0.015 at any NoV
                   Case{0.3f, 1.0f, 0.4524f, -0.0024f}}) {
        glm::vec2 ab = envBrdfApprox(k.noV, k.roughness);
        EXPECT_NEAR(ab.x, k.a, 1e-6f) << "NoV " << k.noV << " r " << k.roughness;
        EXPECT_NEAR(ab.y, k.b, 1e-6f) << "NoV " << k.noV << " r " << k.roughness;
    }
    // A perfect mirror reflects F(NoV) of the incoming light, so with Schlick's F the split sum is
    // a = 1 - (1 - NoV)^5, b = (1 - NoV)^5 exactly; the fit keeps a + b = 1 and follows b within 0.045.
    for (int i = 0; i <= 20; ++i) {
        float noV = i / 20.0f;
        glm::vec2 ab = envBrdfApprox(noV, 0.0f);
        EXPECT_NEAR(ab.x + ab.y, 1.0f, 1e-6f) << "NoV " << noV;
        EXPECT_NEAR(ab.y, std::pow(1.0f - noV, 5.0f), 0.05f) << "NoV " << noV;
    }
}

TEST(Brdf, ToksvigWidensTheLobeByTheNormalVariance) {
    for (float r : {0.1f, 0.3f, 0.6f}) {
        EXPECT_NEAR(ggxAlpha(toksvigRoughness(r, 1.0f)), ggxAlpha(r), 1e-5f);
        float previous = r;
        for (float len : {0.999f, 0.99f, 0.95f, 0.8f, 0.5f}) {
            float widened = toksvigRoughness(r, len);
            EXPECT_GT(widened, previous);
            EXPECT_LE(widened, 1.0f);
            previous = widened;
            if (len < 0.99f || r > 0.3f) continue;
            // Small-alpha, small-variance form: alpha'^2 ~ alpha^2 + 2 (1 - |Na|) / |Na|.
            double a = ggxAlpha(r), expected = std::sqrt(a * a + 2.0 * (1.0 - len) / len);
            EXPECT_NEAR(ggxAlpha(widened), expected, 0.03 * expected) << r << " " << len;
        }
    }
    EXPECT_NEAR(toksvigRoughness(0.0f, 0.01f), 1.0f, 0.05f);
}

// The bake's caustic footprint: a mirror's lobe for the sun widened so that half of the reflected sun lands within
// `footprint` metres of the mirror image on a surface `distance` away (normal incidence: the reflection of a half
// vector at theta_h turns by 2 theta_h, so it lands at distance tan(2 theta_h)), integrated here over GGX's own
// distribution of half vectors (D cos theta_h, whose integral is 1).
TEST(Brdf, RegularizedRoughnessLandsHalfTheSunsReflectionWithinTheFootprint) {
    for (float distance : {1.0f, 4.0f, 12.0f})
        for (float footprint : {0.05f, 0.25f}) {
            const float alpha = ggxAlpha(regularizedRoughness(0.0f, footprint, distance));
            const double thetaMax = 0.5 * std::atan(double(footprint) / distance);
            const int steps = 20000;
            double inside = 0.0;
            for (int i = 0; i < steps; ++i) { // midpoint rule over theta_h, solid angle 2 pi sin
                const double theta = (i + 0.5) / steps * thetaMax;
                inside += ggxD(float(std::cos(theta)), alpha) * std::cos(theta) * 2.0 * 3.14159265358979 *
                          std::sin(theta) * thetaMax / steps;
            }
            EXPECT_NEAR(inside, 0.5, 0.02) << "footprint " << footprint << " m at " << distance << " m";
        }
    // A lobe already wider keeps its roughness; footprint 0 changes nothing; the widening stops at roughness 1.
    EXPECT_EQ(regularizedRoughness(0.7f, 0.25f, 4.0f), 0.7f);
    EXPECT_EQ(regularizedRoughness(0.05f, 0.0f, 4.0f), 0.05f);
    EXPECT_GT(regularizedRoughness(0.05f, 0.25f, 4.0f), 0.05f);
    EXPECT_EQ(regularizedRoughness(0.05f, 10.0f, 0.01f), 1.0f);
}

} // namespace
} // namespace vitrine::shading

namespace vitrine::shading {
namespace {

// KHR_materials_specular against the extension's closed form, written here in double from the Khronos text:
//   dielectric_brdf's specular = k F D V, F = f0c + (1 - f0c) (1 - VoH)^5, f0c = min(((ior - 1)/(ior + 1))^2 c, 1)
//   metal_brdf = (base + (1 - base) (1 - VoH)^5) D V, material = mix(dielectric, metal, metallic)
// with GGX D and height-correlated Smith V, plus vitrine's diffuse (1 - metallic) base / pi (the lobes add:
// MUSEUM_SPEC §1, so the diffuse is not weighted by 1 - k F as Khronos' fresnel_mix would), times NoL.
glm::dvec3 khronosSpecularCosine(glm::dvec3 n, glm::dvec3 v, glm::dvec3 l, glm::dvec3 base, double metallic,
                                 double roughness, double ior, glm::dvec3 color, double k) {
    const double pi = 3.14159265358979323846;
    double NoL = glm::dot(n, l), NoV = glm::dot(n, v);
    glm::dvec3 h = glm::normalize(v + l);
    double NoH = glm::dot(n, h), VoH = glm::dot(v, h);
    double a = std::max(roughness * roughness, 0.002), a2 = a * a;
    double d = NoH * NoH * (a2 - 1.0) + 1.0;
    double D = a2 / (pi * d * d);
    double V = 0.5 / (NoL * std::sqrt(NoV * NoV * (1.0 - a2) + a2) + NoV * std::sqrt(NoL * NoL * (1.0 - a2) + a2));
    double w = std::pow(1.0 - VoH, 5.0);
    double r = (ior - 1.0) / (ior + 1.0);
    glm::dvec3 f0c = glm::min(r * r * color, glm::dvec3(1.0));
    glm::dvec3 dielectric = k * (f0c + (1.0 - f0c) * w) * D * V;
    glm::dvec3 metal = (base + (1.0 - base) * w) * D * V;
    glm::dvec3 diffuse = (1.0 - metallic) * base / pi;
    return (diffuse + (1.0 - metallic) * dielectric + metallic * metal) * NoL;
}

TEST(Brdf, SpecularExtensionMatchesTheKhronosClosedForm) {
    struct Case {
        glm::vec3 base;
        float metallic, roughness, ior;
        glm::vec3 color;
        float k;
    };
    const Case cases[] = {
        {glm::vec3(0.0f), 0.0f, 0.5f, 1.5f, glm::vec3(1.0f, 0.5f, 0.25f), 0.4f}, // tinted, weakened dielectric
        {glm::vec3(0.8f, 0.2f, 0.1f), 0.0f, 0.3f, 4.0f, glm::vec3(3.0f, 1.0f, 0.2f), 0.7f}, // f0 0.36 x 3 clamps to 1
        {glm::vec3(0.9f, 0.6f, 0.3f), 0.5f, 0.7f, 1.5f, glm::vec3(0.5f), 0.25f}, // half metal: F90 = k + (1 - k) / 2
        {glm::vec3(0.5f), 0.0f, 0.4f, 1.5f, glm::vec3(1.0f), 0.0f},              // no specular at all
    };
    // Directions: near normal, and a grazing pair where F90 dominates (VoH ~ 0.17).
    const glm::vec3 n(0, 0, 1);
    const glm::vec3 dirs[][2] = {
        {glm::normalize(glm::vec3(0.2f, 0.1f, 1.0f)), glm::normalize(glm::vec3(-0.3f, 0.0f, 1.0f))},
        {glm::normalize(glm::vec3(1.0f, 0.0f, 0.2f)), glm::normalize(glm::vec3(-1.0f, 0.1f, 0.25f))}};
    for (const Case& c : cases) {
        float r = (c.ior - 1.0f) / (c.ior + 1.0f);
        glm::vec4 dielectric = dielectricSpecular(r * r, glm::vec4(c.color, c.k));
        for (const auto& vl : dirs) {
            glm::vec3 got = brdfCosineSpecular(n, vl[0], vl[1], c.base, c.metallic, c.roughness, dielectric);
            glm::dvec3 want =
                khronosSpecularCosine(n, vl[0], vl[1], c.base, c.metallic, c.roughness, c.ior, c.color, c.k);
            for (int i = 0; i < 3; ++i)
                EXPECT_NEAR(got[i], want[i], 1e-5 + 1e-4 * want[i]) << "k " << c.k << " channel " << i;
        }
    }
    // Without the extension (c = 1, k = 1) the surface is the plain BRDF, to the bit.
    glm::vec4 plain = dielectricSpecular(0.04f, glm::vec4(1.0f));
    EXPECT_EQ(plain, glm::vec4(0.04f, 0.04f, 0.04f, 1.0f));
    for (const auto& vl : dirs) {
        for (float metallic : {0.0f, 0.3f, 1.0f}) {
            glm::vec3 base(0.7f, 0.4f, 0.2f);
            EXPECT_EQ(brdfCosineSpecular(n, vl[0], vl[1], base, metallic, 0.35f, plain),
                      brdfCosine(n, vl[0], vl[1], base, metallic, 0.35f));
            EXPECT_EQ(shadeDirectionalSpecular(n, vl[0], vl[1], base, metallic, 0.35f, plain, glm::vec3(2.0f)),
                      shadeDirectional(n, vl[0], vl[1], base, metallic, 0.35f, glm::vec3(2.0f)));
        }
    }
}

} // namespace
} // namespace vitrine::shading

namespace vitrine::shading {
namespace {

// KHR_materials_clearcoat against the layering written out here in double from the Khronos text and the glTF Sample
// Viewer: coat Fresnel Fc(x) = 0.04 + 0.96 (1 - x)^5 (ior 1.5), the coat's lobe D V Fc(v.h) (n_c.l) with GGX of
// alpha = r^2 about the coat normal, and f = f_base (1 - c Fc(n_c.v)) + c coat; f_base is the uncoated model (its own
// test above, so taken from brdfCosine here). Bound 0.1 %: float32 against double at the mirror pair of a coat of
// roughness 0.1, where the GGX peak (1 / (pi alpha^2)) comes from NoH^2 (alpha^2 - 1) + 1, measured 0.033 %.
double khronosCoatCosine(glm::dvec3 nc, glm::dvec3 v, glm::dvec3 l, double r) {
    const double pi = 3.14159265358979323846;
    double NoL = glm::dot(nc, l), NoV = glm::dot(nc, v);
    if (NoL <= 0.0 || NoV <= 0.0) return 0.0;
    glm::dvec3 h = glm::normalize(v + l);
    double NoH = glm::dot(nc, h), VoH = glm::dot(v, h);
    double a = std::max(r * r, 0.002), a2 = a * a;
    double d = NoH * NoH * (a2 - 1.0) + 1.0;
    double D = a2 / (pi * d * d);
    double V = 0.5 / (NoL * std::sqrt(NoV * NoV * (1.0 - a2) + a2) + NoV * std::sqrt(NoL * NoL * (1.0 - a2) + a2));
    double F = 0.04 + 0.96 * std::pow(1.0 - VoH, 5.0);
    return D * V * F * NoL;
}

TEST(Brdf, ClearcoatMatchesTheKhronosLayering) {
    // The Fresnel itself: 0.04 at normal incidence, 1 at grazing, Schlick in between.
    EXPECT_FLOAT_EQ(clearcoatFresnel(1.0f), 0.04f);
    EXPECT_FLOAT_EQ(clearcoatFresnel(0.0f), 1.0f);
    EXPECT_NEAR(clearcoatFresnel(0.5f), 0.04 + 0.96 * std::pow(0.5, 5.0), 1e-7);

    const glm::vec3 n(0, 0, 1);
    // A coat normal tilted away from the base's (a coat normal map), and the base's own.
    const glm::vec3 tilted = glm::normalize(glm::vec3(0.15f, -0.1f, 1.0f));
    const glm::vec3 dirs[][2] = {
        {glm::normalize(glm::vec3(0.2f, 0.1f, 1.0f)), glm::normalize(glm::vec3(-0.3f, 0.0f, 1.0f))},
        {glm::normalize(glm::vec3(1.0f, 0.0f, 0.2f)), glm::normalize(glm::vec3(-1.0f, 0.1f, 0.25f))},
        {glm::normalize(glm::vec3(0.5f, 0.5f, 0.7f)), glm::normalize(glm::vec3(-0.5f, -0.5f, 0.7f))}}; // the mirror
    const glm::vec4 plain = dielectricSpecular(0.04f, glm::vec4(1.0f));
    const glm::vec3 base(0.8f, 0.3f, 0.1f);
    for (glm::vec3 nc : {n, tilted}) {
        for (glm::vec2 coat : {glm::vec2(1.0f, 0.1f), glm::vec2(0.5f, 0.3f), glm::vec2(0.8f, 0.9f)}) {
            for (const auto& vl : dirs) {
                glm::vec3 got = brdfCosineClearcoat(n, nc, vl[0], vl[1], base, 0.2f, 0.6f, plain, coat);
                glm::dvec3 f = glm::dvec3(brdfCosine(n, vl[0], vl[1], base, 0.2f, 0.6f));
                double NcoV = glm::dot(glm::dvec3(nc), glm::dvec3(vl[0]));
                double Fv = 0.04 + 0.96 * std::pow(1.0 - NcoV, 5.0);
                double c = coat.x;
                glm::dvec3 want = f * (1.0 - c * Fv) +
                                  c * khronosCoatCosine(glm::dvec3(nc), glm::dvec3(vl[0]), glm::dvec3(vl[1]), coat.y);
                for (int i = 0; i < 3; ++i)
                    EXPECT_NEAR(got[i], want[i], 1e-5 + 1e-3 * want[i]) << "c " << c << " r " << coat.y << " ch " << i;
            }
        }
    }
    // The smooth coat's mirror highlight is far brighter than the base's (a check that its own roughness is used,
    // not the base's 0.6): at the mirror pair D of alpha 0.002 is 1 / (pi 0.002^2).
    glm::vec3 mirrorV = dirs[2][0], mirrorL = dirs[2][1];
    EXPECT_GT(clearcoatSpecularCosine(n, mirrorV, mirrorL, 0.0f),
              100.0f * clearcoatSpecularCosine(n, mirrorV, mirrorL, 0.6f));
    // No coat (c = 0): the base to the bit, whatever the coat's normal and roughness.
    for (const auto& vl : dirs) {
        EXPECT_EQ(brdfCosineClearcoat(n, tilted, vl[0], vl[1], base, 0.2f, 0.6f, plain, glm::vec2(0.0f, 0.4f)),
                  brdfCosineSpecular(n, vl[0], vl[1], base, 0.2f, 0.6f, plain));
    }
    // clearcoatLayer alone: the base attenuated by 1 - c Fc(NcoV), the coat added times c.
    glm::vec3 layered = clearcoatLayer(glm::vec3(1.0f, 2.0f, 3.0f), 0.5f, 0.5f, glm::vec3(4.0f));
    double Fh = 0.04 + 0.96 * std::pow(0.5, 5.0);
    for (int i = 0; i < 3; ++i)
        EXPECT_NEAR(layered[i], (i + 1) * (1.0 - 0.5 * Fh) + 2.0, 1e-6);
}

} // namespace
} // namespace vitrine::shading

namespace vitrine::shading {
namespace {

// KHR_materials_sheen. The Charlie distribution's definition: D(h) NoH integrates to 1 over the hemisphere of h
// (2 pi ∫ D(cos t) cos t sin t dt, a 1-D midpoint rule in double over 20000 steps of t). Bound 1e-4: the lobe of
// the smallest alpha (0.01, sin^100) is sharp at t = 90 degrees; measured 3e-8 (the quadrature is fine enough).
TEST(Brdf, CharlieNdfProjectedAreaIsOne) {
    const double pi = 3.14159265358979323846;
    double worst = 0.0;
    for (float r : {0.0f, 0.1f, 0.3f, 0.5f, 0.8f, 1.0f}) {
        const float alpha = sheenAlpha(r);
        const int steps = 20000;
        double sum = 0.0;
        for (int i = 0; i < steps; ++i) {
            double t = (i + 0.5) / steps * 0.5 * pi;
            sum += sheenCharlieD(static_cast<float>(std::cos(t)), alpha) * std::cos(t) * std::sin(t);
        }
        double area = 2.0 * pi * sum * (0.5 * pi / steps);
        worst = std::max(worst, std::abs(area - 1.0));
        EXPECT_NEAR(area, 1.0, 1e-4) << "r " << r;
    }
    std::printf("Charlie D: worst |projected area - 1| %.2g\n", worst);
    EXPECT_FLOAT_EQ(sheenAlpha(0.5f), 0.25f);
    EXPECT_FLOAT_EQ(sheenAlpha(0.0f), kMinSheenAlpha);
}

// The lobe against the spec's formulas written out here in double: D = (2 + 1/a) sin^(1/a)(t_h) / (2 pi), V = 1 /
// ((1 + lambda(NoV) + lambda(NoL)) 4 NoV NoL) with the spec's fitted lambda, sheen = sc D V (n.l). Bound 0.1 %.
double khronosSheenLambda(double x, double a) {
    double t = (1.0 - a) * (1.0 - a);
    double A = 21.5473 + (25.3245 - 21.5473) * t, B = 3.82987 + (3.32435 - 3.82987) * t;
    double C = 0.19823 + (0.16801 - 0.19823) * t, D = -1.97760 + (-1.27393 + 1.97760) * t;
    double E = -4.32054 + (-4.85967 + 4.32054) * t;
    auto L = [&](double y) { return A / (1.0 + B * std::pow(y, C)) + D * y + E; };
    return x < 0.5 ? std::exp(L(x)) : std::exp(2.0 * L(0.5) - L(1.0 - x));
}
double khronosSheenCosine(glm::dvec3 n, glm::dvec3 v, glm::dvec3 l, double r) {
    const double pi = 3.14159265358979323846;
    double NoL = glm::dot(n, l), NoV = glm::dot(n, v);
    if (NoL <= 0.0 || NoV <= 0.0) return 0.0;
    double a = std::max(r * r, 0.01);
    double NoH = glm::dot(n, glm::normalize(v + l));
    double D = (2.0 + 1.0 / a) * std::pow(1.0 - NoH * NoH, 0.5 / a) / (2.0 * pi);
    double V = 1.0 / ((1.0 + khronosSheenLambda(NoV, a) + khronosSheenLambda(NoL, a)) * 4.0 * NoV * NoL);
    return D * V * NoL;
}

// The lobe's directional albedo: sheenCosine of a white sheen integrated over the hemisphere of l (midpoint rule in
// (cos t, phi), double).
double sheenLobeAlbedo(float NoV, float r, int steps) {
    const double pi = 3.14159265358979323846;
    const glm::vec3 n(0, 0, 1), v(std::sqrt(1.0f - NoV * NoV), 0.0f, NoV);
    double sum = 0.0;
    for (int i = 0; i < steps; ++i) {
        double mu = (i + 0.5) / steps, s = std::sqrt(1.0 - mu * mu);
        for (int j = 0; j < 2 * steps; ++j) {
            double phi = (j + 0.5) / (2 * steps) * 2.0 * pi;
            glm::vec3 l(static_cast<float>(s * std::cos(phi)), static_cast<float>(s * std::sin(phi)),
                        static_cast<float>(mu));
            sum += sheenCosine(n, v, l, glm::vec3(1.0f), r).x; // dl = d(mu) d(phi)
        }
    }
    return sum * (1.0 / steps) * (pi / steps);
}

TEST(Brdf, SheenLobeMatchesTheKhronosFormulas) {
    const glm::vec3 n(0, 0, 1);
    const glm::vec3 dirs[][2] = {
        {glm::normalize(glm::vec3(0.2f, 0.1f, 1.0f)), glm::normalize(glm::vec3(-0.3f, 0.0f, 1.0f))},
        {glm::normalize(glm::vec3(1.0f, 0.0f, 0.2f)), glm::normalize(glm::vec3(-1.0f, 0.1f, 0.25f))},
        {glm::normalize(glm::vec3(1.0f, 0.0f, 0.1f)), glm::normalize(glm::vec3(0.0f, 1.0f, 0.6f))},
        {glm::normalize(glm::vec3(0.5f, 0.5f, 0.7f)), glm::normalize(glm::vec3(-0.5f, -0.5f, 0.7f))}};
    const glm::vec3 colour(0.9f, 0.4f, 0.2f);
    for (float r : {0.0f, 0.25f, 0.5f, 0.9f}) {
        for (const auto& vl : dirs) {
            glm::vec3 got = sheenCosine(n, vl[0], vl[1], colour, r);
            double want = khronosSheenCosine(glm::dvec3(n), glm::dvec3(vl[0]), glm::dvec3(vl[1]), r);
            for (int i = 0; i < 3; ++i)
                EXPECT_NEAR(got[i], colour[i] * want, 1e-7 + 1e-3 * colour[i] * want) << "r " << r << " ch " << i;
        }
    }
    // Below the surface on either side: nothing.
    EXPECT_EQ(sheenCosine(n, dirs[0][0], -dirs[0][1], colour, 0.5f), glm::vec3(0.0f));
    EXPECT_EQ(sheenCosine(n, -dirs[0][0], dirs[0][1], colour, 0.5f), glm::vec3(0.0f));
}

// common/sheen_albedo.h's fit (tools/make_sheen_albedo.py) against the integral done again here, at points between the
// fitted grid's, NoV >= 0.05 (nearer grazing the lobe of low roughness reflects more than 1 and the scaling is clamped
// at 0 anyway). Bound 0.012 absolute: the fit's (measured 0.0061).
TEST(Brdf, SheenAlbedoFitMatchesQuadrature) {
    double worst = 0.0;
    for (float NoV : {0.05f, 0.13f, 0.31f, 0.5f, 0.77f, 0.97f}) {
        for (float r : {0.0f, 0.15f, 0.37f, 0.55f, 0.71f, 0.93f}) {
            double want = sheenLobeAlbedo(NoV, r, 160);
            float got = sheenAlbedo(NoV, r);
            worst = std::max(worst, std::abs(got - want));
            EXPECT_NEAR(got, want, 0.012) << "NoV " << NoV << " r " << r;
        }
    }
    std::printf("sheen albedo fit: worst |fit - quadrature| %.5f\n", worst);
}

// common/ggx_albedo.h's fit (tools/make_ggx_albedo.py, which integrates with the split sum's estimator) against the
// directional albedo done again here in Heitz's Lambda form (furnace.hpp), at points between the fitted grid's,
// NoV >= 0.013 (below 0.01 the shaders read NoV 0.01). Bound 0.02 absolute (the fit's worst was 0.017).
TEST(Brdf, GgxAlbedoFitMatchesQuadrature) {
    double worst = 0.0;
    for (float NoV : {0.013f, 0.07f, 0.23f, 0.5f, 0.77f, 0.97f})
        for (float r : {0.0f, 0.11f, 0.27f, 0.46f, 0.63f, 0.81f, 0.99f}) {
            const float alpha = ggxAlpha(r);
            double want = test::specularAlbedo(NoV, alpha, 1024, 128);
            float got = ggxAlbedo(NoV, alpha);
            worst = std::max(worst, std::abs(got - want));
            EXPECT_NEAR(got, want, 0.02) << "NoV " << NoV << " r " << r;
        }
    std::printf("GGX albedo fit: worst |fit - quadrature| %.5f\n", worst);
}

// Multiple-scattering compensation [Turquin19]: with it a white metal's lobe (F0 = 1) reflects all the light it
// gets at every roughness and view, the integral of brdfCosineF0F90 over the hemisphere within 2 % of 1 (the fit's
// relative error); without it the integral is the single-scattering albedo, 31 % at roughness 1 seen from above.
// A dielectric's lobe (F0 0.04, diffuse 0) gains a few per cent at most.
TEST(Brdf, MultiscatterWhiteMetalReflectsAllItGets) {
    const glm::vec3 n(0, 0, 1);
    auto albedo = [&](float NoV, float roughness, glm::vec3 f0, bool ms) {
        const glm::vec3 v(std::sqrt(1.0f - NoV * NoV), 0.0f, NoV);
        return test::integrateHalfVectors(ggxAlpha(roughness), [&](double cosH, double phi) {
            const double sinH = std::sqrt(std::max(0.0, 1.0 - cosH * cosH));
            const glm::vec3 h(static_cast<float>(sinH * std::cos(phi)), static_cast<float>(sinH * std::sin(phi)),
                              static_cast<float>(cosH));
            const float VoH = glm::dot(v, h);
            if (VoH <= 0.0f) return 0.0;
            const glm::vec3 l = 2.0f * VoH * h - v;
            // d omega_l = 4 VoH d omega_h
            return static_cast<double>(brdfCosineF0F90(n, v, l, glm::vec3(0.0f), f0, 1.0f, roughness, ms).g) * 4.0 *
                   VoH;
        });
    };
    double worst = 0.0;
    for (float NoV : {0.15f, 0.4f, 0.7f, 1.0f})
        for (float r : {0.1f, 0.3f, 0.55f, 0.8f, 1.0f}) {
            const double ms = albedo(NoV, r, glm::vec3(1.0f), true);
            worst = std::max(worst, std::abs(ms - 1.0));
            EXPECT_NEAR(ms, 1.0, 0.02) << "NoV " << NoV << " r " << r;
            const double dielectric = albedo(NoV, r, glm::vec3(0.04f), true) / albedo(NoV, r, glm::vec3(0.04f), false);
            EXPECT_GE(dielectric, 1.0) << "NoV " << NoV << " r " << r;
            EXPECT_LT(dielectric, 1.1) << "NoV " << NoV << " r " << r;
        }
    const double single = albedo(1.0f, 1.0f, glm::vec3(1.0f), false);
    std::printf("multiscatter: white metal albedo worst |1 - E_ms| %.4f; single scattering at r 1, NoV 1: %.4f\n",
                worst, single);
    EXPECT_NEAR(single, 1.0 - std::log(2.0), 0.005); // E(NoV 1, alpha 1) = 1 - ln 2, worked out by hand
}

// The layering f = sc D V + (1 - max(sc) E(n.v)) f_base under the coat, and the energy it keeps: the directional
// albedo of the sheen over a white Lambertian-plus-GGX base stays at most 1 (and the sheen adds what it removes:
// sheen + scaled base lies between the base's albedo and 1) wherever the fitted lobe reflects at most what it
// receives (E <= 1: away from grazing for low roughness, see common/brdf.glsl).
TEST(Brdf, SheenLayeringKeepsEnergy) {
    const glm::vec3 n(0, 0, 1);
    const glm::vec4 plain = dielectricSpecular(0.04f, glm::vec4(1.0f));
    const glm::vec3 base(0.8f, 0.3f, 0.1f);
    const glm::vec4 sheen(0.2f, 0.7f, 0.5f, 0.6f);
    const glm::vec3 v = glm::normalize(glm::vec3(0.6f, 0.0f, 0.5f)), l = glm::normalize(glm::vec3(-0.2f, 0.4f, 0.8f));
    glm::vec3 got = brdfCosineSheen(n, n, v, l, base, 0.1f, 0.5f, plain, glm::vec2(0.0f), sheen);
    float E = sheenAlbedo(glm::dot(n, v), sheen.a);
    glm::vec3 want = brdfCosineSpecular(n, v, l, base, 0.1f, 0.5f, plain) * (1.0f - 0.7f * E) +
                     glm::vec3(sheen) * static_cast<float>(khronosSheenCosine(n, v, l, sheen.a));
    for (int i = 0; i < 3; ++i)
        EXPECT_NEAR(got[i], want[i], 1e-6 + 1e-3 * want[i]) << i;
    // No sheen: brdfCosineClearcoat to the bit.
    EXPECT_EQ(
        brdfCosineSheen(n, n, v, l, base, 0.1f, 0.5f, plain, glm::vec2(0.3f, 0.2f), glm::vec4(0.0f, 0.0f, 0.0f, 0.7f)),
        brdfCosineClearcoat(n, n, v, l, base, 0.1f, 0.5f, plain, glm::vec2(0.3f, 0.2f)));
    // Energy, white everything: integrate brdfCosineSheen over l.
    const double pi = 3.14159265358979323846;
    for (float NoV : {0.2f, 0.5f, 0.9f}) {
        for (float r : {0.3f, 0.6f, 1.0f}) {
            const glm::vec3 vv(std::sqrt(1.0f - NoV * NoV), 0.0f, NoV);
            const int steps = 128;
            double withSheen = 0.0, without = 0.0;
            for (int i = 0; i < steps; ++i) {
                double mu = (i + 0.5) / steps, s = std::sqrt(1.0 - mu * mu);
                for (int j = 0; j < 2 * steps; ++j) {
                    double phi = (j + 0.5) / (2 * steps) * 2.0 * pi;
                    glm::vec3 ll(static_cast<float>(s * std::cos(phi)), static_cast<float>(s * std::sin(phi)),
                                 static_cast<float>(mu));
                    withSheen += brdfCosineSheen(n, n, vv, ll, glm::vec3(1.0f), 0.0f, 0.5f, plain, glm::vec2(0.0f),
                                                 glm::vec4(1.0f, 1.0f, 1.0f, r))
                                     .x;
                    without += brdfCosineSpecular(n, vv, ll, glm::vec3(1.0f), 0.0f, 0.5f, plain).x;
                }
            }
            withSheen *= (1.0 / steps) * (pi / steps);
            without *= (1.0 / steps) * (pi / steps);
            // The white base of this model reflects a little more than 1 (Lambert plus GGX, not energy-shared);
            // the sheen's share replaces (1 - E) of it: sheen E + (1 - E) base.
            double E = sheenAlbedo(NoV, r);
            EXPECT_NEAR(withSheen, E + (1.0 - E) * without, 0.01) << "NoV " << NoV << " r " << r;
            EXPECT_LE(withSheen, std::max(without, 1.0) + 1e-3) << "NoV " << NoV << " r " << r;
        }
    }
}

} // namespace
} // namespace vitrine::shading
