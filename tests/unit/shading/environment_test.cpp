// sky.hdri's CPU half on a synthetic equirect: a constant sky with a small very bright disk.
#include "core/shading/environment.hpp"
#include "core/shading/sky.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

namespace vitrine::shading {
namespace {

constexpr double kPi = std::numbers::pi;

// Pixels covered by the disk (radius `radius` around `center`) take `disk`, by 8x8 sub-samples.
std::vector<float> syntheticSky(int w, int h, glm::dvec3 sky, glm::dvec3 disk, glm::dvec3 center, double radius) {
    std::vector<float> px(static_cast<size_t>(w) * h * 4);
    const double cosR = std::cos(radius);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            int inside = 0;
            for (int sy = 0; sy < 8; ++sy)
                for (int sx = 0; sx < 8; ++sx)
                    inside +=
                        glm::dot(equirectDirection((x + (sx + 0.5) / 8) / w, (y + (sy + 0.5) / 8) / h), center) > cosR;
            glm::dvec3 c = sky + (disk - sky) * (inside / 64.0);
            float* p = &px[(static_cast<size_t>(y) * w + x) * 4];
            p[0] = static_cast<float>(c.x);
            p[1] = static_cast<float>(c.y);
            p[2] = static_cast<float>(c.z);
            p[3] = 1.0f;
        }
    return px;
}

TEST(Environment, FindsTheSunAndRemovesItFromTheSh) {
    const glm::dvec3 sky(0.4, 0.6, 1.0), disk(2e4, 1.8e4, 1.5e4), center = sunDirection(35.0, -70.0);
    const double radius = 3.0 * kPi / 180.0;
    auto px = syntheticSky(512, 256, sky, disk, center, radius);
    EnvironmentBake bake = bakeEquirect(px.data(), 512, 256, 16, 2.0, true);
    ASSERT_TRUE(bake.sun.found);
    double angle = std::acos(std::clamp(glm::dot(bake.sun.direction, center), -1.0, 1.0)) * 180.0 / kPi;
    EXPECT_LT(angle, 0.25);
    // A uniform disk on a perpendicular surface: (L_disk - L_sky) pi sin^2 r, times the intensity.
    glm::dvec3 expected = 2.0 * (disk - sky) * (kPi * std::sin(radius) * std::sin(radius));
    for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(bake.sun.illuminance[c], expected[c], 0.01 * expected[c]);
    for (glm::dvec3 n : {glm::dvec3(0, 1, 0), center, -center, glm::dvec3(1, 0, 0)}) {
        glm::dvec3 e = shIrradiance(bake.sh, n);
        for (int c = 0; c < 3; ++c)
            EXPECT_NEAR(e[c], 2.0 * kPi * sky[c], 1e-3 * kPi * sky[c]);
    }
}

TEST(Environment, NoSunInAFlatSky) {
    std::vector<float> px(64 * 32 * 4, 1.0f);
    for (size_t i = 0; i < px.size(); i += 4)
        px[i] = 1.0f + 0.5f * static_cast<float>(i % 7);
    EnvironmentBake bake = bakeEquirect(px.data(), 64, 32, 8, 1.0, true);
    EXPECT_FALSE(bake.sun.found);
    EXPECT_EQ(bake.sun.illuminance, glm::dvec3(0.0));
}

} // namespace
} // namespace vitrine::shading
