// The CPU half of bake.lightmap (core/bake/lightmap_bake): the probe directions cover the sphere evenly, a
// probe's SH of a known radiance field gives the irradiance the convolution says, the grid covers the static
// scene within its probe budget, and the cache format round-trips and refuses damaged bytes.
#include "core/bake/lightmap_bake.hpp"

#include "core/scene/museum.hpp"
#include "core/scene/scene.hpp"
#include "core/shading/sh.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

namespace vitrine::bake {
namespace {

TEST(LightmapBake, ProbeDirectionsAreUnitAndEvenlySpread) {
    const uint32_t n = 256;
    glm::dvec3 mean(0.0);
    double meanZ2 = 0.0;
    for (uint32_t i = 0; i < n; ++i) {
        const glm::vec3 d = probeDirection(i, n);
        ASSERT_NEAR(glm::length(d), 1.0f, 1e-5f);
        mean += glm::dvec3(d);
        meanZ2 += double(d.z) * d.z;
    }
    // The sphere's first moments: E[d] = 0, E[z^2] = 1/3.
    EXPECT_LT(glm::length(mean / double(n)), 0.01);
    EXPECT_NEAR(meanZ2 / n, 1.0 / 3.0, 0.005);
}

TEST(LightmapBake, ProbeShGivesTheIrradianceOfAKnownSky) {
    // Radiance 1 + z (a sky brighter above): the irradiance at a normal n is pi + (2 pi / 3) n.z exactly
    // (band 0 and 1 only, which SH9 holds), so up gets pi (1 + 2/3) and down pi (1 - 2/3).
    IrradianceVolume v;
    v.counts = {1, 1, 1};
    v.sh.resize(1);
    v.validity.resize(1);
    const uint32_t n = 1024;
    std::vector<glm::vec3> radiance(n);
    for (uint32_t i = 0; i < n; ++i) radiance[i] = glm::vec3(1.0f + probeDirection(i, n).z);
    projectProbe(v, 0, radiance, 0.0f);
    shading::Sh9 sh;
    for (int k = 0; k < 9; ++k) sh.c[k] = glm::dvec3(v.sh[0][k]);
    const double pi = std::numbers::pi;
    EXPECT_NEAR(shading::shIrradiance(sh, {0, 0, 1}).r, pi * (1.0 + 2.0 / 3.0), 0.01 * pi);
    EXPECT_NEAR(shading::shIrradiance(sh, {0, 0, -1}).r, pi * (1.0 - 2.0 / 3.0), 0.01 * pi);
    EXPECT_NEAR(shading::shIrradiance(sh, {1, 0, 0}).r, pi, 0.01 * pi);
    EXPECT_EQ(v.validity[0], 1.0f);
    projectProbe(v, 0, radiance, 0.3f); // most rays hit back faces: inside a wall
    EXPECT_EQ(v.validity[0], 0.0f);
}

TEST(LightmapBake, VolumeCoversTheStaticSceneWithinItsBudget) {
    scene::MuseumOptions o;
    o.textureSize = 16;
    const scene::Scene s = scene::buildMuseum(o);
    scene::Aabb bounds;
    for (const scene::MeshInstance& i : s.instances)
        if (!i.dynamic) bounds.expand(i.worldBounds);
    for (uint32_t budget : {100000u, 300u}) {
        const IrradianceVolume v = planIrradianceVolume(s, 2.0f, budget);
        ASSERT_GT(v.probeCount(), 0u);
        EXPECT_LE(v.probeCount(), budget);
        if (budget == 100000u) {
            EXPECT_FLOAT_EQ(v.spacing, 2.0f);
        }
        const glm::vec3 lo = v.position(0, 0, 0), hi = v.position(v.counts.x - 1, v.counts.y - 1, v.counts.z - 1);
        for (int a = 0; a < 3; ++a) {
            EXPECT_LE(lo[a], bounds.min[a] + 1e-3f);
            EXPECT_GE(hi[a], bounds.max[a] - 1e-3f);
        }
    }
    scene::Scene empty;
    EXPECT_EQ(planIrradianceVolume(empty, 2.0f, 100).probeCount(), 0u);
}

TEST(LightmapBake, CacheBytesRoundTripAndRefuseDamage) {
    BakedLighting b;
    b.width = 3;
    b.height = 2;
    b.lightmap = {1, 2, 3, 4, 5, 0xffffffffu};
    b.volume.counts = {2, 1, 1};
    b.volume.origin = {1, 2, 3};
    b.volume.spacing = 1.5f;
    b.volume.sh.resize(2);
    b.volume.sh[1][8] = glm::vec3(7, 8, 9);
    b.volume.validity = {1.0f, 0.0f};
    const std::vector<uint8_t> bytes = serializeBakedLighting(b);
    const auto back = deserializeBakedLighting(bytes);
    ASSERT_TRUE(back);
    EXPECT_EQ(back->lightmap, b.lightmap);
    EXPECT_EQ(back->volume.counts, b.volume.counts);
    EXPECT_EQ(back->volume.origin, b.volume.origin);
    EXPECT_EQ(back->volume.spacing, b.volume.spacing);
    EXPECT_EQ(back->volume.sh[1][8], glm::vec3(7, 8, 9));
    EXPECT_EQ(back->volume.validity, b.volume.validity);
    for (size_t cut : {size_t(0), size_t(10), bytes.size() - 1})
        EXPECT_FALSE(deserializeBakedLighting(std::span(bytes).first(cut))) << cut;
    std::vector<uint8_t> longer = bytes;
    longer.push_back(0);
    EXPECT_FALSE(deserializeBakedLighting(longer));
    std::vector<uint8_t> wrongMagic = bytes;
    wrongMagic[0] = 'X';
    EXPECT_FALSE(deserializeBakedLighting(wrongMagic));
}

} // namespace
} // namespace vitrine::bake
