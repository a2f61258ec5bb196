// The Preetham sky and sun against the ranges the paper and daylight measurements give: zenith
// luminance of thousands of cd/m^2, sun illuminance of ~80-120 klux at high sun falling with
// elevation, a diffuse sky of ~5-50 klux, and a redder sun near the horizon.
#include "core/shading/sky.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace vitrine::shading {
namespace {

TEST(Sky, ZenithLuminanceInThePapersRange) {
    for (double T : {2.0, 4.0, 6.0}) {
        double previous = 0.0;
        for (double elevation : {10.0, 30.0, 50.0, 70.0}) {
            PreethamSky sky(T, sunDirection(elevation, 30.0), 0.3);
            double yz = sky.zenithLuminance();
            std::printf("T %.0f elevation %2.0f: zenith %7.0f cd/m^2, x %.3f y %.3f\n", T, elevation, yz,
                        sky.zenithChromaticity().x, sky.zenithChromaticity().y);
            EXPECT_GT(yz, 1000.0);
            EXPECT_LT(yz, 40000.0);
            EXPECT_GT(yz, previous); // brighter as the sun rises
            previous = yz;
            // The zenith radiance is the zenith luminance, and a clear sky's zenith is bluish.
            glm::dvec3 zenith = sky.skyRadiance({0.0, 1.0, 0.0});
            EXPECT_NEAR(luminance709(zenith), yz, 1e-6 * yz);
            if (T <= 4.0) {
                EXPECT_GT(zenith.z, zenith.x);
            }
        }
    }
    // Haze brightens the sky at a given sun position.
    EXPECT_GT(PreethamSky(6.0, sunDirection(45, 0), 0.3).zenithLuminance(),
              PreethamSky(2.0, sunDirection(45, 0), 0.3).zenithLuminance());
}

TEST(Sky, SunIlluminanceFromTheAtmosphere) {
    for (double T : {2.0, 3.0}) {
        double previous = 1e9;
        for (double elevation : {90.0, 75.0, 60.0, 45.0, 30.0, 15.0, 5.0, 1.0}) {
            PreethamSky sky(T, sunDirection(elevation, 0.0), 0.3);
            glm::dvec3 e = sky.sunIlluminance();
            double lux = luminance709(e);
            std::printf("T %.0f elevation %2.0f: sun %6.0f lux (rgb %.0f %.0f %.0f), sky diffuse %6.0f lux\n", T,
                        elevation, lux, e.x, e.y, e.z, luminance709(sky.skyIrradianceHorizontal()));
            EXPECT_LT(lux, previous);
            previous = lux;
            if (elevation >= 60.0) {
                EXPECT_GT(lux, 80000.0);
                EXPECT_LT(lux, 120000.0);
                double diffuse = luminance709(sky.skyIrradianceHorizontal());
                EXPECT_GT(diffuse, 5000.0);
                EXPECT_LT(diffuse, 50000.0); // Preetham runs bright near a high sun (Zotti et al. 2007)
            }
            // The disk radiance is that of the sun: ~1e9 cd/m^2 at high sun.
            if (elevation >= 45.0) {
                EXPECT_GT(luminance709(sky.sunRadiance()), 5e8);
            }
        }
    }
    glm::dvec3 high = PreethamSky(3.0, sunDirection(70, 0), 0.3).sunIlluminance();
    glm::dvec3 low = PreethamSky(3.0, sunDirection(3, 0), 0.3).sunIlluminance();
    EXPECT_GT(low.x / low.z, 1.5 * high.x / high.z); // reddened by the long path
}

TEST(Sky, GroundIsLambertianUnderSkyAndSun) {
    PreethamSky sky(3.0, sunDirection(40.0, 120.0), 0.25);
    glm::dvec3 expected =
        0.25 / 3.14159265358979 *
        (sky.skyIrradianceHorizontal() + sky.sunIlluminance() * std::sin(40.0 * 3.14159265358979 / 180.0));
    glm::dvec3 ground = sky.radiance({0.3, -0.5, 0.1});
    for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(ground[c], expected[c], 1e-9 * expected[c]);
}

TEST(Sky, SunAzimuthConvention) {
    glm::dvec3 north = sunDirection(0.0, 0.0), east = sunDirection(0.0, 90.0), up = sunDirection(90.0, 0.0);
    EXPECT_NEAR(north.z, -1.0, 1e-12);
    EXPECT_NEAR(east.x, 1.0, 1e-12);
    EXPECT_NEAR(up.y, 1.0, 1e-12);
}

// The static sunIlluminance (scene.museum's sun, without integrating the sky dome) is the member's, bit for bit.
TEST(Sky, SunIlluminanceWithoutTheSkyIsTheSkysSun) {
    for (double turbidity : {2.0, 3.0, 6.5})
        for (glm::dvec3 toSun : {glm::dvec3(0.3, 0.72, -0.63), glm::dvec3(0.0, 1.0, 0.0), glm::dvec3(1.0, 0.1, 2.0)}) {
            const glm::dvec3 a = PreethamSky(turbidity, toSun, 0.3).sunIlluminance();
            const glm::dvec3 b = PreethamSky::sunIlluminance(turbidity, toSun);
            EXPECT_EQ(a, b) << turbidity << " " << toSun.x << " " << toSun.y << " " << toSun.z;
            EXPECT_GT(b.y, 0.0);
        }
}

} // namespace
} // namespace vitrine::shading
