// core/accel traversal on the CPU (the mirror of shaders/accel/bvh.glsl) against a brute-force loop over
// every triangle: the same triangle at the same t; watertightness on closed meshes; the dynamic level
// following the pose; the BVH through the bake cache.
#include "tests/unit/accel/accel_scenes.hpp"
#include "tests/unit/accel/compare_hits.hpp"

#include "core/scene/deformation.hpp"
#include "core/scene/gltf.hpp"
#include "core/scene/museum.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>

namespace vitrine::accel {
namespace {

using namespace test;

std::vector<Hit> traceAll(const SceneBvh& bvh, std::span<const GpuBvhInstance> top, const std::vector<Ray>& rays) {
    std::vector<Hit> hits;
    for (const Ray& r : rays)
        hits.push_back(traceClosest(bvh.arrays(), top, r));
    return hits;
}

TEST(BvhTraversal, ClosestHitMatchesBruteForceOnRandomSoup) {
    scene::Scene s = randomSoup(3000, 11);
    SceneBvh bvh = SceneBvh::build(s);
    WorldTriangles w = worldTriangles(s);
    scene::Aabb box = s.bounds;
    box.expand(box.min - 0.5f);
    box.expand(box.max + 0.5f);
    std::vector<Ray> rays = randomRays(w, box, 20000, 5);
    size_t hits, ties;
    expectSameHits(bvh, w, rays, traceAll(bvh, bvh.topLevel({}), rays), hits, ties);
    EXPECT_GT(hits, rays.size() / 2);
    std::printf("soup: %zu rays, %zu hits, %zu ties\n", rays.size(), hits, ties);
}

// After a refit moved every triangle of the soup (movedTriangle: a twist and shifts of up to 0.4 per axis), traversal
// finds what brute force over the moved triangles finds.
TEST(BvhTraversal, ClosestHitMatchesBruteForceAfterARefit) {
    scene::Scene s = randomSoup(3000, 5);
    SceneBvh bvh = SceneBvh::build(s);
    BvhArrays a = bvh.arrays();
    BvhBottomLevel level = bvh.levels()[0];
    refitBottomLevel(level, a, [&](const GpuBvhTriangleRef& r, glm::vec3(&v)[3]) { movedTriangle(s, r, v); });
    WorldTriangles w = worldTriangles(s);
    scene::Aabb box;
    for (size_t t = 0; t < w.refs.size(); ++t) {
        glm::vec3 v[3];
        movedTriangle(s, w.refs[t], v);
        for (int k = 0; k < 3; ++k)
            box.expand(w.v[3 * t + k] = v[k]);
    }
    std::vector<GpuBvhInstance> top = bvh.topLevel({});
    top[0].boundsMin = glm::vec4(level.bounds.min, 0.0f);
    top[0].boundsMax = glm::vec4(level.bounds.max, 0.0f);
    box.expand(box.min - 0.5f);
    box.expand(box.max + 0.5f);
    std::vector<Ray> rays = randomRays(w, box, 20000, 6);
    std::vector<Hit> found;
    for (const Ray& r : rays)
        found.push_back(traceClosest(a, top, r));
    size_t hits, ties;
    expectSameHits(bvh, w, rays, found, hits, ties);
    EXPECT_GT(hits, rays.size() / 2);
    std::printf("refit soup: %zu rays, %zu hits, %zu ties\n", rays.size(), hits, ties);
}

// Deforming meshes (scene::Deformation: a moving skin, animated morph weights) get bottom levels of their own, refit
// to the posed vertices (SceneBvh::refit): the corpus's two-bone bend and morphing cube (whose nodes the animation
// makes dynamic), and a second, unanimated node drawing the same cube 3 m above (a static instance whose vertices
// still deform: the weights are the mesh's), at rest and posed, are hit where brute force over their posed triangles
// hits them. Three quarters of the rays aim at posed triangles, which a BVH left at rest would miss.
TEST(BvhDeforming, SkinnedAndMorphedMeshesAreHitWhereTheyArePosed) {
    for (const char* file : {"skin_bend.gltf", "morph_animated.gltf"}) {
        SCOPED_TRACE(file);
        scene::Scene s = scene::loadGltf(std::filesystem::path(VITRINE_CORPUS_DIR) / file);
        if (std::string(file) == "morph_animated.gltf") {
            const auto cube =
                std::find_if(s.nodes.begin(), s.nodes.end(), [](const scene::Node& n) { return n.mesh >= 0; });
            ASSERT_NE(cube, s.nodes.end());
            scene::Node still = *cube;
            still.local.translation += glm::vec3(0.0f, 3.0f, 0.0f);
            s.roots.push_back(static_cast<uint32_t>(s.nodes.size()));
            s.nodes.push_back(still);
            s.finalize();
            ASSERT_EQ(s.instances.size(), 2u);
            EXPECT_FALSE(s.instances[1].dynamic);
        }
        const scene::Deformation deformation(s);
        ASSERT_TRUE(deformation.any());
        SceneBvh bvh = SceneBvh::build(s);
        ASSERT_EQ(bvh.deformedLevels().size(), 1u);
        EXPECT_EQ(bvh.levels()[0].triangleCount, 0u); // nothing static: every instance's mesh deforms
        EXPECT_EQ(bvh.dynamicInstances().size(), s.instances.size());
        float largestMove = 0.0f;
        for (double t : {0.0, 0.4, 1.0, 2.0}) {
            const scene::ScenePose pose = s.evaluate(t);
            const std::vector<scene::Vertex> posed = deformation.posedVertices(pose);
            for (size_t v = 0; v < posed.size(); ++v)
                largestMove = std::max(largestMove, glm::length(posed[v].position - s.vertices[v].position));
            bvh.refit(s, posed);
            WorldTriangles w = worldTriangles(s, pose, posed);
            scene::Aabb box;
            for (const glm::vec3& v : w.v)
                box.expand(v);
            box.expand(box.min - 1.0f);
            box.expand(box.max + 1.0f);
            // From random points of the box: at the inside of random posed triangles (edges would tie between the few
            // triangles), and every fourth in a random direction.
            std::mt19937 rng(8 + static_cast<uint32_t>(4 * t));
            std::uniform_real_distribution<float> u(0.0f, 1.0f);
            std::vector<Ray> rays(3000);
            for (size_t i = 0; i < rays.size(); ++i) {
                Ray& r = rays[i];
                r.origin = box.min + glm::vec3(u(rng), u(rng), u(rng)) * (box.max - box.min);
                const size_t k = rng() % w.refs.size();
                const float a = 0.05f + 0.6f * u(rng), b = 0.05f + 0.3f * u(rng);
                const glm::vec3 target =
                    w.v[3 * k] + a * (w.v[3 * k + 1] - w.v[3 * k]) + b * (w.v[3 * k + 2] - w.v[3 * k]);
                r.direction = i % 4 == 0 ? randomUnit(rng) : target - r.origin;
            }
            size_t hits, ties;
            expectSameHits(bvh, w, rays, traceAll(bvh, bvh.topLevel(pose), rays), hits, ties);
            EXPECT_GT(hits, rays.size() / 2) << "t = " << t;
        }
        EXPECT_GT(largestMove, 0.9f); // the tip of the bend moves by 1.4, the cube's face by 1
    }
}

// A BVH from the bake cache knows its deforming levels as a built one does (they are derived, not stored).
TEST(BvhDeforming, TheCachedBvhRefitsToo) {
    namespace fs = std::filesystem;
    const fs::path root = fs::temp_directory_path() / ("vitrine_bvh_deform_test_" + std::to_string(::getpid()));
    fs::remove_all(root);
    BakeCache cache(root);
    const scene::Scene s = scene::loadGltf(fs::path(VITRINE_CORPUS_DIR) / "skin_bend.gltf");
    SceneBvh::CacheStatus status;
    const SceneBvh built = SceneBvh::loadOrBuild(s, cache, {}, &status);
    ASSERT_TRUE(status.stored);
    const SceneBvh loaded = SceneBvh::loadOrBuild(s, cache, {}, &status);
    EXPECT_TRUE(status.fromCache);
    EXPECT_EQ(loaded.deformedLevels(), built.deformedLevels());
    EXPECT_FALSE(loaded.deformedLevels().empty());
    fs::remove_all(root);
}

class MuseumBvh : public ::testing::Test {
protected:
    static void SetUpTestSuite() {
        scene::MuseumOptions o;
        o.textureSize = 16;
        sScene = std::make_unique<scene::Scene>(scene::buildMuseum(o));
        sBvh = std::make_unique<SceneBvh>(SceneBvh::build(*sScene));
    }
    static void TearDownTestSuite() {
        sBvh.reset();
        sScene.reset();
    }
    static inline std::unique_ptr<scene::Scene> sScene;
    static inline std::unique_ptr<SceneBvh> sBvh;
};

TEST_F(MuseumBvh, ClosestHitMatchesBruteForceWithTheRobotPosed) {
    // 3.7 s into the walk: the robot is away from its rest pose, so its hits go through the dynamic level.
    scene::ScenePose pose = sScene->evaluate(3.7);
    WorldTriangles w = worldTriangles(*sScene, pose);
    std::vector<Ray> rays = randomRays(w, sScene->bounds, 450, 7);
    // And rays at the robot: the last instances are its parts.
    std::vector<uint32_t> robot;
    for (uint32_t i = 0; i < w.refs.size(); ++i)
        if (sScene->instances[w.refs[i].instance].dynamic) robot.push_back(i);
    ASSERT_FALSE(robot.empty());
    std::mt19937 rng(3);
    for (int i = 0; i < 150; ++i) {
        uint32_t t = robot[rng() % robot.size()];
        glm::vec3 c = (w.v[3 * t] + w.v[3 * t + 1] + w.v[3 * t + 2]) / 3.0f;
        Ray r;
        r.origin = c + 3.0f * randomUnit(rng);
        r.direction = c - r.origin;
        rays.push_back(r);
    }
    size_t hits, ties;
    expectSameHits(*sBvh, w, rays, traceAll(*sBvh, sBvh->topLevel(pose), rays), hits, ties);
    EXPECT_GT(hits, rays.size() / 2);
    std::printf("museum: %zu rays, %zu hits, %zu ties\n", rays.size(), hits, ties);
}

TEST_F(MuseumBvh, AnyHitAgreesWithClosestHit) {
    scene::ScenePose pose = sScene->evaluate(1.0);
    std::vector<GpuBvhInstance> top = sBvh->topLevel(pose);
    WorldTriangles w = worldTriangles(*sScene, pose);
    std::vector<Ray> rays = randomRays(w, sScene->bounds, 3000, 9);
    size_t occluded = 0;
    for (size_t i = 0; i < rays.size(); ++i) {
        Ray r = rays[i];
        Hit closest = traceClosest(sBvh->arrays(), top, r);
        // Shadow rays toward a point before, and just past, the closest hit.
        r.tmax = closest.valid() ? closest.t * 0.999f : 5.0f;
        EXPECT_FALSE(traceAny(sBvh->arrays(), top, r)) << "ray " << i;
        if (!closest.valid()) continue;
        r.tmax = closest.t * 1.001f;
        EXPECT_TRUE(traceAny(sBvh->arrays(), top, r)) << "ray " << i;
        // tmin past the first hit finds something farther, never that one again.
        r.tmin = closest.t * 1.001f;
        r.tmax = std::numeric_limits<float>::infinity();
        Hit next = traceClosest(sBvh->arrays(), top, r);
        if (next.valid()) {
            EXPECT_GT(next.t, r.tmin);
        }
        ++occluded;
    }
    EXPECT_GT(occluded, rays.size() / 2);
}

// Rays from inside a closed mesh at its edges and vertices: none may leak, each meets the surface at t = 1.
void expectWatertight(const scene::Scene& s, const scene::ScenePose& pose, glm::vec3 center, float radius, size_t count,
                      uint32_t seed) {
    SceneBvh bvh = SceneBvh::build(s);
    std::vector<GpuBvhInstance> top = bvh.topLevel(pose);
    WorldTriangles w = worldTriangles(s, pose);
    std::vector<uint32_t> indices(w.v.size());
    for (uint32_t i = 0; i < indices.size(); ++i)
        indices[i] = i;
    std::vector<Ray> rays = edgeRays(w.v, indices, center, radius, count, seed);
    size_t leaks = 0, far = 0;
    for (const Ray& r : rays) {
        Hit h = traceClosest(bvh.arrays(), top, r);
        if (!h.valid())
            ++leaks;
        else if (std::abs(h.t - 1.0f) > 1e-3f)
            ++far;
    }
    EXPECT_EQ(leaks, 0u) << "of " << rays.size() << " rays";
    EXPECT_EQ(far, 0u) << "rays that met the surface away from t = 1";
}

TEST(BvhWatertight, NoRayLeaksThroughEdgesOfAStaticSphere) {
    // A rotated, scaled, moved icosphere (20480 triangles): the static level holds it pre-transformed.
    scene::Scene s;
    addRootNode(
        s, "sphere", addMesh(s, "sphere", icosphere(5)),
        transform({0.3f, 1.2f, -0.7f}, glm::angleAxis(0.4f, glm::normalize(glm::vec3(1, 1, 0))), glm::vec3(1.7f)));
    s.finalize();
    expectWatertight(s, {}, {0.3f, 1.2f, -0.7f}, 0.8f, 1000000, 17);
}

TEST(BvhWatertight, NoRayLeaksThroughEdgesOfAMovingCube) {
    // A finely tessellated cube (27648 triangles, flat boxes along its faces) as a dynamic instance: rays
    // are transformed into its object space.
    scene::Scene s;
    uint32_t node = addRootNode(s, "cube", addMesh(s, "cube", tessellatedCube(48)),
                                transform({0, 0, 0}, glm::angleAxis(0.3f, glm::normalize(glm::vec3(0, 1, 1)))));
    animateTranslation(s, node, {0.0f, 0.0f, 0.0f}, {2.0f, 1.0f, 0.0f});
    s.finalize();
    ASSERT_TRUE(s.instances[0].dynamic);
    expectWatertight(s, s.evaluate(0.5), {1.0f, 0.5f, 0.0f}, 0.5f, 1000000, 23);
}

TEST(BvhDynamic, MovedInstanceIsHitAtItsNewPlace) {
    // A static floor and a box that moves 4 m along +x between t = 0 and t = 1.
    scene::Scene s;
    IndexedMesh floor;
    floor.positions = {{-10, 0, -10}, {10, 0, -10}, {10, 0, 10}, {-10, 0, 10}};
    floor.indices = {0, 2, 1, 0, 3, 2};
    addRootNode(s, "floor", addMesh(s, "floor", floor));
    uint32_t box = addRootNode(s, "box", addMesh(s, "box", tessellatedCube(2)), transform({0, 1, 0}));
    animateTranslation(s, box, {0, 1, 0}, {4, 1, 0});
    s.finalize();
    SceneBvh bvh = SceneBvh::build(s);
    ASSERT_EQ(bvh.dynamicInstances().size(), 1u);
    const uint32_t boxInstance = bvh.dynamicInstances()[0].instance;

    auto down = [&](const scene::ScenePose& pose, float x) {
        Ray r;
        r.origin = {x, 5.0f, 0.2f};
        r.direction = {0.0f, -1.0f, 0.0f};
        return traceClosest(bvh.arrays(), bvh.topLevel(pose), r);
    };
    for (double t : {0.0, 0.25, 1.0}) {
        scene::ScenePose pose = s.evaluate(t);
        const float x = static_cast<float>(4.0 * t);
        Hit onBox = down(pose, x);
        ASSERT_TRUE(onBox.valid());
        EXPECT_EQ(onBox.instance, boxInstance) << "t = " << t;
        EXPECT_NEAR(onBox.t, 3.0f, 1e-5f); // the box's top at y = 2
        Hit beside = down(pose, x + 1.5f);
        ASSERT_TRUE(beside.valid());
        EXPECT_NE(beside.instance, boxInstance) << "t = " << t;
        EXPECT_NEAR(beside.t, 5.0f, 1e-5f); // the floor
    }
    // Where the box was at t = 0 there is floor at t = 1, and where it is at t = 1 there was floor at t = 0.
    EXPECT_NEAR(down(s.evaluate(1.0), 0.0f).t, 5.0f, 1e-5f);
    EXPECT_NEAR(down(s.evaluate(0.0), 4.0f).t, 5.0f, 1e-5f);
}

TEST(SceneBvhCache, RoundTripsAndLoadsFromTheBakeCache) {
    namespace fs = std::filesystem;
    const fs::path root = fs::temp_directory_path() / ("vitrine_bvh_cache_test_" + std::to_string(::getpid()));
    fs::remove_all(root);
    BakeCache cache(root);
    scene::Scene s = randomSoup(3000, 2);
    SceneBvh::CacheStatus status;
    SceneBvh built = SceneBvh::loadOrBuild(s, cache, {}, &status);
    EXPECT_FALSE(status.fromCache);
    EXPECT_TRUE(status.stored);
    SceneBvh loaded = SceneBvh::loadOrBuild(s, cache, {}, &status);
    EXPECT_TRUE(status.fromCache);
    EXPECT_EQ(loaded.serialize(), built.serialize());
    EXPECT_EQ(loaded.levels().size(), built.levels().size());

    // Another scene, or other build options, is another key.
    scene::Scene other = randomSoup(3000, 4);
    BvhBuildOptions leaves8;
    leaves8.maxLeafSize = 8;
    EXPECT_NE(SceneBvh::cacheKey(s, {}).hash, SceneBvh::cacheKey(other, {}).hash);
    EXPECT_NE(SceneBvh::cacheKey(s, {}).hash, SceneBvh::cacheKey(s, leaves8).hash);
    EXPECT_EQ(SceneBvh::cacheKey(s, {}).hash, SceneBvh::cacheKey(randomSoup(3000, 2), {}).hash);
    SceneBvh::loadOrBuild(other, cache, {}, &status);
    EXPECT_FALSE(status.fromCache);
    SceneBvh::loadOrBuild(s, cache, leaves8, &status);
    EXPECT_FALSE(status.fromCache);

    // A damaged file is rebuilt, not trusted.
    const fs::path file = cache.pathOf(SceneBvh::cacheKey(s, {}));
    fs::resize_file(file, fs::file_size(file) / 2);
    SceneBvh rebuilt = SceneBvh::loadOrBuild(s, cache, {}, &status);
    EXPECT_FALSE(status.fromCache);
    EXPECT_EQ(rebuilt.serialize(), built.serialize());

    // Bytes that pass the cache's checksum but not SceneBvh's own checks.
    std::vector<uint8_t> bytes = built.serialize();
    EXPECT_TRUE(SceneBvh::deserialize(bytes));
    bytes.pop_back();
    EXPECT_FALSE(SceneBvh::deserialize(bytes));
    bytes = built.serialize();
    bytes[4] ^= 1; // the version
    EXPECT_FALSE(SceneBvh::deserialize(bytes));
    fs::remove_all(root);
}

} // namespace
} // namespace vitrine::accel
