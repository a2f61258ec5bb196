#include "tools/vitrine/bench_bvh.hpp"

#include "core/accel/gpu_bvh.hpp"
#include "core/accel/ray_batch.hpp"
#include "core/accel/scene_bvh.hpp"
#include "core/accel/traverse.hpp"
#include "core/bake/cache.hpp"
#include "core/base/error.hpp"
#include "core/gpu/context.hpp"
#include "core/scene/gpu_scene.hpp"
#include "core/shader/compiler.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <random>

namespace vitrine::cli {

namespace {

using Clock = std::chrono::steady_clock;
using gpu_types::GpuBvhInstance;
using gpu_types::GpuRay;
using gpu_types::GpuRayHit;

double msSince(Clock::time_point start) {
    return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

// One ray through each pixel centre, row by row (neighbouring invocations trace neighbouring pixels).
std::vector<GpuRay> primaryRays(const CameraFrame& camera) {
    const scene::CameraState& s = camera.state;
    const uint32_t w = camera.width, h = camera.height;
    const float aspect = static_cast<float>(w) / static_cast<float>(h); // as CameraState::projection()
    const float tanHalf = std::tan(0.5f * s.lens.yfov);
    const bool ortho = s.lens.projection == scene::Projection::Orthographic;
    const glm::mat4 proj = s.projection(aspect); // the orthographic half-extents fitted to the frame
    const float xmag = 1.0f / proj[0][0], ymag = -1.0f / proj[1][1];
    std::vector<GpuRay> rays;
    rays.reserve(static_cast<size_t>(w) * h);
    for (uint32_t y = 0; y < h; ++y)
        for (uint32_t x = 0; x < w; ++x) {
            const float nx = 2.0f * (static_cast<float>(x) + 0.5f) / static_cast<float>(w) - 1.0f;
            const float ny = 1.0f - 2.0f * (static_cast<float>(y) + 0.5f) / static_cast<float>(h);
            glm::vec3 origin = s.position, dir;
            if (ortho) {
                origin = glm::vec3(s.world * glm::vec4(nx * xmag, ny * ymag, 0.0f, 1.0f));
                dir = glm::vec3(s.world * glm::vec4(0.0f, 0.0f, -1.0f, 0.0f));
            } else {
                dir = glm::normalize(glm::vec3(s.world * glm::vec4(nx * tanHalf * aspect, ny * tanHalf, -1.0f, 0.0f)));
            }
            const float far = s.lens.zfar > 0.0f ? s.lens.zfar : std::numeric_limits<float>::infinity();
            rays.push_back({glm::vec4(origin, s.lens.znear), glm::vec4(dir, far)});
        }
    return rays;
}

// From each primary hit, a ray in a cosine-distributed direction about the face normal on the side the
// primary ray came from: what a path tracer's diffuse bounce traces. Origins are nudged off the surface.
std::vector<GpuRay> bounceRays(const accel::SceneBvh& bvh, std::span<const GpuBvhInstance> top,
                               std::span<const GpuRay> primary, std::span<const GpuRayHit> hits) {
    std::map<uint32_t, const GpuBvhInstance*> dynamicEntry;
    for (const GpuBvhInstance& e : top)
        if (e.info.y != accel::kNone) dynamicEntry[e.info.y] = &e;
    std::mt19937 rng(1234);
    std::uniform_real_distribution<float> u01(0.0f, 1.0f);
    std::vector<GpuRay> rays;
    rays.reserve(primary.size());
    for (size_t i = 0; i < primary.size(); ++i) {
        const GpuRayHit& h = hits[i];
        if (h.id.x == accel::kNone) continue;
        const gpu_types::GpuBvhTriangle& tri = bvh.arrays().triangles[h.id.x];
        glm::vec3 n = glm::cross(glm::vec3(tri.v1 - tri.v0), glm::vec3(tri.v2 - tri.v0));
        if (auto it = dynamicEntry.find(h.id.y);
            it != dynamicEntry.end() && bvh.arrays().refs[h.id.x].instance == accel::kNone) {
            // Object to world for normals: the transpose of world-to-object.
            const GpuBvhInstance& e = *it->second;
            n = glm::vec3(e.worldToObject0) * n.x + glm::vec3(e.worldToObject1) * n.y +
                glm::vec3(e.worldToObject2) * n.z;
        }
        if (glm::dot(n, n) == 0.0f) continue;
        const glm::vec3 d(primary[i].direction);
        n = glm::normalize(n);
        if (glm::dot(n, d) > 0.0f) n = -n;
        const glm::vec3 p = glm::vec3(primary[i].origin) + h.hit.x * d;
        const glm::vec3 a = std::abs(n.x) > 0.5f ? glm::vec3(0, 1, 0) : glm::vec3(1, 0, 0);
        const glm::vec3 t = glm::normalize(glm::cross(a, n)), b = glm::cross(n, t);
        const float r = std::sqrt(u01(rng)), phi = 6.2831853f * u01(rng);
        const glm::vec3 dir =
            r * std::cos(phi) * t + r * std::sin(phi) * b + std::sqrt(std::max(0.0f, 1.0f - r * r)) * n;
        const float scale = std::max({1.0f, std::abs(p.x), std::abs(p.y), std::abs(p.z)});
        rays.push_back(
            {glm::vec4(p + n * (1e-4f * scale), 0.0f), glm::vec4(dir, std::numeric_limits<float>::infinity())});
    }
    return rays;
}

// The same rays through the CPU traversal (core/accel/traverse.cpp), one thread: the reference for CPU
// bakers, and a sanity check of the GPU numbers.
double cpuRaysPerSecond(const accel::SceneBvh& bvh, std::span<const GpuBvhInstance> top, std::span<const GpuRay> rays) {
    const auto start = Clock::now();
    size_t hits = 0;
    for (const GpuRay& g : rays) {
        accel::Ray r{glm::vec3(g.origin), g.origin.w, glm::vec3(g.direction), g.direction.w};
        hits += accel::traceClosest(bvh.arrays(), top, r).valid();
    }
    const double ms = msSince(start);
    return ms > 0.0 && hits <= rays.size() ? static_cast<double>(rays.size()) / (ms * 1e-3) : 0.0;
}

nlohmann::json traceStats(const RayBatchTracer::Result& r) {
    size_t hits = 0;
    for (const GpuRayHit& h : r.hits)
        hits += h.id.x != accel::kNone;
    auto perSecond = [&](double ms) { return ms > 0.0 ? static_cast<double>(r.hits.size()) / (ms * 1e-3) : 0.0; };
    return {{"rays", r.hits.size()}, {"hits", hits},
            {"gpu_ms", r.gpuMs},     {"rays_per_s", perSecond(r.gpuMs)},
            {"wall_ms", r.wallMs},   {"rays_per_s_wall", perSecond(r.wallMs)}};
}

} // namespace

nlohmann::json benchSceneBvh(Context& ctx, ShaderCompiler& shaders, const std::string& resource,
                             const SceneObject& object, const CameraFrame* camera) {
    const scene::Scene& scene = object.scene();
    nlohmann::json j;
    j["resource"] = resource;
    j["triangles"] = scene.triangleCount();

    const accel::SceneBvh built = accel::SceneBvh::build(scene);
    j["build_ms"] = built.buildMs();
    const accel::BvhBottomLevel& st = built.levels()[0];
    j["nodes"] = built.arrays().nodes.size();
    j["static_level"] = {
        {"triangles", st.triangleCount}, {"nodes", st.nodeCount}, {"depth", st.depth}, {"sah_cost", st.sahCost}};
    j["dynamic_levels"] = built.levels().size() - 1;
    j["dynamic_instances"] = built.dynamicInstances().size();
    j["gpu_bytes"] = built.gpuBytes();

    // Through the bake cache: what a second run pays instead of the build.
    const BakeCache cache(defaultCacheDir());
    const BakeKey key = accel::SceneBvh::cacheKey(scene, built.options());
    auto start = Clock::now();
    const std::vector<uint8_t> bytes = built.serialize();
    const bool stored = cache.put(key, bytes);
    j["cache_store_ms"] = msSince(start);
    j["cache_bytes"] = bytes.size();
    j["cache_file"] = cache.pathOf(key).string();
    if (!stored) throw UserError("bench --bvh: cannot write the bake cache " + cache.pathOf(key).string());
    start = Clock::now();
    std::optional<std::vector<uint8_t>> loadedBytes = cache.get(key);
    std::optional<accel::SceneBvh> loaded = loadedBytes ? accel::SceneBvh::deserialize(*loadedBytes) : std::nullopt;
    j["cache_load_ms"] = msSince(start);
    if (!loaded) throw InternalError("bench --bvh: the BVH just stored in the bake cache did not load back");

    GpuBvh gpuBvh(ctx, *loaded, resource);
    gpuBvh.update(object.pose);
    j["upload_ms"] = gpuBvh.uploadMs();

    if (camera) {
        RayBatchTracer tracer(ctx, shaders);
        const std::vector<GpuRay> primary = primaryRays(*camera);
        RayBatchTracer::Result p = tracer.trace(gpuBvh, primary);
        const std::vector<GpuBvhInstance> top = loaded->topLevel(object.pose);
        j["primary"] = traceStats(p);
        j["primary"]["width"] = camera->width;
        j["primary"]["height"] = camera->height;
        j["primary"]["cpu_rays_per_s"] = cpuRaysPerSecond(*loaded, top, primary);
        const std::vector<GpuRay> bounce = bounceRays(*loaded, top, primary, p.hits);
        j["incoherent"] = traceStats(tracer.trace(gpuBvh, bounce));
        j["incoherent"]["cpu_rays_per_s"] = cpuRaysPerSecond(*loaded, top, bounce);
    }

    return j;
}

void printSceneBvhBench(const nlohmann::json& j) {
    const nlohmann::json& st = j["static_level"];
    std::printf("  BVH %s: %zu triangles; build %.0f ms; %zu nodes (static level: %u nodes, depth %u, SAH cost %.1f; "
                "%zu dynamic levels for %zu instances); %.1f MiB on the GPU\n",
                j["resource"].get<std::string>().c_str(), j["triangles"].get<size_t>(), j["build_ms"].get<double>(),
                j["nodes"].get<size_t>(), st["nodes"].get<uint32_t>(), st["depth"].get<uint32_t>(),
                st["sah_cost"].get<double>(), j["dynamic_levels"].get<size_t>(), j["dynamic_instances"].get<size_t>(),
                j["gpu_bytes"].get<double>() / 1048576.0);
    std::printf("    bake cache: store %.1f ms, load %.1f ms (%.1f MiB); upload %.0f ms\n",
                j["cache_store_ms"].get<double>(), j["cache_load_ms"].get<double>(),
                j["cache_bytes"].get<double>() / 1048576.0, j["upload_ms"].get<double>());
    for (const char* kind : {"primary", "incoherent"}) {
        if (!j.contains(kind)) continue;
        const auto& t = j[kind];
        std::printf("    %-10s %9zu rays, %5.1f %% hit: %9.1f ms GPU (timestamps), %.2f Mrays/s; %9.1f ms submit to "
                    "fence, %.2f Mrays/s; CPU traversal (1 thread) %.2f Mrays/s\n",
                    kind, t["rays"].get<size_t>(),
                    t["rays"].get<size_t>() ? 100.0 * t["hits"].get<double>() / t["rays"].get<double>() : 0.0,
                    t["gpu_ms"].get<double>(), t["rays_per_s"].get<double>() * 1e-6, t["wall_ms"].get<double>(),
                    t["rays_per_s_wall"].get<double>() * 1e-6, t["cpu_rays_per_s"].get<double>() * 1e-6);
        if (t["gpu_ms"].get<double>() * 10.0 < t["wall_ms"].get<double>())
            std::printf("      (the timestamps do not cover the dispatch on this device, as on lavapipe: read the "
                        "submit-to-fence "
                        "numbers)\n");
    }
}

} // namespace vitrine::cli
