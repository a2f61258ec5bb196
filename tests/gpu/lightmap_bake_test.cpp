// bake.lightmap against answers it does not compute itself:
//   - a floor beside a long wall under a uniform sky with a black wall: every floor point sees the sky except
//     the wall, E(d) = pi C (1 - F(d)), with F(d) = (1 - d / sqrt(d^2 + h^2)) / 2 the view factor from a point
//     at distance d to an infinitely long wall of height h;
//   - the same floor, black, with a sunlit white wall and no sky: the wall is a uniform Lambert emitter of
//     radiance a E_sun cos(theta) / pi, so E(d) = a E_sun cos(theta) F(d) (the texel's own direct sun is left
//     to the frame, and a black floor returns nothing to the wall);
//   - the floor of a closed box whose walls all emit Le and reflect with albedo rho: radiance is the same
//     everywhere, Le (1 + rho + ... + rho^n) after n reflections, so E = pi Le sum rho^k (bounces and Russian
//     roulette, the emissive path);
//   - the museum: no NaN or Inf anywhere, no black texel where the sun reaches the surface (the CPU BVH says
//     which), gutters dilated; a second run loads the cache instead of baking; a damaged cache file is baked
//     again;
//   - the museum frame with lightmaps against the path-traced reference: where the light falls (the mean
//     luminance of each block of an 8 x 4 grid over the image, in log units) is nearer the reference's than
//     without them.
#include "tests/gpu/lighting_scene.hpp"

#include "core/accel/scene_bvh.hpp"
#include "core/accel/traverse.hpp"
#include "core/bake/lightmap_atlas.hpp"
#include "core/bake/lightmap_bake.hpp"
#include "core/bake/lightmap_raster.hpp"
#include "core/graph/loader.hpp"
#include "core/image/io.hpp"
#include "core/scene/gltf.hpp"
#include "core/scene/gpu_scene.hpp"
#include "core/scene/museum.hpp"
#include "core/shading/brdf.hpp"
#include "core/shader/compiler.hpp"
#include "shaders/sky/sky.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <optional>
#include <sstream>

namespace vitrine::test {
namespace {

using nlohmann::json;
using namespace lighting;
namespace fs = std::filesystem;

class LightmapBake : public GpuTest {};

// Sets an environment variable for a scope (the bake cache's folder).
class ScopedEnv {
public:
    ScopedEnv(const char* name, const std::string& value) : mName(name) {
        if (const char* old = std::getenv(name)) mOld = old;
        setenv(name, value.c_str(), 1);
    }
    ~ScopedEnv() {
        if (mOld) setenv(mName, mOld->c_str(), 1);
        else unsetenv(mName);
    }

private:
    const char* mName;
    std::optional<std::string> mOld;
};

constexpr float kFloor = 8.0f;     // the floor spans x in [0, 8], z in [-4, 4]
constexpr float kWallHeight = 2.0f; // the wall's face is the plane x = 0, y in [0, 2], z in [-100, 100]
constexpr float kTexelsPerMeter = 4.0f;

// The lightmapped floor of these scenes: kFloor square at y = 0, x in [0, kFloor], uv1 = (x / kFloor, (z + kFloor / 2)
// / kFloor), of `material`.
void addLightmappedFloor(SceneBuilder& b, uint32_t material) {
    std::vector<Tri> floor;
    addQuad(floor, {kFloor / 2, 0, 0}, {kFloor / 2, 0, 0}, {0, 0, kFloor / 2}, {0, 1, 0});
    for (Tri& t : floor)
        for (scene::Vertex* v : {&t.a, &t.b, &t.c})
            v->uv1 = {v->position.x / kFloor, (v->position.z + kFloor / 2) / kFloor};
    const uint32_t mesh = b.mesh("floor", floor, material);
    b.s.primitives[b.s.meshes[mesh].firstPrimitive].lightmapUvs = true;
    b.node("floor", static_cast<int32_t>(mesh));
}

// A lightmapped floor (uv1 = (x / 8, (z + 4) / 8)) beside a long wall without lightmap UVs.
fs::path floorAndWall(const std::string& name, glm::vec3 floorBase, float floorMetallic, glm::vec3 wallBase,
                      float wallMetallic, glm::vec3 toSun, float wallShininess = 0.0f, float wallCoat = 0.0f,
                      float wallCoatRoughness = 0.0f) {
    SceneBuilder b(name);
    // Lambertian surfaces (KHR_materials_specular's strength 0 takes the dielectric's specular lobe away), so that
    // the view-factor cases stay exact now that bake paths reflect with the full material.
    const uint32_t floorMaterial = b.material("floor", floorBase, floorMetallic, 0.0f);
    const uint32_t wallMaterial = b.material("wall", wallBase, wallMetallic, wallShininess);
    b.s.materials[floorMaterial].specular = 0.0f;
    b.s.materials[wallMaterial].specular = 0.0f;
    b.s.materials[wallMaterial].clearcoat = wallCoat;
    b.s.materials[wallMaterial].clearcoatRoughness = wallCoatRoughness;
    addLightmappedFloor(b, floorMaterial);
    const uint32_t wall = b.mesh("wall", boxTris({0.1f, kWallHeight / 2, 100.0f}), wallMaterial);
    b.node("wall", static_cast<int32_t>(wall), {-0.1f, kWallHeight / 2, 0.0f});
    b.camera({4.0f, 3.0f, 6.0f}, {4.0f, 0.0f, 0.0f}, 0.9f);
    b.sun(toSun);
    return b.write();
}

json uniformSky(const fs::path& glb, double c) {
    Image sky(32, 16);
    for (float& v : sky.pixels) v = 1.0f;
    const auto file = glb.parent_path() / (glb.stem().string() + "_sky.exr");
    writeExr(file, sky, ExrPixelType::Float);
    return {{"type", "sky.hdri"}, {"params", {{"path", file.string()}, {"intensity", c}, {"size", 16}}}};
}

// Both integrators of bake.lightmap are held to each case: shaders/bake/lightmap.comp ("gpu") and render.pathtrace's
// CPU tracer ("cpu", what "auto" picks on lavapipe).
constexpr const char* kBackends[] = {"gpu", "cpu"};

json bakeGraph(const fs::path& glb, json sky, json params, const char* backend) {
    params["backend"] = backend;
    params["texels_per_meter"] = kTexelsPerMeter;
    params["probe_spacing"] = 100.0;
    params["probe_rays"] = 16;
    if (!params.contains("cache"))
        params["cache"] = false; // always this build's integrator, never an earlier build's file
    json nodes = {{"scene", {{"type", "scene.gltf"}, {"params", {{"path", glb.string()}}}}},
                  {"sky", sky},
                  {"bake", {{"type", "bake.lightmap"},
                            {"in", {{"scene", "scene.scene"}, {"sky", "sky.cubemap"}, {"sky_sh", "sky.sh"}}},
                            {"params", params}}}};
    return graph(nodes, {{"lightmap", "bake.lightmap"}, {"volume", "bake.volume"}, {"sh", "sky.sh"}}, 16, 16);
}

// The floor's region in the atlas the node planned (the same plan, from the same loaded scene).
bake::LightmapRegion floorRegion(const fs::path& glb) {
    const scene::Scene s = scene::loadGltf(glb);
    bake::LightmapAtlasOptions o;
    o.texelsPerMeter = kTexelsPerMeter;
    const bake::LightmapAtlas atlas = bake::planLightmapAtlas(s, o);
    EXPECT_EQ(atlas.regions.size(), 1u);
    return atlas.regions.at(0);
}

double viewFactorToWall(double d) { return 0.5 * (1.0 - d / std::sqrt(d * d + kWallHeight * kWallHeight)); }

// Mean baked irradiance (red) of each texel column of the floor's region against expected(d), d the
// distance of the column's texel centres from the wall, for d in [0.5, dMax] m: each column within
// `tolerance`, their sum within `totalTolerance`.
void expectProfile(const Image& lightmap, const bake::LightmapRegion& r, const std::function<double(double)>& expected,
                   double tolerance, double totalTolerance, double dMax = kFloor - 0.5) {
    double worst = 0.0, total = 0.0, totalExpected = 0.0;
    int columns = 0;
    for (uint32_t i = 0; i < r.size; ++i) {
        // Texel centre -> uv1 through the region's scale and offset -> x = 8 u.
        const double atlasU = (r.x + i + 0.5) / lightmap.width;
        const double d = (atlasU - r.scaleOffset.z) / r.scaleOffset.x * kFloor;
        if (d < 0.5 || d > dMax) continue;
        double sum = 0.0;
        for (uint32_t j = 0; j < r.size; ++j) sum += lightmap.at(int(r.x + i), int(r.y + j))[0];
        const double mean = sum / r.size, want = expected(d);
        const double e = std::abs(mean / want - 1.0);
        worst = std::max(worst, e);
        EXPECT_LT(e, tolerance) << "d = " << d << " m: baked " << mean << " lux, expected " << want;
        total += mean;
        totalExpected += want;
        ++columns;
    }
    const double totalError = std::abs(total / totalExpected - 1.0);
    std::printf("  %d columns, worst relative error %.4f, of the sum %.4f\n", columns, worst, totalError);
    EXPECT_LT(totalError, totalTolerance);
    EXPECT_GE(columns, 10);
}

TEST_F(LightmapBake, SkyLightBesideABlackWallFollowsTheViewFactor) {
    const double C = 1000.0;
    const fs::path glb = floorAndWall("bake_sky_wall", glm::vec3(0.5f), 0.0f, glm::vec3(0.0f), 1.0f, {0.3f, 1.0f, 0.2f});
    const bake::LightmapRegion r = floorRegion(glb);
    // Raw with many samples (the integrator), then few samples (16, half the node's default) and the filter,
    // which must remove the noise without flattening the contact gradient near the wall.
    for (const char* backend : kBackends)
        for (auto [samples, iterations, tolerance, totalTolerance] :
             {std::tuple{256, 0, 0.02, 0.01}, std::tuple{16, 4, 0.05, 0.03}}) {
            SCOPED_TRACE(std::string(backend) + ", filter iterations " + std::to_string(iterations));
            auto out = runGraph(bakeGraph(glb, uniformSky(glb, C),
                                          {{"samples", samples}, {"sun_scale", 0.0}, {"filter_iterations", iterations}},
                                          backend));
            std::printf("%s: sky beside a black wall, %d samples, filter %d:\n", backend, samples, iterations);
            expectProfile(
                out.at("lightmap"), r, [&](double d) { return kPi * C * (1.0 - viewFactorToWall(d)); }, tolerance,
                totalTolerance);
            // The gutter ring around the region holds its border's values (dilation): nothing black.
            const Image& lm = out.at("lightmap");
            for (uint32_t i = 0; i < r.size; ++i) {
                EXPECT_GT(lm.at(int(r.x + i), int(r.y) - 1)[0], 0.3 * kPi * C) << "gutter above column " << i;
                EXPECT_GT(lm.at(int(r.x + i), int(r.y + r.size))[0], 0.3 * kPi * C) << "gutter below column " << i;
            }
        }
}

// `seed`: the same seed bakes the same bits; another seed is an independent bake of the same light (the lightmap
// differs texel by texel, by the noise of 16 paths, but its mean agrees), and another cache key.
TEST_F(LightmapBake, AnotherSeedIsAnIndependentBakeOfTheSameLight) {
    const double C = 1000.0;
    const fs::path glb = floorAndWall("bake_seed", glm::vec3(0.5f), 0.0f, glm::vec3(0.0f), 1.0f, {0.3f, 1.0f, 0.2f});
    const bake::LightmapRegion r = floorRegion(glb);
    for (const char* backend : kBackends) {
        SCOPED_TRACE(backend);
        auto bakeWith = [&](int seed) {
            return runGraph(bakeGraph(glb, uniformSky(glb, C),
                                      {{"samples", 16}, {"sun_scale", 0.0}, {"filter_iterations", 0}, {"seed", seed}},
                                      backend))
                .at("lightmap");
        };
        const Image a = bakeWith(0), again = bakeWith(0), b = bakeWith(7);
        EXPECT_EQ(a.pixels, again.pixels);
        double sumA = 0.0, sumB = 0.0, diff = 0.0;
        int differing = 0, n = 0;
        for (uint32_t j = 0; j < r.size; ++j)
            for (uint32_t i = 0; i < r.size; ++i) {
                const float va = a.at(int(r.x + i), int(r.y + j))[0], vb = b.at(int(r.x + i), int(r.y + j))[0];
                sumA += va;
                sumB += vb;
                diff += std::abs(va - vb);
                differing += va != vb ? 1 : 0;
                ++n;
            }
        std::printf(
            "%s: seeds 0 and 7: %d of %d texels differ, mean |diff| %.4f of the mean, means %.1f and %.1f lux\n",
            backend, differing, n, diff / sumA, sumA / n, sumB / n);
        // (Texels far from the wall see only the uniform sky: exact whatever the paths, the same in both.)
        EXPECT_GT(differing, n / 4) << "seed 7 drew the same paths as seed 0";
        EXPECT_GT(diff / sumA, 0.005) << "seed 7 drew (nearly) the same paths as seed 0";
        EXPECT_NEAR(sumB / sumA, 1.0, 0.02) << "another seed must bake the same light";
    }
    bake::LightmapBakeSettings s0, s7;
    s7.seed = 7;
    scene::Scene empty;
    EXPECT_NE(bake::lightmapCacheKey(empty, s0, 1).hash, bake::lightmapCacheKey(empty, s7, 1).hash);
}

// `backend`: auto traces on the CPU when the Vulkan device is a CPU (lavapipe), else on the GPU; the two integrators
// draw different paths (the same light, other bits), and each is its own cache entry.
TEST_F(LightmapBake, AutoTracesOnTheCpuOfACpuDevice) {
    const fs::path glb = floorAndWall("bake_backend", glm::vec3(0.5f), 0.0f, glm::vec3(0.0f), 1.0f, {0.3f, 1.0f, 0.2f});
    auto bakeWith = [&](const char* backend, bool cache) {
        return runGraph(bakeGraph(glb, uniformSky(glb, 1000.0), {{"samples", 8}, {"sun_scale", 0.0}, {"cache", cache}},
                                  backend))
            .at("lightmap");
    };
    const Image automatic = bakeWith("auto", false), cpu = bakeWith("cpu", false), gpuBake = bakeWith("gpu", false);
    const bool cpuDevice = gpu().deviceInfo().type == VK_PHYSICAL_DEVICE_TYPE_CPU;
    EXPECT_EQ(automatic.pixels, cpuDevice ? cpu.pixels : gpuBake.pixels) << "device is a CPU: " << cpuDevice;
    EXPECT_NE(cpu.pixels, gpuBake.pixels);
    // Through a cache of its own: the GPU bake after a stored CPU bake is the GPU's, and the other way round.
    const fs::path cacheDir = fs::path(VITRINE_TEST_OUT) / "bake_backend_cache";
    fs::remove_all(cacheDir);
    ScopedEnv env("VITRINE_CACHE_DIR", cacheDir.string());
    EXPECT_EQ(bakeWith("cpu", true).pixels, cpu.pixels);
    EXPECT_EQ(bakeWith("gpu", true).pixels, gpuBake.pixels);
    EXPECT_EQ(bakeWith("cpu", true).pixels, cpu.pixels);
}

// The floor beside a wall seen from behind: a single-sided quad at x = 0 facing away from the floor, which the
// rasteriser culls and the path tracer passes through. A bake path that first meets the back of a single-sided
// surface counts as started inside geometry and brings no light; the texel's light is the mean of the other paths
// (were they counted as black, the floor would come out pi C (1 - F(d)), as beside a black wall). Every
// direction that is not blocked sees the uniform sky, so every texel is pi C, as the path tracer has it.
TEST_F(LightmapBake, PathsThatStartBehindAWallAreLeftOutOfTheTexelsMean) {
    const double C = 1000.0;
    SceneBuilder b("bake_back_wall");
    addLightmappedFloor(b, b.material("floor", glm::vec3(0.5f), 0.0f, 0.0f));
    std::vector<Tri> wall;
    addQuad(wall, {0, kWallHeight / 2, 0}, {0, kWallHeight / 2, 0}, {0, 0, 100.0f}, {-1, 0, 0});
    b.node("wall", static_cast<int32_t>(b.mesh("wall", wall, b.material("wall", glm::vec3(0.0f), 0.0f, 0.0f))));
    b.camera({4.0f, 3.0f, 6.0f}, {4.0f, 0.0f, 0.0f}, 0.9f);
    b.sun({0.3f, 1.0f, 0.2f});
    const fs::path glb = b.write();
    const bake::LightmapRegion r = floorRegion(glb);
    for (const char* backend : kBackends) {
        SCOPED_TRACE(backend);
        auto out = runGraph(bakeGraph(glb, uniformSky(glb, C),
                                      {{"samples", 64}, {"sun_scale", 0.0}, {"filter_iterations", 0}}, backend));
        std::printf("%s: floor beside a wall seen from behind, 64 samples:\n", backend);
        expectProfile(
            out.at("lightmap"), r, [&](double) { return kPi * C; }, 0.02, 0.01);
    }
}

// A closed box standing on the floor (1.5 m square, 1 m tall): the floor's texels under it start every path inside
// geometry. They are hidden — given their visible neighbours' light by dilation, so that bilinear filtering at the
// box's foot does not smear their darkness into the texels beside it — not baked black: every texel of the floor,
// under the box or not, holds light. (Were the hidden ones baked, the 4 x 4 texels wholly under the box would be 0.)
TEST_F(LightmapBake, TexelsUnderABoxTakeTheirNeighboursLight) {
    const double C = 1000.0;
    SceneBuilder b("bake_box_on_floor");
    const uint32_t floorMaterial = b.material("floor", glm::vec3(0.5f), 0.0f, 0.0f);
    b.s.materials[floorMaterial].specular = 0.0f;
    addLightmappedFloor(b, floorMaterial);
    // Its sides at 3.25 and 4.75 m: texel edges (4 texels per metre) lie on neither, so its border texels are partly
    // covered and the 4 x 4 inside them wholly.
    const uint32_t box = b.mesh("box", boxTris({0.75f, 0.5f, 0.75f}), b.material("box", glm::vec3(0.5f), 0.0f, 0.0f));
    b.node("box", static_cast<int32_t>(box), {4.0f, 0.5f, 0.0f});
    b.camera({4.0f, 3.0f, 6.0f}, {4.0f, 0.0f, 0.0f}, 0.9f);
    b.sun({0.3f, 1.0f, 0.2f});
    const fs::path glb = b.write();
    const bake::LightmapRegion r = floorRegion(glb);
    for (const char* backend : kBackends) {
        SCOPED_TRACE(backend);
        testing::internal::CaptureStderr();
        auto out = runGraph(bakeGraph(glb, uniformSky(glb, C),
                                      {{"samples", 16}, {"sun_scale", 0.0}, {"filter_iterations", 0}}, backend));
        const std::string log = testing::internal::GetCapturedStderr();
        const Image& lightmap = out.at("lightmap");
        int dark = 0, under = 0;
        double darkest = 1e30;
        for (uint32_t j = 0; j < r.size; ++j)
            for (uint32_t i = 0; i < r.size; ++i) {
                const double value = lightmap.at(int(r.x + i), int(r.y + j))[0];
                darkest = std::min(darkest, value);
                dark += value < 0.1 * kPi * C ? 1 : 0;
                // Texel centre -> floor position: wholly under the box when its whole footprint is.
                const double x = ((r.x + i + 0.5) / lightmap.width - r.scaleOffset.z) / r.scaleOffset.x * kFloor;
                const double z =
                    ((r.y + j + 0.5) / lightmap.height - r.scaleOffset.w) / r.scaleOffset.y * kFloor - kFloor / 2;
                under += std::abs(x - 4.0) < 0.75 - 0.125 && std::abs(z) < 0.75 - 0.125 ? 1 : 0;
            }
        std::printf("%s: %d texels wholly under the box; darkest floor texel %.0f lux (pi C = %.0f)\n", backend, under,
                    darkest, kPi * C);
        EXPECT_GE(under, 16);
        EXPECT_EQ(dark, 0) << "floor texels baked black (under the box?); darkest " << darkest << "\n" << log;
        EXPECT_NE(log.find("texels lie inside geometry and take their neighbours' light"), std::string::npos) << log;
    }
}

TEST_F(LightmapBake, SunBouncedOffAWhiteWallFollowsTheViewFactor) {
    const glm::vec3 wallBase(0.5f);
    const fs::path glb = floorAndWall("bake_sun_wall", glm::vec3(0.0f), 1.0f, wallBase, 0.0f, {1.0f, 1.0f, 0.3f});
    const bake::LightmapRegion r = floorRegion(glb);
    json sky = {{"type", "sky.procedural"}, {"in", {{"scene", "scene.scene"}}}, {"params", {{"size", 16}, {"sun_in_cubemap", false}}}};
    for (const char* backend : kBackends) {
        SCOPED_TRACE(backend);
        auto out =
            runGraph(bakeGraph(glb, sky, {{"samples", 1024}, {"sky_scale", 0.0}, {"filter_iterations", 0}}, backend));
        const glm::dvec3 sunE = rgb(out.at("sh"), SKY_TEXEL_SUN_ILLUMINANCE, 0);
        const glm::dvec3 toSun = glm::normalize(rgb(out.at("sh"), SKY_TEXEL_SUN_DIRECTION, 0));
        // A Lambertian wall (no specular lobe): it reflects its base colour.
        const double albedo = wallBase.r;
        const double cosine = glm::dot(toSun, glm::dvec3(1, 0, 0));
        ASSERT_GT(cosine, 0.3);
        std::printf("%s: sun off a white wall (E_sun %.0f lux, cos %.3f):\n", backend, sunE.r, cosine);
        // Few paths find the wall far from it (F = 0.11 at 3 m): columns to 3 m, each within 6 %, their sum 2 %.
        expectProfile(
            out.at("lightmap"), r, [&](double d) { return albedo * sunE.r * cosine * viewFactorToWall(d); }, 0.06, 0.02,
            3.0);
    }
}

// caustic_footprint: the wall is a mirror (a white metal) the sun shines on, the floor black; the floor's light is
// the sun reflected by the wall (a caustic), E(p) = integral over the wall of E_sun f(v, l) (n.l) cos_wall cos_floor
// / r^2 dA, f the wall's BRDF (core/shading's brdfCosine, the CPU mirror of brdf.glsl). The bake widens the wall's
// lobe for the sun to alpha' = max(alpha, F / (2 r)), r the distance to the floor point: half of a mirror's reflection
// of the sun then lands within F metres of the mirror image (GGX: P(tan theta_h < alpha) = 1/2, the reflection
// turns by 2 theta_h). The integral is written here with that alpha', column by column: a nearly smooth mirror
// (shininess 0.95) is spread over F = 2 texels = 0.5 m, a rough one (shininess 0.4) keeps its own lobe, with the
// footprint and without; a black metal under a smooth clear coat has its coat's lobe spread the same way.
TEST_F(LightmapBake, SunGlintOffAMirrorIsSpreadOverTheCausticFootprint) {
    const glm::vec3 toSunIn(1.0f, 1.0f, 0.3f);
    json sky = {{"type", "sky.procedural"},
                {"in", {{"scene", "scene.scene"}}},
                {"params", {{"size", 16}, {"sun_in_cubemap", false}}}};
    struct Case {
        float shininess;
        double footprintTexels;
        float base = 1.0f, coat = 0.0f; // a white metal, or a black one under a clear coat of roughness 0.05
    };
    for (const Case c : {Case{0.95f, 2.0}, Case{0.4f, 2.0}, Case{0.4f, 0.0}, Case{0.95f, 2.0, 0.0f, 1.0f}}) {
        const std::string name =
            "bake_glint_" + std::to_string(int(c.shininess * 100)) + (c.coat > 0.0f ? "_coated" : "");
        const float coatRoughness = 0.05f;
        const fs::path glb = floorAndWall(name, glm::vec3(0.0f), 1.0f, glm::vec3(c.base), 1.0f, toSunIn, c.shininess,
                                          c.coat, coatRoughness);
        const bake::LightmapRegion r = floorRegion(glb);
        const double footprint = c.footprintTexels / kTexelsPerMeter;
        const double alpha = shading::ggxAlpha(shading::roughnessFromShininess(c.shininess));
        for (const char* backend : kBackends) {
            SCOPED_TRACE(std::string(backend) + ", shininess " + std::to_string(c.shininess) + ", footprint " +
                         std::to_string(c.footprintTexels) + ", coat " + std::to_string(c.coat));
            auto out = runGraph(bakeGraph(glb, sky,
                                          {{"samples", c.shininess > 0.5f ? 4096 : 2048},
                                           {"sky_scale", 0.0},
                                           {"filter_iterations", 0},
                                           {"caustic_footprint", c.footprintTexels}},
                                          backend));
            const glm::dvec3 sunE = rgb(out.at("sh"), SKY_TEXEL_SUN_ILLUMINANCE, 0);
            const glm::vec3 toSun = glm::normalize(glm::vec3(rgb(out.at("sh"), SKY_TEXEL_SUN_DIRECTION, 0)));
            const glm::vec3 nWall(1.0f, 0.0f, 0.0f);
            // The wall's face x = 0, y in [0, 2], |z| < 12 (its tails beyond carry < 0.1 %), on a midpoint grid.
            auto expected = [&](double d) {
                const double dy = 0.02, dz = 0.02;
                double sum = 0.0;
                for (double y = dy / 2; y < kWallHeight; y += dy)
                    for (double z = -12.0 + dz / 2; z < 12.0; z += dz) {
                        const glm::dvec3 toFloor = glm::dvec3(d, 0.0, 0.0) - glm::dvec3(0.0, y, z);
                        const double dist = glm::length(toFloor);
                        const glm::vec3 v(toFloor / dist);
                        // Each lobe's alpha widened to the footprint's, as roughness (alpha = roughness^2).
                        auto widened = [&](double a) {
                            a = c.footprintTexels > 0.0 ? std::max(a, footprint / (2.0 * dist)) : a;
                            return float(std::sqrt(std::min(a, 1.0)));
                        };
                        const glm::vec2 coat(c.coat, widened(coatRoughness * coatRoughness));
                        const double f =
                            shading::brdfCosineSheen(nWall, nWall, v, toSun, glm::vec3(c.base), 1.0f, widened(alpha),
                                                     glm::vec4(0.04f, 0.04f, 0.04f, 1.0f), coat, glm::vec4(0.0f))
                                .r;
                        sum += sunE.r * f * double(v.x) * (y / dist) / (dist * dist) * dy * dz;
                    }
                return sum;
            };
            std::printf("%s, shininess %.2f, footprint %.0f texels, coat %.0f: sun %.0f lux, caustic at 1 m %.0f lux\n",
                        backend, c.shininess, c.footprintTexels, c.coat, sunE.r, expected(1.0));
            // Columns to 3.5 m (the mirror image of the wall's top edge is at 2 m: beyond it, only the widened
            // lobe's light), each within 6 %, their sum 2 %.
            expectProfile(out.at("lightmap"), r, expected, 0.06, 0.02, 3.5);
        }
    }
    bake::LightmapBakeSettings exact, spread;
    spread.causticFootprint = 2.0f;
    scene::Scene empty;
    EXPECT_NE(bake::lightmapCacheKey(empty, exact, 1).hash, bake::lightmapCacheKey(empty, spread, 1).hash);
}

// A closed box whose six walls glow with Le and reflect with the material of (base, shininess 0 = roughness 1):
// the floor's irradiance after k bounces. Lambertian walls (specular strength 0) give pi Le sum rho^k exactly; the
// default dielectric (GGX + Lambert) after one bounce pi Le (1 + A), A the cosine-weighted mean of the directional
// albedo of core/shading's brdfCosine (the CPU mirror of brdf.glsl): the bake reflects with the path tracer's material.
// panel: also a single-sided quad of the same material across half the box at mid-height (y = 0, z < 0), facing up.
fs::path emissiveBox(const std::string& name, float Le, float base, float specular, bool panel = false,
                     float metallic = 0.0f) {
    SceneBuilder b(name);
    const uint32_t material = b.material("glow", glm::vec3(base), metallic, 0.0f);
    b.s.materials[material].specular = specular;
    b.s.materials[material].emissiveFactor = glm::vec3(1.0f);
    b.s.materials[material].emissiveStrength = Le;
    // Five walls facing inwards, and the floor (y = -1) lightmapped on its own.
    const glm::vec3 half(2.0f, 1.0f, 2.0f);
    std::vector<Tri> walls, floor;
    for (int axis = 0; axis < 3; ++axis)
        for (float sign : {-1.0f, 1.0f}) {
            glm::vec3 n(0.0f), u(0.0f), v(0.0f);
            n[axis] = -sign;
            u[(axis + 1) % 3] = half[(axis + 1) % 3];
            v[(axis + 2) % 3] = half[(axis + 2) % 3];
            addQuad(axis == 1 && sign < 0.0f ? floor : walls, sign * half[axis] * glm::vec3(axis == 0, axis == 1, axis == 2), u, v, n);
        }
    for (Tri& t : floor)
        for (scene::Vertex* v : {&t.a, &t.b, &t.c}) v->uv1 = {(v->position.x + half.x) / 4.0f, (v->position.z + half.z) / 4.0f};
    const uint32_t floorMesh = b.mesh("floor", floor, material);
    b.s.primitives[b.s.meshes[floorMesh].firstPrimitive].lightmapUvs = true;
    b.node("floor", static_cast<int32_t>(floorMesh));
    b.node("walls", static_cast<int32_t>(b.mesh("walls", walls, material)));
    if (panel) {
        std::vector<Tri> shelf;
        addQuad(shelf, {0.0f, 0.0f, -half.z / 2}, {half.x, 0.0f, 0.0f}, {0.0f, 0.0f, half.z / 2}, {0.0f, 1.0f, 0.0f});
        b.node("panel", static_cast<int32_t>(b.mesh("panel", shelf, material)));
    }
    b.camera({0.0f, 0.0f, 0.0f}, {0.0f, -1.0f, 1.0f}, 0.9f);
    b.sun({0.3f, 1.0f, 0.2f});
    return b.write();
}

// Mean and worst relative texel error of the floor's lightmap against `expected`.
void expectEmissiveBox(const fs::path& glb, int bounces, double expected, double scale) {
    for (const char* backend : kBackends) {
        SCOPED_TRACE(backend);
        const bake::LightmapRegion r = floorRegion(glb);
        auto out = runGraph(bakeGraph(glb, uniformSky(glb, 1000.0),
                                      {{"samples", 64},
                                       {"max_bounces", bounces},
                                       {"sun_scale", 0.0},
                                       {"sky_scale", 0.0},
                                       {"emissive_scale", scale}},
                                      backend));
        double sum = 0.0, worst = 0.0;
        for (uint32_t j = 0; j < r.size; ++j)
            for (uint32_t i = 0; i < r.size; ++i) {
                const double e = out.at("lightmap").at(int(r.x + i), int(r.y + j))[0];
                sum += e;
                worst = std::max(worst, std::abs(e / expected - 1.0));
            }
        const double mean = sum / (double(r.size) * r.size);
        std::printf("%s: emissive box %s, %d bounces: mean %.1f lux, expected %.1f (worst texel %.3f off)\n", backend,
                    glb.stem().string().c_str(), bounces, mean, expected, worst);
        EXPECT_NEAR(mean / expected, 1.0, 0.01) << bounces << " bounces";
        EXPECT_LT(worst, 0.1);
    }
}

TEST_F(LightmapBake, ClosedEmissiveBoxFollowsTheGeometricSeries) {
    const float Le = 100.0f, base = 0.5f;
    const double scale = 2.0; // emissive_scale multiplies every emitter the paths find
    const fs::path glb = emissiveBox("bake_emissive_box", Le, base, 0.0f);
    for (int bounces : {1, 4}) {
        double series = 0.0;
        for (int k = 0; k <= bounces; ++k) series += std::pow(double(base), k);
        expectEmissiveBox(glb, bounces, kPi * scale * Le * series, scale);
    }
}

// The same box of rough white metal (F0 1, roughness 1) baked with multiscatter: the compensated lobe reflects all it
// receives for every view (its directional albedo is 1, where single scattering keeps 31 % seen head-on), so the
// walls' radiance after k reflections is Le (k + 1) and the floor's irradiance after N bounces pi Le (N + 1). Bound
// 3 % on the mean (the albedo fit's relative error, 1.9 % at worst, at each bounce), 15 % per texel (256 paths: the
// compensated weights, up to x3.3 at roughness 1, are noisy; measured 8 %); single scattering reads less than 80 % of
// it at 3 bounces.
TEST_F(LightmapBake, MultiscatterWhiteMetalBoxKeepsEveryBounce) {
    const float Le = 100.0f;
    const fs::path glb = emissiveBox("bake_multiscatter_box", Le, 1.0f, 1.0f, false, 1.0f);
    const bake::LightmapRegion r = floorRegion(glb);
    for (const char* backend : kBackends)
        for (const int bounces : {1, 3}) {
            SCOPED_TRACE(std::string(backend) + ", " + std::to_string(bounces) + " bounces");
            double means[2] = {0.0, 0.0}, worst = 0.0;
            const double expected = kPi * Le * (bounces + 1);
            for (const bool ms : {true, false}) {
                if (!ms && bounces == 1) continue;
                auto out = runGraph(bakeGraph(glb, uniformSky(glb, 1000.0),
                                              {{"samples", 256},
                                               {"max_bounces", bounces},
                                               {"sun_scale", 0.0},
                                               {"sky_scale", 0.0},
                                               {"multiscatter", ms}},
                                              backend));
                double sum = 0.0;
                for (uint32_t j = 0; j < r.size; ++j)
                    for (uint32_t i = 0; i < r.size; ++i) {
                        const double e = out.at("lightmap").at(int(r.x + i), int(r.y + j))[0];
                        sum += e;
                        if (ms) worst = std::max(worst, std::abs(e / expected - 1.0));
                    }
                means[ms ? 0 : 1] = sum / (double(r.size) * r.size) / expected;
            }
            std::printf("%s: white metal box, %d bounces: floor / pi Le (N + 1) %.4f with multiscatter (worst texel "
                        "%.3f off)",
                        backend, bounces, means[0], worst);
            if (bounces == 3) std::printf(", %.4f without", means[1]);
            std::printf("\n");
            EXPECT_NEAR(means[0], 1.0, 0.03);
            EXPECT_LT(worst, 0.15);
            if (bounces == 3) {
                EXPECT_LT(means[1], 0.8);
            }
        }
    // A bake with it is not one without it (the cache key; the bakes above do not use the cache).
    bake::LightmapBakeSettings single, compensated;
    compensated.multiscatter = true;
    scene::Scene empty;
    EXPECT_NE(bake::lightmapCacheKey(empty, single, 1).hash, bake::lightmapCacheKey(empty, compensated, 1).hash);
}

// One back-face rule for both integrators, render.pathtrace's: past a path's first surface, the back of a single-sided
// triangle is passed through (the rasteriser culls it). The box above with a single-sided panel of the same material
// across half of it, facing up: seen from below the panel is not there, seen from above it emits and reflects like
// every wall, so radiance is still the same everywhere and the floor's irradiance is the same series. Paths that
// bounce off a lower wall up into the panel's back must go on through it (ending them there darkens the floor);
// a floor texel's own first ray into the panel's back starts "inside" and is left out, which in a uniform field
// changes nothing either.
TEST_F(LightmapBake, BouncesPassThroughTheBackOfASingleSidedSurface) {
    const float Le = 100.0f, base = 0.5f;
    const double scale = 2.0;
    const fs::path glb = emissiveBox("bake_emissive_box_panel", Le, base, 0.0f, true);
    const int bounces = 4;
    double series = 0.0;
    for (int k = 0; k <= bounces; ++k) series += std::pow(double(base), k);
    expectEmissiveBox(glb, bounces, kPi * scale * Le * series, scale);
}

TEST_F(LightmapBake, BouncesReflectWithTheFullMaterial) {
    const float Le = 100.0f, base = 0.5f;
    const double scale = 2.0;
    const fs::path glb = emissiveBox("bake_emissive_box_ggx", Le, base, 1.0f);
    // A = 2 int_0^1 albedo(mu) mu dmu, midpoint rule over mu.
    const float roughness = shading::roughnessFromShininess(0.0f);
    double A = 0.0;
    const int steps = 64;
    for (int i = 0; i < steps; ++i) {
        const double mu = (i + 0.5) / steps;
        A += 2.0 * mu / steps * directionalAlbedo(mu, 128, [&](glm::vec3 n, glm::vec3 v, glm::vec3 l) {
                 return shading::brdfCosine(n, v, l, glm::vec3(base), 0.0f, roughness).g;
             });
    }
    std::printf("cosine-weighted albedo of (0.5, roughness %.2f): %.4f (a Lambertian 0.5: 0.5)\n", roughness, A);
    ASSERT_GT(std::abs(A - base), 0.015) << "the case must tell the full material from a Lambertian one";
    expectEmissiveBox(glb, 1, kPi * scale * Le * (1.0 + A), scale);
}

// Builds the museum as scene.museum does with these params, and its lightmap texels as the bake saw them.
struct MuseumTexels {
    scene::Scene scene;
    bake::LightmapAtlas atlas;
    bake::LightmapTexels texels;
};

TEST_F(LightmapBake, MuseumBakeIsFiniteLitWhereTheSunIsAndCached) {
    const float tpm = 2.0f;
    json nodes = {{"scene", {{"type", "scene.museum"}, {"params", {{"texture_size", 64}, {"camera", "static"}}}}},
                  {"sky",
                   {{"type", "sky.procedural"},
                    {"in", {{"scene", "scene.scene"}}},
                    {"params", {{"size", 16}, {"sun_in_cubemap", false}}}}},
                  {"bake",
                   {{"type", "bake.lightmap"},
                    {"in", {{"scene", "scene.scene"}, {"sky", "sky.cubemap"}, {"sky_sh", "sky.sh"}}},
                    // The GPU integrator: the last step edits its shader (the CPU one is compiled in).
                    {"params",
                     {{"samples", 4},
                      {"texels_per_meter", tpm},
                      {"probe_spacing", 6.0},
                      {"probe_rays", 16},
                      {"backend", "gpu"}}}}}};
    const json g = graph(nodes, {{"lightmap", "bake.lightmap"}, {"volume", "bake.volume"}, {"sh", "sky.sh"}}, 16, 16);

    // A cache of its own, so the first run bakes.
    const fs::path cacheDir = fs::path(VITRINE_TEST_OUT) / "museum_bake_cache";
    fs::remove_all(cacheDir);
    ScopedEnv env("VITRINE_CACHE_DIR", cacheDir.string());
    auto first = runGraph(g);
    std::vector<fs::path> files;
    for (const auto& e : fs::directory_iterator(cacheDir / "bake" / "lightmap")) files.push_back(e.path());
    ASSERT_EQ(files.size(), 1u) << "the bake is stored once";
    const auto stamp = fs::last_write_time(files[0]);

    // Every texel and probe finite.
    for (const char* name : {"lightmap", "volume"})
        for (float v : first.at(name).pixels) ASSERT_TRUE(std::isfinite(v)) << name;

    // The texels the bake integrated, and the sun's visibility at each from the CPU BVH.
    scene::MuseumOptions mo;
    mo.textureSize = 64;
    const scene::Scene s = scene::buildMuseum(mo);
    bake::LightmapAtlasOptions ao;
    ao.texelsPerMeter = tpm;
    const bake::LightmapAtlas atlas = bake::planLightmapAtlas(s, ao);
    ASSERT_EQ(first.at("lightmap").width, int(atlas.width));
    ShaderCompiler shaders;
    GpuScene gpuScene(gpu(), shaders, s);
    const scene::ScenePose pose = s.evaluate(0.0);
    gpuScene.update(pose, pose, CameraFrame{});
    const bake::LightmapTexels t = bake::rasterizeLightmapTexels(gpu(), shaders, gpuScene, s, atlas);
    const accel::SceneBvh bvh = accel::SceneBvh::build(s);
    const auto top = bvh.topLevel(pose);
    const glm::vec3 toSun = glm::normalize(glm::vec3(rgb(first.at("sh"), SKY_TEXEL_SUN_DIRECTION, 0)));
    size_t covered = 0, sunlit = 0, blackSunlit = 0;
    for (uint32_t y = 0; y < t.height; ++y)
        for (uint32_t x = 0; x < t.width; ++x) {
            const size_t i = t.index(x, y);
            if (t.region[i] < 0) continue;
            ++covered;
            if (glm::dot(t.normal[i], toSun) < 0.2f) continue;
            accel::Ray ray;
            ray.origin = t.position[i] + t.normal[i] * 1e-3f;
            ray.direction = toSun;
            if (accel::traceAny(bvh.arrays(), top, ray)) continue;
            ++sunlit;
            const float* e = first.at("lightmap").at(int(x), int(y));
            if (!(e[0] + e[1] + e[2] > 0.0f)) ++blackSunlit;
        }
    std::printf("museum bake: %zu covered texels, %zu sunlit, %zu of them black\n", covered, sunlit, blackSunlit);
    EXPECT_GT(sunlit, 500u);
    EXPECT_LE(blackSunlit, sunlit / 200) << "more than 0.5 % of the sunlit texels are black";

    // A second run loads the bake: the file is not rewritten and the result is the same.
    auto second = runGraph(g);
    EXPECT_EQ(fs::last_write_time(files[0]), stamp) << "the second run baked again";
    EXPECT_EQ(second.at("lightmap").pixels, first.at("lightmap").pixels);
    EXPECT_EQ(second.at("volume").pixels, first.at("volume").pixels);

    // A damaged file is not used: the bake runs again (same seeds, same result) and replaces it.
    fs::resize_file(files[0], fs::file_size(files[0]) / 2);
    auto third = runGraph(g);
    EXPECT_EQ(third.at("lightmap").pixels, first.at("lightmap").pixels);
    EXPECT_GT(fs::file_size(files[0]), 0u);
    EXPECT_NE(fs::last_write_time(files[0]), stamp);

    // Another sky is other lighting: baked anew under another key, with another result.
    json hazy = g;
    hazy["nodes"]["sky"]["params"]["turbidity"] = 6.0;
    auto fourth = runGraph(hazy);
    size_t stored = 0;
    for (const auto& e : fs::directory_iterator(cacheDir / "bake" / "lightmap")) stored += e.is_regular_file() ? 1 : 0;
    EXPECT_EQ(stored, 2u) << "a changed sky must not reuse the bake of the first";
    EXPECT_NE(fourth.at("lightmap").pixels, first.at("lightmap").pixels);

    // An edit of the bake's own code (its sky term, in a copy of shaders/) is baked anew: the key holds the bake
    // shaders' SPIR-V, so neither a user's edit nor a mutation run is served the stale file.
    const fs::path edited = fs::path(VITRINE_TEST_OUT) / "museum_bake_shaders";
    fs::remove_all(edited);
    fs::copy(defaultShaderDir(), edited, fs::copy_options::recursive);
    {
        std::ifstream in(edited / "bake" / "lightmap.comp");
        std::stringstream source;
        source << in.rdbuf();
        std::string text = source.str();
        const std::string from = "* push.scales.y;";
        const size_t at = text.find(from);
        ASSERT_NE(at, std::string::npos) << "the bake shader's sky term moved; update this test";
        text.replace(at, from.size(), "* push.scales.y * 0.5;");
        std::ofstream(edited / "bake" / "lightmap.comp") << text;
    }
    ScopedEnv shaderDir("VITRINE_SHADER_DIR", edited.string());
    auto fifth = runGraph(g);
    stored = 0;
    for (const auto& e : fs::directory_iterator(cacheDir / "bake" / "lightmap")) stored += e.is_regular_file() ? 1 : 0;
    EXPECT_EQ(stored, 3u) << "an edited bake shader must not load the bake of the unedited one";
    EXPECT_NE(fifth.at("lightmap").pixels, first.at("lightmap").pixels);
}

// Mean luminance of each block of a bx x by grid over the image.
std::vector<double> blockMeans(const Image& img, int bx, int by) {
    std::vector<double> means(size_t(bx) * by, 0.0);
    for (int y = 0; y < img.height; ++y)
        for (int x = 0; x < img.width; ++x) {
            const float* p = img.at(x, y);
            means[size_t(y * by / img.height) * bx + x * bx / img.width] += 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
        }
    for (double& m : means) m /= double(img.width / bx) * (img.height / by);
    return means;
}

// Mean |log(a / b)| over the blocks: 0 when the light is distributed alike, log 2 when off by a factor 2.
double logBlockError(const Image& a, const Image& b) {
    const std::vector<double> ma = blockMeans(a, 8, 4), mb = blockMeans(b, 8, 4);
    double sum = 0.0;
    for (size_t i = 0; i < ma.size(); ++i) sum += std::abs(std::log(std::max(ma[i], 1e-6) / std::max(mb[i], 1e-6)));
    return sum / double(ma.size());
}

TEST_F(LightmapBake, MuseumLightIsDistributedMoreLikeTheReference) {
    const fs::path root = fs::path(VITRINE_SOURCE_DIR) / "graphs";
    // The static shot (the walkthrough's camera moves, so the reference would restart every frame), HDR.
    const std::vector<std::string> common = {"frame.width=64", "frame.height=36", "scene.params.camera=static",
                                             "scene.params.texture_size=64"};
    auto hdr = [&](const std::string& file, std::vector<std::string> sets, const std::string& output) {
        sets.insert(sets.begin(), common.begin(), common.end());
        sets.push_back("outputs.hdr=" + output);
        return runGraphFile((root / file).string(), sets).at("hdr");
    };
    // The lightmaps' own effect: the museum's lighting without the terms that sit on top of the baked light (the
    // reflection probes' specular, screen-space AO, the temporal normal filter), in both graphs (ssr.composite, which
    // weighs SSR by the probes' LUT, then by Karis' fit as the sky's term is weighed).
    const nlohmann::json bakedOnly = nlohmann::json::parse(R"({"nodes": {
        "capture": null, "ibl": null, "ao": null, "ao_accumulate": null, "gfilter": null,
        "lighting": {"in": {"ibl_specular": null, "ibl_diffuse": null, "ao": null, "normal": "gbuffer.normal"}},
        "ssr_composite": {"in": {"brdf_lut": null}}}})");
    auto lit = [&](const std::string& file, std::vector<std::string> sets) {
        sets.insert(sets.begin(), common.begin(), common.end());
        sets.push_back("outputs.hdr=lighting.color");
        nlohmann::json doc = loadGraphDocument(root / file, sets);
        doc.merge_patch(bakedOnly);
        return runGraph(doc).at("hdr");
    };
    const Image gi = lit("museum.json", {"bake.params.samples=8", "bake.params.texels_per_meter=2"});
    const Image noGi = lit("variants/museum_no_gi.json", {});
    const Image reference = hdr("variants/museum_reference.json", {"pathtrace.params.spp=256", "pathtrace.params.target_noise=0"},
                                 "pathtrace.color");
    const double eGi = logBlockError(gi, reference), eNoGi = logBlockError(noGi, reference);
    {
        const auto a = blockMeans(gi, 8, 4), b = blockMeans(noGi, 8, 4), r = blockMeans(reference, 8, 4);
        for (int y = 0; y < 4; ++y) {
            for (int x = 0; x < 8; ++x) std::printf(" %5.2f/%5.2f", a[y * 8 + x] / r[y * 8 + x], b[y * 8 + x] / r[y * 8 + x]);
            std::printf("\n");
        }
    }
    std::printf("mean |log luminance ratio| to the reference over 8x4 blocks: lightmaps %.4f, without %.4f\n", eGi,
                eNoGi);
    // Against a 256-spp reference both tracers give 0.196 with lightmaps and 0.241-0.245 without (ratio 0.80); at the
    // former 64 spp the reference's own noise moved the ratio between 0.69 (GPU tracer) and 0.87 (CPU tracer), so the
    // reference has 256 spp now and the bound leaves room for its remaining noise.
    EXPECT_LT(eGi, 0.9 * eNoGi) << "the lightmaps must bring the light's distribution nearer the reference";
    EXPECT_LT(eGi, std::log(1.5)) << "within a factor 1.5 of the reference on average";
}

} // namespace
} // namespace vitrine::test
