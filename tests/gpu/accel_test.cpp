// The BVH on the GPU (core/accel/gpu_bvh, shaders/accel/bvh.glsl through shaders/accel/trace_rays.comp)
// against the CPU: closest hits against a brute-force loop over every triangle (the same triangle at the
// same t, 1e-5 relative) and against the CPU traversal (the hit point from the barycentrics); any-hit; 1e6 rays aimed
// at the shared edges and vertices of closed meshes from inside, none of which may leak; the dynamic level following
// the pose written by GpuBvh::update.
#include "tests/gpu/gpu_test.hpp"

#include "core/accel/gpu_bvh.hpp"
#include "core/accel/ray_batch.hpp"
#include "core/scene/gpu_scene.hpp"
#include "core/scene/museum.hpp"
#include "core/shader/compiler.hpp"
#include "tests/unit/accel/accel_scenes.hpp"
#include "tests/unit/accel/compare_hits.hpp"

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sys/wait.h>

namespace vitrine::test {
namespace {

using namespace accel;
using namespace accel::test;
using gpu_types::GpuRay;
using gpu_types::GpuRayHit;

std::vector<GpuRay> toGpu(const std::vector<Ray>& rays) {
    std::vector<GpuRay> out;
    out.reserve(rays.size());
    for (const Ray& r : rays)
        out.push_back({glm::vec4(r.origin, r.tmin), glm::vec4(r.direction, r.tmax)});
    return out;
}

std::vector<Hit> fromGpu(const std::vector<GpuRayHit>& hits) {
    std::vector<Hit> out;
    out.reserve(hits.size());
    for (const GpuRayHit& g : hits) {
        Hit h;
        h.triangle = g.id.x;
        h.instance = g.id.y;
        h.t = g.hit.x;
        h.barycentrics = {g.hit.y, g.hit.z};
        out.push_back(h);
    }
    return out;
}

class GpuBvhTest : public GpuTest {
protected:
    std::vector<Hit> trace(const GpuBvh& bvh, const std::vector<Ray>& rays, bool anyHit = false, double* ms = nullptr) {
        RayBatchTracer::Result r = mTracer.trace(bvh, toGpu(rays), anyHit);
        if (ms) *ms = r.gpuMs;
        return fromGpu(r.hits);
    }
    ShaderCompiler mShaders;
    RayBatchTracer mTracer{gpu(), mShaders};
};

// GPU hits against brute force, and against the CPU traversal of the same BVH (same triangle, t and
// barycentrics: the two are meant to be the same code).
void expectMatches(const SceneBvh& bvh, const scene::ScenePose& pose, const WorldTriangles& w,
                   const std::vector<Ray>& rays, const std::vector<Hit>& gpuHits, const char* what) {
    size_t hits, ties;
    expectSameHits(bvh, w, rays, gpuHits, hits, ties);
    EXPECT_GT(hits, rays.size() / 2);
    std::vector<GpuBvhInstance> top = bvh.topLevel(pose);
    size_t differ = 0;
    for (size_t i = 0; i < rays.size(); ++i) {
        Hit c = traceClosest(bvh.arrays(), top, rays[i]);
        const Hit& g = gpuHits[i];
        if (c.triangle != g.triangle) {
            ++differ; // a tie resolved the other way by the GPU's rounding; expectSameHits judged it
            continue;
        }
        if (!c.valid()) continue;
        EXPECT_EQ(c.instance, g.instance) << what << " ray " << i;
        EXPECT_LE(std::abs(c.t - g.t), kRelT * c.t) << what << " ray " << i;
        // The hit points the barycentrics give, in the triangle's space, agree as t does: within 1e-5 of the
        // distance travelled (barycentrics alone differ more on small triangles seen from afar).
        const GpuBvhTriangle& tri = bvh.arrays().triangles[c.triangle];
        auto point = [&](glm::vec2 b) {
            return glm::vec3(tri.v0) + b.x * glm::vec3(tri.v1 - tri.v0) + b.y * glm::vec3(tri.v2 - tri.v0);
        };
        EXPECT_LE(glm::length(point(c.barycentrics) - point(g.barycentrics)),
                  kRelT * c.t * glm::length(rays[i].direction))
            << what << " ray " << i << ": barycentrics " << c.barycentrics.x << ", " << c.barycentrics.y << " vs "
            << g.barycentrics.x << ", " << g.barycentrics.y;
    }
    EXPECT_LE(differ, rays.size() / 100) << what;
    std::printf("%s: %zu rays, %zu hits, %zu ties with brute force, %zu different from the CPU traversal\n", what,
                rays.size(), hits, ties, differ);
}

TEST_F(GpuBvhTest, ClosestHitsMatchBruteForceOnRandomSoup) {
    scene::Scene s = randomSoup(3000, 11);
    SceneBvh bvh = SceneBvh::build(s);
    GpuBvh gpuBvh(gpu(), bvh, "soup");
    WorldTriangles w = worldTriangles(s);
    scene::Aabb box = s.bounds;
    box.expand(box.min - 0.5f);
    box.expand(box.max + 0.5f);
    std::vector<Ray> rays = randomRays(w, box, 6000, 5);
    expectMatches(bvh, {}, w, rays, trace(gpuBvh, rays), "soup");
}

TEST_F(GpuBvhTest, ClosestHitsMatchBruteForceInTheMuseumWithTheRobotPosed) {
    scene::MuseumOptions o;
    o.textureSize = 16;
    scene::Scene s = scene::buildMuseum(o);
    SceneBvh bvh = SceneBvh::build(s);
    GpuBvh gpuBvh(gpu(), bvh, "museum");
    scene::ScenePose pose = s.evaluate(3.7);
    gpuBvh.update(pose);
    WorldTriangles w = worldTriangles(s, pose);
    std::vector<Ray> rays = randomRays(w, s.bounds, 450, 7);
    std::mt19937 rng(3);
    std::vector<uint32_t> robot;
    for (uint32_t i = 0; i < w.refs.size(); ++i)
        if (s.instances[w.refs[i].instance].dynamic) robot.push_back(i);
    ASSERT_FALSE(robot.empty());
    for (int i = 0; i < 150; ++i) {
        uint32_t t = robot[rng() % robot.size()];
        glm::vec3 c = (w.v[3 * t] + w.v[3 * t + 1] + w.v[3 * t + 2]) / 3.0f;
        Ray r;
        r.origin = c + 3.0f * randomUnit(rng);
        r.direction = c - r.origin;
        rays.push_back(r);
    }
    std::vector<Hit> hits = trace(gpuBvh, rays);
    expectMatches(bvh, pose, w, rays, hits, "museum");
    size_t onRobot = 0;
    for (const Hit& h : hits)
        onRobot += h.valid() && s.instances[h.instance].dynamic;
    EXPECT_GT(onRobot, 100u);
}

TEST_F(GpuBvhTest, AnyHitFindsOccludersBeforeTmaxOnly) {
    scene::Scene s = randomSoup(3000, 12);
    SceneBvh bvh = SceneBvh::build(s);
    GpuBvh gpuBvh(gpu(), bvh, "soup");
    WorldTriangles w = worldTriangles(s);
    std::vector<Ray> rays = randomRays(w, s.bounds, 4000, 8);
    std::vector<Hit> closest = fromGpu(mTracer.trace(gpuBvh, toGpu(rays)).hits);
    std::vector<Ray> before = rays, past = rays;
    for (size_t i = 0; i < rays.size(); ++i) {
        before[i].tmax = closest[i].valid() ? closest[i].t * 0.999f : 10.0f;
        past[i].tmax = closest[i].valid() ? closest[i].t * 1.001f : 10.0f;
    }
    std::vector<Hit> anyBefore = trace(gpuBvh, before, true), anyPast = trace(gpuBvh, past, true);
    size_t occluded = 0;
    for (size_t i = 0; i < rays.size(); ++i) {
        EXPECT_FALSE(anyBefore[i].valid()) << "ray " << i;
        EXPECT_EQ(anyPast[i].valid(), closest[i].valid()) << "ray " << i;
        occluded += anyPast[i].valid();
    }
    EXPECT_GT(occluded, rays.size() / 2);
}

// 1e6 rays from inside a closed mesh at its edges and vertices: none may leak, each meets the surface at
// t = 1 (direction = target - origin).
void expectWatertight(RayBatchTracer& tracer, const scene::Scene& s, const scene::ScenePose& pose, glm::vec3 center,
                      float radius, uint32_t seed) {
    SceneBvh bvh = SceneBvh::build(s);
    GpuBvh gpuBvh(gpu(), bvh, "closed");
    gpuBvh.update(pose);
    WorldTriangles w = worldTriangles(s, pose);
    std::vector<uint32_t> indices(w.v.size());
    for (uint32_t i = 0; i < indices.size(); ++i)
        indices[i] = i;
    std::vector<Ray> rays = edgeRays(w.v, indices, center, radius, 1000000, seed);
    RayBatchTracer::Result r = tracer.trace(gpuBvh, toGpu(rays));
    size_t leaks = 0, far = 0;
    for (const GpuRayHit& h : r.hits) {
        if (h.id.x == kNone)
            ++leaks;
        else if (std::abs(h.hit.x - 1.0f) > 1e-3f)
            ++far;
    }
    EXPECT_EQ(leaks, 0u) << "of " << rays.size() << " rays";
    EXPECT_EQ(far, 0u) << "rays that met the surface away from t = 1";
    std::printf("%zu edge rays in %.1f ms (%.2f Mrays/s)\n", rays.size(), r.gpuMs, rays.size() / r.gpuMs * 1e-3);
}

TEST_F(GpuBvhTest, NoRayLeaksThroughEdgesOfAStaticSphere) {
    scene::Scene s;
    addRootNode(
        s, "sphere", addMesh(s, "sphere", icosphere(5)),
        transform({0.3f, 1.2f, -0.7f}, glm::angleAxis(0.4f, glm::normalize(glm::vec3(1, 1, 0))), glm::vec3(1.7f)));
    s.finalize();
    expectWatertight(mTracer, s, {}, {0.3f, 1.2f, -0.7f}, 0.8f, 17);
}

TEST_F(GpuBvhTest, NoRayLeaksThroughEdgesOfAMovingCube) {
    scene::Scene s;
    uint32_t node = addRootNode(s, "cube", addMesh(s, "cube", tessellatedCube(48)),
                                transform({0, 0, 0}, glm::angleAxis(0.3f, glm::normalize(glm::vec3(0, 1, 1)))));
    animateTranslation(s, node, {0.0f, 0.0f, 0.0f}, {2.0f, 1.0f, 0.0f});
    s.finalize();
    expectWatertight(mTracer, s, s.evaluate(0.5), {1.0f, 0.5f, 0.0f}, 0.5f, 23);
}

// A static floor and a box that moves 4 m along +x between t = 0 and t = 1.
scene::Scene floorAndMovingBox() {
    scene::Scene s;
    s.name = "mover";
    IndexedMesh floor;
    floor.positions = {{-10, 0, -10}, {10, 0, -10}, {10, 0, 10}, {-10, 0, 10}};
    floor.indices = {0, 2, 1, 0, 3, 2};
    addRootNode(s, "floor", addMesh(s, "floor", floor));
    uint32_t box = addRootNode(s, "box", addMesh(s, "box", tessellatedCube(2)), transform({0, 1, 0}));
    animateTranslation(s, box, {0, 1, 0}, {4, 1, 0});
    s.finalize();
    return s;
}

// Rays straight down from y = 5 at these x (z = 0.2).
std::vector<Ray> downAt(std::initializer_list<float> xs) {
    std::vector<Ray> rays;
    for (float x : xs) {
        Ray r;
        r.origin = {x, 5.0f, 0.2f};
        r.direction = {0.0f, -1.0f, 0.0f};
        rays.push_back(r);
    }
    return rays;
}

TEST_F(GpuBvhTest, DynamicInstanceFollowsThePose) {
    scene::Scene s = floorAndMovingBox();
    SceneBvh bvh = SceneBvh::build(s);
    GpuBvh gpuBvh(gpu(), bvh, "mover");
    const uint32_t boxInstance = bvh.dynamicInstances().at(0).instance;
    const std::vector<Ray> rays = downAt({0.0f, 1.0f, 4.0f, 5.5f});
    // Expected t per ray: 3 on the box's top (y = 2), 5 on the floor.
    const std::vector<std::pair<double, std::vector<float>>> cases = {
        {0.0, {3, 5, 5, 5}}, {0.25, {3, 3, 5, 5}}, {1.0, {5, 5, 3, 5}}};
    for (const auto& [time, expected] : cases) {
        gpuBvh.update(s.evaluate(time));
        std::vector<Hit> hits = trace(gpuBvh, rays);
        for (size_t i = 0; i < rays.size(); ++i) {
            ASSERT_TRUE(hits[i].valid()) << "t = " << time << ", ray " << i;
            EXPECT_NEAR(hits[i].t, expected[i], 1e-5f) << "t = " << time << ", ray " << i;
            EXPECT_EQ(hits[i].instance == boxInstance, expected[i] == 3.0f) << "t = " << time << ", ray " << i;
        }
    }
}

TEST_F(GpuBvhTest, SceneObjectUploadsItsBvhPosedAndCachesIt) {
    // What a ray-tracing pass gets from its scene port: the BVH, posed at the frame it first asked in.
    auto s = std::make_shared<scene::Scene>(floorAndMovingBox());
    SceneObject first(s);
    first.pose = s->evaluate(1.0);
    EXPECT_FALSE(first.hasBvh());
    GpuBvh& bvh = first.bvh(gpu());
    EXPECT_TRUE(first.hasBvh());
    EXPECT_EQ(&first.bvh(gpu()), &bvh);
    std::vector<Hit> hits = trace(bvh, downAt({0.0f, 4.0f}));
    EXPECT_NEAR(hits[0].t, 5.0f, 1e-5f); // floor where the box was at t = 0
    EXPECT_NEAR(hits[1].t, 3.0f, 1e-5f); // the box's top, at x = 4 at t = 1
    first.pose = s->evaluate(0.0);
    bvh.update(first.pose); // what the scene node does every frame
    hits = trace(bvh, downAt({0.0f, 4.0f}));
    EXPECT_NEAR(hits[0].t, 3.0f, 1e-5f);
    EXPECT_NEAR(hits[1].t, 5.0f, 1e-5f);

    // Another run (another object) loads the same BVH from the bake cache instead of building it.
    SceneObject second(s);
    second.bvh(gpu());
    EXPECT_TRUE(second.bvhFromCache());
}

// `vitrine bench --bvh` on the museum graph at a tiny size: it runs clean under validation and reports the
// BVH (nodes, memory, cache) and one primary ray per pixel with a bounce ray per primary hit.
TEST(GpuBvhBench, ReportsTheMuseumBvh) {
    const std::filesystem::path out = std::filesystem::path(VITRINE_TEST_OUT) / "bench_bvh.json";
    std::filesystem::create_directories(out.parent_path());
    std::filesystem::remove(out);
    const std::string command = std::string(VITRINE_BINARY) + " bench " + VITRINE_SOURCE_DIR +
                                "/graphs/museum.json --frames 1 --warmup 0 --bvh --validate --quiet --json " +
                                out.string() +
                                " --set frame.width=64 --set frame.height=36 --set scene.params.texture_size=16"
                                " --set shadow.params.resolution=256 2>&1";
    FILE* pipe = popen(command.c_str(), "r");
    ASSERT_NE(pipe, nullptr);
    std::string output;
    char buffer[4096];
    for (size_t n; (n = fread(buffer, 1, sizeof buffer, pipe)) > 0;)
        output.append(buffer, n);
    const int status = pclose(pipe);
    ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << output;
    std::ifstream in(out);
    const nlohmann::json j = nlohmann::json::parse(in);
    ASSERT_EQ(j.at("bvh").size(), 1u);
    const nlohmann::json& b = j["bvh"][0];
    EXPECT_GT(b.at("triangles").get<size_t>(), 100000u);
    EXPECT_GT(b.at("nodes").get<size_t>(), b["triangles"].get<size_t>() / 8);
    EXPECT_GE(b.at("dynamic_instances").get<size_t>(), 7u); // the robot's parts
    EXPECT_GT(b.at("gpu_bytes").get<size_t>(), b["triangles"].get<size_t>() * 48);
    EXPECT_GT(b.at("build_ms").get<double>(), 0.0);
    EXPECT_GT(b.at("cache_load_ms").get<double>(), 0.0);
    EXPECT_TRUE(std::filesystem::exists(b.at("cache_file").get<std::string>()));
    EXPECT_EQ(b.at("primary").at("rays").get<size_t>(), 64u * 36u);
    EXPECT_GT(b["primary"].at("hits").get<size_t>(), 64u * 36u * 9 / 10);
    EXPECT_EQ(b.at("incoherent").at("rays").get<size_t>(), b["primary"]["hits"].get<size_t>());
    for (const char* kind : {"primary", "incoherent"}) {
        EXPECT_GT(b[kind].at("wall_ms").get<double>(), 0.0) << kind;
        EXPECT_GT(b[kind].at("cpu_rays_per_s").get<double>(), 0.0) << kind;
    }
}

} // namespace
} // namespace vitrine::test
