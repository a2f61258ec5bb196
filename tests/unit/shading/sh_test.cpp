// SH9 projection and irradiance against analytic irradiance: constant, linear and clamped-cosine
// radiance, projected through cube-map texels with exact solid angles.
#include "core/shading/cubemap.hpp"
#include "core/shading/sh.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

namespace vitrine::shading {
namespace {

constexpr double kPi = std::numbers::pi;

std::vector<glm::dvec3> normals() {
    std::vector<glm::dvec3> n;
    for (int i = 0; i < 200; ++i) {
        double z = 1.0 - 2.0 * (i + 0.5) / 200, r = std::sqrt(1.0 - z * z), phi = 2.399963229728653 * i;
        n.emplace_back(r * std::cos(phi), z, r * std::sin(phi));
    }
    return n;
}

TEST(Sh, TexelSolidAnglesCoverTheSphere) {
    for (int size : {1, 7, 32}) {
        double sum = 0.0;
        for (int y = 0; y < size; ++y)
            for (int x = 0; x < size; ++x)
                sum += 6.0 * cubeTexelSolidAngle(x, y, size);
        EXPECT_NEAR(sum, 4.0 * kPi, 1e-9) << size;
    }
}

TEST(Sh, CubeCoordinatesInvertCubeDirection) {
    for (int face = 0; face < 6; ++face)
        for (double u : {-0.9, -0.2, 0.4, 0.95})
            for (double v : {-0.7, 0.1, 0.8}) {
                CubeCoord c = cubeCoord(cubeDirection(face, u, v) * 3.0);
                EXPECT_EQ(c.face, face);
                EXPECT_NEAR(c.u, u, 1e-12);
                EXPECT_NEAR(c.v, v, 1e-12);
            }
    // Vulkan's major-axis table: +Y's top row looks toward -Z, +Z's centre is +Z.
    EXPECT_LT(cubeDirection(2, 0.0, -1.0).z, 0.0);
    EXPECT_EQ(cubeDirection(4, 0.0, 0.0), glm::dvec3(0, 0, 1));
}

TEST(Sh, ConstantRadianceGivesPiLEverywhere) {
    const glm::dvec3 L(1.5, 2.0, 0.25);
    Sh9 sh = projectCube(32, [&](int, int, int) { return L; });
    for (glm::dvec3 n : normals()) {
        glm::dvec3 e = shIrradiance(sh, n);
        for (int c = 0; c < 3; ++c)
            EXPECT_NEAR(e[c], kPi * L[c], 1e-9 * kPi * L[c]);
    }
}

TEST(Sh, LinearRadianceIsExact) {
    // L = 1 + w.d is in bands 0-1: E(n) = pi + 2 pi / 3 n.d exactly.
    const glm::dvec3 d = glm::normalize(glm::dvec3(0.3, 0.8, -0.5));
    Sh9 sh = projectCube(
        32, [&](int f, int x, int y) { return glm::dvec3(1.0 + glm::dot(cubeTexelDirection(f, x, y, 32), d)); });
    for (glm::dvec3 n : normals())
        EXPECT_NEAR(shIrradiance(sh, n).x, kPi + 2.0 * kPi / 3.0 * glm::dot(n, d), 1e-9);
}

TEST(Sh, ClampedCosineLobeMatchesAnalyticIrradiance) {
    // L = max(0, w.d): E(beta) = 2/3 ((pi - beta) cos beta + sin beta), beta = angle(n, d).
    // SH9 drops bands >= 4 (band 3 of a clamped cosine is zero); stated error: 2.5 % of the
    // peak irradiance 2 pi / 3, plus the texel quadrature.
    const int size = 64;
    const glm::dvec3 d = glm::normalize(glm::dvec3(-0.2, 0.9, 0.4));
    Sh9 sh = projectCube(size, [&](int f, int x, int y) {
        return glm::dvec3(std::max(0.0, glm::dot(cubeTexelDirection(f, x, y, size), d)));
    });
    double worst = 0.0;
    for (glm::dvec3 n : normals()) {
        double beta = std::acos(std::clamp(glm::dot(n, d), -1.0, 1.0));
        double exact = 2.0 / 3.0 * ((kPi - beta) * std::cos(beta) + std::sin(beta));
        worst = std::max(worst, std::fabs(shIrradiance(sh, n).x - exact));
    }
    std::printf("SH9 irradiance of a clamped cosine lobe: max error %.4f (peak %.4f)\n", worst, 2.0 * kPi / 3.0);
    EXPECT_LT(worst, 0.025 * 2.0 * kPi / 3.0);
}

} // namespace
} // namespace vitrine::shading
