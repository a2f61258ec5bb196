#include "core/accel/scene_bvh.hpp"

#include "core/base/error.hpp"
#include "core/scene/closed_mesh.hpp"
#include "core/scene/deformation.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>

namespace vitrine::accel {

namespace {

// Appends the triangles of every primitive of mesh, transformed by world (object space: identity).
void gather(const scene::Scene& scene, uint32_t mesh, const glm::mat4& world, bool transform, uint32_t instance,
            bool transparent, std::vector<BvhBuildTriangle>& out) {
    const scene::Mesh& m = scene.meshes[mesh];
    for (uint32_t p = m.firstPrimitive; p < m.firstPrimitive + m.primitiveCount; ++p) {
        const scene::Primitive& prim = scene.primitives[p];
        // Transparent primitives (alpha blend, glass) are left out unless asked for (BvhBuildOptions::transparent):
        // the tracers that read this BVH without seeing through surfaces would take a pane for a wall.
        if (!transparent && scene.materials[prim.material].transparent()) continue;
        for (uint32_t t = 0; t < prim.indexCount / 3; ++t) {
            glm::vec3 v[3];
            for (uint32_t k = 0; k < 3; ++k) {
                const glm::vec3& pos =
                    scene.vertices[prim.vertexOffset + scene.indices[prim.firstIndex + 3 * t + k]].position;
                v[k] = transform ? transformPoint(world, pos) : pos;
            }
            out.push_back({v[0], v[1], v[2], {instance, p, t, prim.material}});
        }
    }
}

} // namespace

std::vector<GpuBvhPrimitive> SceneBvh::primitivesOf(const scene::Scene& scene) {
    const std::vector<uint8_t> openVolume = scene::openVolumePrimitives(scene);
    std::vector<GpuBvhPrimitive> out;
    out.reserve(scene.primitives.size());
    for (size_t i = 0; i < scene.primitives.size(); ++i) {
        const scene::Primitive& p = scene.primitives[i];
        out.push_back(
            {p.firstIndex, p.indexCount, p.vertexOffset, openVolume[i] ? VITRINE_BVH_PRIMITIVE_OPEN_VOLUME : 0u});
    }
    return out;
}

namespace {

// The levels of dynamic's instances whose mesh deforms, ascending, each once.
std::vector<uint32_t> levelsThatDeform(const scene::Scene& scene, const scene::Deformation& deformation,
                                       const std::vector<BvhDynamicInstance>& dynamic) {
    std::vector<uint32_t> levels;
    for (const BvhDynamicInstance& d : dynamic) {
        if (d.instance < scene.instances.size() && deformation.meshDeforms(scene.instances[d.instance].mesh))
            levels.push_back(d.level);
    }
    std::sort(levels.begin(), levels.end());
    levels.erase(std::unique(levels.begin(), levels.end()), levels.end());
    return levels;
}

} // namespace

std::vector<uint32_t> SceneBvh::deformedLevelsOf(const scene::Scene& scene,
                                                 const std::vector<BvhDynamicInstance>& dynamic) {
    return levelsThatDeform(scene, scene::Deformation(scene), dynamic);
}

SceneBvh SceneBvh::build(const scene::Scene& scene, const BvhBuildOptions& options) {
    const auto start = std::chrono::steady_clock::now();
    SceneBvh bvh;
    bvh.mSceneHash = scene.contentHash();
    bvh.mOptions = options;
    bvh.mPrimitives = primitivesOf(scene);

    // An instance whose mesh deforms gets a level of its own, as an animated one does, for refit() to move.
    const scene::Deformation deformation(scene);
    auto ownLevel = [&](const scene::MeshInstance& inst) { return inst.dynamic || deformation.meshDeforms(inst.mesh); };
    std::vector<BvhBuildTriangle> triangles;
    for (uint32_t i = 0; i < scene.instances.size(); ++i) {
        const scene::MeshInstance& inst = scene.instances[i];
        if (!ownLevel(inst)) gather(scene, inst.mesh, inst.world, true, i, options.transparent, triangles);
    }
    bvh.mLevels.push_back(buildBottomLevel(triangles, options, bvh.mArrays));

    std::map<uint32_t, uint32_t> levelOfMesh;
    for (uint32_t i = 0; i < scene.instances.size(); ++i) {
        const scene::MeshInstance& inst = scene.instances[i];
        if (!ownLevel(inst)) continue;
        auto [it, added] = levelOfMesh.try_emplace(inst.mesh, static_cast<uint32_t>(bvh.mLevels.size()));
        if (added) {
            triangles.clear();
            gather(scene, inst.mesh, glm::mat4(1.0f), false, kNone, options.transparent, triangles);
            bvh.mLevels.push_back(buildBottomLevel(triangles, options, bvh.mArrays));
        }
        bvh.mDynamic.push_back({i, it->second, inst.world});
    }
    bvh.mDeformedLevels = levelsThatDeform(scene, deformation, bvh.mDynamic);
    bvh.mBuildMs = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    return bvh;
}

void SceneBvh::refit(const scene::Scene& scene, std::span<const scene::Vertex> vertices) {
    if (vertices.size() != scene.vertices.size())
        throw InternalError("SceneBvh::refit: " + std::to_string(vertices.size()) + " vertices for a scene of " +
                            std::to_string(scene.vertices.size()));
    for (uint32_t l : mDeformedLevels) {
        refitBottomLevel(mLevels[l], mArrays, [&](const GpuBvhTriangleRef& ref, glm::vec3(&v)[3]) {
            const scene::Primitive& p = scene.primitives[ref.primitive];
            for (uint32_t k = 0; k < 3; ++k)
                v[k] = vertices[p.vertexOffset + scene.indices[p.firstIndex + 3 * ref.triangle + k]].position;
        });
    }
}

std::vector<GpuBvhInstance> SceneBvh::topLevel(const scene::ScenePose& pose) const {
    std::vector<GpuBvhInstance> top;
    top.reserve(1 + mDynamic.size());
    GpuBvhInstance s{};
    s.worldToObject0 = {1.0f, 0.0f, 0.0f, 0.0f};
    s.worldToObject1 = {0.0f, 1.0f, 0.0f, 0.0f};
    s.worldToObject2 = {0.0f, 0.0f, 1.0f, 0.0f};
    s.boundsMin = glm::vec4(mLevels[0].bounds.min, 0.0f);
    s.boundsMax = glm::vec4(mLevels[0].bounds.max, 0.0f);
    s.info = {mLevels[0].root, kNone, 0u, 0u};
    top.push_back(s);
    for (const BvhDynamicInstance& d : mDynamic) {
        const glm::mat4& world = d.instance < pose.instanceWorld.size() ? pose.instanceWorld[d.instance] : d.restWorld;
        const BvhBottomLevel& level = mLevels[d.level];
        if (level.triangleCount == 0 || glm::determinant(glm::mat3(world)) == 0.0f) continue; // nothing to hit
        const glm::mat4 inv = glm::inverse(world);
        GpuBvhInstance e{};
        // glm is column-major: row r of inv is (inv[0][r], inv[1][r], inv[2][r], inv[3][r]).
        e.worldToObject0 = {inv[0][0], inv[1][0], inv[2][0], inv[3][0]};
        e.worldToObject1 = {inv[0][1], inv[1][1], inv[2][1], inv[3][1]};
        e.worldToObject2 = {inv[0][2], inv[1][2], inv[2][2], inv[3][2]};
        BvhBox box;
        for (int c = 0; c < 8; ++c) {
            glm::vec3 corner((c & 1) ? level.bounds.max.x : level.bounds.min.x,
                             (c & 2) ? level.bounds.max.y : level.bounds.min.y,
                             (c & 4) ? level.bounds.max.z : level.bounds.min.z);
            box.expand(transformPoint(world, corner));
        }
        // The rounding of the corners' transform and of the ray's must not cull a grazing hit.
        const glm::vec3 pad = 1e-5f * (glm::abs(box.min) + glm::abs(box.max) + (box.max - box.min)) + 1e-30f;
        e.boundsMin = glm::vec4(box.min - pad, 0.0f);
        e.boundsMax = glm::vec4(box.max + pad, 0.0f);
        e.info = {level.root, d.instance, 0u, 0u};
        top.push_back(e);
    }
    return top;
}

uint64_t SceneBvh::gpuBytes() const {
    return mArrays.nodes.size() * sizeof(GpuBvhNode) + mArrays.triangles.size() * sizeof(GpuBvhTriangle) +
           mArrays.refs.size() * sizeof(GpuBvhTriangleRef) + mPrimitives.size() * sizeof(GpuBvhPrimitive) + 16 +
           (1 + mDynamic.size()) * sizeof(GpuBvhInstance);
}

} // namespace vitrine::accel
