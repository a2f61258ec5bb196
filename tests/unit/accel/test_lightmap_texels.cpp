// CPU passes over a baked lightmap (core/bake/lightmap_texels): E5B9G9R9 packing against values worked out by
// hand from the Vulkan specification's shared-exponent algorithm, dilation into gutters, and the edge-aware
// filter (constants preserved, noise reduced, no mixing across regions, creases, parallel surfaces or chart seams).
#include "core/bake/lightmap_texels.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace vitrine::bake {
namespace {

TEST(LightmapTexels, Rgb9e5PacksLikeTheVulkanSpecification) {
    EXPECT_EQ(packRgb9e5(glm::vec3(0.0f)), 0u);
    // 1.0: floor(log2 1) = 0 -> exp' = 0 + 1 + 15 = 16; mantissa 1 / 2^(16 - 24) = 256.
    EXPECT_EQ(packRgb9e5(glm::vec3(1.0f)), 256u | (256u << 9) | (256u << 18) | (16u << 27));
    // The largest value, 511/512 * 2^16 = 65408: exponent 31, mantissa 511; anything larger clamps to it.
    const uint32_t maxPacked = 511u | (511u << 9) | (511u << 18) | (31u << 27);
    EXPECT_EQ(packRgb9e5(glm::vec3(65408.0f)), maxPacked);
    EXPECT_EQ(packRgb9e5(glm::vec3(1e9f)), maxPacked);
    EXPECT_EQ(unpackRgb9e5(maxPacked), glm::vec3(65408.0f));
    // Negative and NaN channels are 0; here only green is left: 2 -> exp' 17, mantissa 256.
    EXPECT_EQ(packRgb9e5(glm::vec3(-1.0f, 2.0f, std::nanf(""))), (256u << 9) | (17u << 27));
    // 0.9995 rounds up to 512 at exponent 15, so the specification bumps the exponent: 16, mantissa 256.
    EXPECT_EQ(packRgb9e5(glm::vec3(0.9995f, 0.0f, 0.0f)), 256u | (16u << 27));
    // The shared exponent follows the largest channel: (4, 1, 0.25) -> exp' 18, step 2^(18-24) = 1/64.
    EXPECT_EQ(packRgb9e5(glm::vec3(4.0f, 1.0f, 0.25f)), 256u | (64u << 9) | (16u << 18) | (18u << 27));
    // Round trip: every channel within half a step of the shared exponent.
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> logValue(-12.0f, 15.0f);
    for (int i = 0; i < 10000; ++i) {
        const glm::vec3 v(std::exp2(logValue(rng)), std::exp2(logValue(rng)), std::exp2(logValue(rng)));
        const uint32_t p = packRgb9e5(v);
        const float step = std::ldexp(1.0f, int(p >> 27) - 24);
        const glm::vec3 back = unpackRgb9e5(p);
        for (int c = 0; c < 3; ++c) ASSERT_LE(std::fabs(back[c] - v[c]), 0.5f * step * 1.0001f) << v[c];
        const float maxC = std::max(v.x, std::max(v.y, v.z));
        ASSERT_LE(std::fabs(std::max(back.x, std::max(back.y, back.z)) - maxC), maxC / 512.0f);
    }
}

LightmapTexels flat(uint32_t w, uint32_t h) {
    LightmapTexels t;
    t.width = w;
    t.height = h;
    t.irradiance.assign(size_t(w) * h, glm::vec3(0.0f));
    t.position.assign(size_t(w) * h, glm::vec3(0.0f));
    t.normal.assign(size_t(w) * h, glm::vec3(0, 1, 0));
    t.region.assign(size_t(w) * h, -1);
    for (uint32_t y = 0; y < h; ++y)
        for (uint32_t x = 0; x < w; ++x) t.position[t.index(x, y)] = glm::vec3(x * 0.05f, 0.0f, y * 0.05f);
    return t;
}

TEST(LightmapTexels, DilationFillsGuttersFromTheNearestRing) {
    LightmapTexels t = flat(10, 10);
    for (uint32_t y = 4; y < 6; ++y)
        for (uint32_t x = 2; x < 4; ++x) {
            t.region[t.index(x, y)] = 0;
            t.irradiance[t.index(x, y)] = glm::vec3(5.0f);
        }
    for (uint32_t y = 4; y < 6; ++y)
        for (uint32_t x = 6; x < 8; ++x) {
            t.region[t.index(x, y)] = 1;
            t.irradiance[t.index(x, y)] = glm::vec3(1.0f);
        }
    dilateLightmap(t, 2);
    EXPECT_EQ(t.irradiance[t.index(1, 4)], glm::vec3(5.0f));  // next to region 0
    EXPECT_EQ(t.irradiance[t.index(0, 3)], glm::vec3(5.0f));  // 2 rings away
    EXPECT_EQ(t.irradiance[t.index(8, 5)], glm::vec3(1.0f));  // next to region 1
    EXPECT_EQ(t.irradiance[t.index(4, 4)], glm::vec3(5.0f));  // nearer region 0 (1 ring) than region 1 (2)
    EXPECT_EQ(t.irradiance[t.index(5, 4)], glm::vec3(1.0f));
    EXPECT_EQ(t.irradiance[t.index(2, 0)], glm::vec3(0.0f));  // 4 rings away: untouched
    EXPECT_EQ(t.region[t.index(1, 4)], -1);                   // coverage is what was rasterised
}

TEST(LightmapTexels, FilterKeepsConstantsAndReducesNoise) {
    LightmapTexels t = flat(32, 32);
    std::mt19937 rng(3);
    std::normal_distribution<float> noise(0.0f, 1.0f);
    for (size_t i = 0; i < t.region.size(); ++i) {
        t.region[i] = 0;
        t.irradiance[i] = glm::vec3(10.0f + noise(rng), 10.0f, 10.0f);
    }
    auto variance = [&](const LightmapTexels& x) {
        double s = 0.0, s2 = 0.0;
        for (const glm::vec3& v : x.irradiance) {
            s += v.x;
            s2 += double(v.x) * v.x;
        }
        const double n = double(x.irradiance.size());
        return s2 / n - (s / n) * (s / n);
    };
    const double before = variance(t);
    filterLightmap(t);
    const double after = variance(t);
    std::printf("filter: noise variance %.4f -> %.4f\n", before, after);
    EXPECT_LT(after, before / 10.0);
    for (const glm::vec3& v : t.irradiance) {
        EXPECT_NEAR(v.y, 10.0f, 1e-4f); // the constant channels stay constant
        EXPECT_NEAR(v.z, 10.0f, 1e-4f);
    }
}

// A sunlit interior's lightmap: most of a texel's 16 paths bring little light, a rare one finds the sun through an
// aperture and brings a lot. The texels are Monte Carlo estimates of the same irradiance, so any filter that only
// removes noise keeps their mean; the luminance test must not turn the bright rare estimates into lost energy.
TEST(LightmapTexels, FilterKeepsTheEnergyOfRareBrightSamples) {
    constexpr uint32_t kSize = 64, kPaths = 16;
    constexpr float kDim = 1.0f, kBright = 40.0f, kChance = 1.0f / 32.0f;
    LightmapTexels t = flat(kSize, kSize);
    t.variance.assign(t.region.size(), 0.0f);
    std::mt19937 rng(11);
    std::bernoulli_distribution bright(kChance);
    double before = 0.0;
    for (size_t i = 0; i < t.region.size(); ++i) {
        t.region[i] = 0;
        float sum = 0.0f, squares = 0.0f;
        for (uint32_t p = 0; p < kPaths; ++p) {
            const float e = bright(rng) ? kBright : kDim;
            sum += e;
            squares += e * e;
        }
        const float mean = sum / kPaths;
        t.irradiance[i] = glm::vec3(mean);
        t.variance[i] = std::max(squares / kPaths - mean * mean, 0.0f) / kPaths; // as bake.lightmap's resolve
        before += mean;
    }
    before /= double(t.region.size());
    filterLightmap(t);
    double after = 0.0;
    for (const glm::vec3& v : t.irradiance) after += v.x;
    after /= double(t.irradiance.size());
    const double expected = kDim + (kBright - kDim) * kChance;
    std::printf("rare bright samples: expected mean %.4f, texels %.4f, filtered %.4f (ratio %.4f)\n", expected, before,
                after, after / before);
    EXPECT_NEAR(after / before, 1.0, 0.02);
}

TEST(LightmapTexels, FilterDoesNotMixRegionsCreasesOrDistantSurfaces) {
    // Left half and right half of a 16x8 atlas, 1 and 10.
    for (int kind = 0; kind < 4; ++kind) {
        LightmapTexels t = flat(16, 8);
        for (uint32_t y = 0; y < 8; ++y)
            for (uint32_t x = 0; x < 16; ++x) {
                const size_t i = t.index(x, y);
                const bool right = x >= 8;
                t.irradiance[i] = glm::vec3(right ? 10.0f : 1.0f);
                t.region[i] = (kind == 0 && right) ? 1 : 0;           // 0: two regions
                if (kind == 1 && right) t.normal[i] = glm::vec3(1, 0, 0); // 1: a 90-degree crease
                if (kind == 2 && right) t.position[i].y += 5.0f;      // 2: a parallel surface 5 m away
                if (kind == 3 && right) t.position[i].x += 10.0f;     // 3: the same plane 10 m on (a chart seam)
            }
        // Cases 0-2 with the plane, normal and region tests alone; the seam needs the reach limit.
        LightmapFilterOptions options;
        if (kind == 3) options.texelSize = 0.05f;
        filterLightmap(t, options);
        for (uint32_t y = 0; y < 8; ++y)
            for (uint32_t x = 0; x < 16; ++x)
                ASSERT_NEAR(t.irradiance[t.index(x, y)].x, x >= 8 ? 10.0f : 1.0f, 1e-3f)
                    << "case " << kind << " at " << x << "," << y;
    }
}

} // namespace
} // namespace vitrine::bake
