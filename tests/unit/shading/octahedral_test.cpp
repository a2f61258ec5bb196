// Octahedral normal encoding: round-trip error in fp32 and after the half-float rounding of an
// RGBA16F G-buffer, over a dense spiral of directions plus the octahedron's edges and poles.
#include "core/shading/octahedral.hpp"

#include <glm/gtc/packing.hpp>
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace vitrine::shading {
namespace {

std::vector<glm::vec3> testDirections(int n) {
    std::vector<glm::vec3> dirs;
    const double golden = 2.399963229728653;
    for (int i = 0; i < n; ++i) {
        double z = 1.0 - 2.0 * (i + 0.5) / n, r = std::sqrt(1.0 - z * z), phi = golden * i;
        dirs.emplace_back(r * std::cos(phi), r * std::sin(phi), z);
    }
    // Poles, axes, and the creases where the lower hemisphere is folded.
    for (int sx : {-1, 0, 1})
        for (int sy : {-1, 0, 1})
            for (int sz : {-1, 0, 1})
                if (sx || sy || sz) dirs.push_back(glm::normalize(glm::vec3(sx, sy, sz)));
    for (int i = 0; i < 1000; ++i) {
        double a = 2.0 * 3.14159265358979 * i / 1000.0;
        dirs.push_back(glm::vec3(std::cos(a), std::sin(a), 0.0f));
        dirs.push_back(glm::normalize(glm::vec3(std::cos(a), std::sin(a), -1e-4f)));
    }
    return dirs;
}

double angleBetween(glm::vec3 a, glm::vec3 b) {
    glm::dvec3 x(a), y(b);
    return std::atan2(glm::length(glm::cross(x, y)), glm::dot(x, y));
}

TEST(Octahedral, RoundTripWithinOneMicroradianInFloat) {
    double worst = 0.0;
    for (glm::vec3 d : testDirections(1000000)) {
        glm::vec2 e = octEncode(d);
        ASSERT_LE(std::fabs(e.x), 1.0f);
        ASSERT_LE(std::fabs(e.y), 1.0f);
        worst = std::max(worst, angleBetween(d, octDecode(e)));
    }
    std::printf("octahedral fp32 round trip: max error %.3g rad\n", worst);
    EXPECT_LT(worst, 1e-6);
}

TEST(Octahedral, HalfFloatStorageErrorBound) {
    double worst = 0.0;
    for (glm::vec3 d : testDirections(1000000)) {
        glm::vec2 e = octEncode(d);
        glm::vec2 q(glm::unpackHalf1x16(glm::packHalf1x16(e.x)), glm::unpackHalf1x16(glm::packHalf1x16(e.y)));
        worst = std::max(worst, angleBetween(d, octDecode(q)));
    }
    std::printf("octahedral RGBA16F round trip: max error %.3g rad (%.4f deg)\n", worst, worst * 57.29578);
    EXPECT_LT(worst, 1.1e-3); // the bound documented in octahedral.hpp / .glsl
    EXPECT_GT(worst, 1e-5);   // half rounding is really applied
}

TEST(Octahedral, UnnormalisedInputEncodesItsDirection) {
    glm::vec3 d = glm::normalize(glm::vec3(0.3f, -0.8f, -0.52f));
    EXPECT_LT(angleBetween(d, octDecode(octEncode(d * 7.5f))), 1e-6);
}

} // namespace
} // namespace vitrine::shading
