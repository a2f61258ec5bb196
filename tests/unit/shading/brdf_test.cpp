// BRDF checks with independent maths: the NDF's normalisation, the directional albedo of the
// GGX-Smith lobe (F = 1) by a deterministic quadrature written here from Heitz's Lambda form of
// the height-correlated masking, the pi convention, and the Toksvig mapping.
#include "core/shading/brdf.hpp"
#include "tests/unit/shading/furnace.hpp"

#include <gtest/gtest.h>

#include <cmath>

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

} // namespace
} // namespace vitrine::shading
