#pragma once

// A scene's ray-tracing BVH in two levels, built on the CPU, cached with the bakes and uploaded by
// core/accel/gpu_bvh.hpp. Static instances are pre-transformed into one world-space bottom level; every
// mesh that a dynamic (animated) or deforming (scene::Deformation: skinned, morphed) instance uses gets an
// object-space bottom level, and the top level — entry 0 the static level, then one entry per such instance
// with this frame's world-to-object transform — is rewritten every frame from the pose, which is all an
// animated rigid part costs. A deforming mesh's level is refit to its posed vertices every frame (refit()).
// Layouts: shaders/accel/bvh.h.

#include "core/accel/bvh.hpp"
#include "core/bake/cache.hpp"
#include "core/scene/scene.hpp"

#include <optional>

namespace vitrine::accel {

using gpu_types::GpuBvhInstance;

// An instance with a bottom level of its own (animated or deforming) and that level, its mesh's.
struct BvhDynamicInstance {
    uint32_t instance = 0; // Scene::instances
    uint32_t level = 0;    // SceneBvh::levels()
    glm::mat4 restWorld{1.0f};
};

// The world-space position of an object-space point as the static level stores it. Anything that must
// agree bit for bit with the BVH's triangles (tests' brute-force loops) transforms with this.
inline glm::vec3 transformPoint(const glm::mat4& m, const glm::vec3& p) {
    return glm::vec3(m * glm::vec4(p, 1.0f));
}

class SceneBvh {
public:
    // Bumped whenever the builder or the byte format changes, so caches of older builds are not used.
    static constexpr uint32_t kVersion = 5; // 2: transparent primitives left out; 3: unless options.transparent;
                                            // 4: GpuBvhPrimitive::flags; 5: deforming meshes' own levels

    static SceneBvh build(const scene::Scene& scene, const BvhBuildOptions& options = {});

    // From the cache when it holds this scene's BVH (same content hash, builder version and options),
    // else built and stored there; status (optional) says which, and whether storing worked.
    struct CacheStatus {
        bool fromCache = false;
        bool stored = false; // built and written to the cache
    };
    static SceneBvh loadOrBuild(const scene::Scene& scene, const BakeCache& cache, const BvhBuildOptions& options = {},
                                CacheStatus* status = nullptr);
    static BakeKey cacheKey(const scene::Scene& scene, const BvhBuildOptions& options);

    std::vector<uint8_t> serialize() const;
    // nullopt when the bytes are not a SceneBvh of this version or are inconsistent.
    static std::optional<SceneBvh> deserialize(std::span<const uint8_t> bytes);

    // Refits the levels of the deforming meshes (deformedLevels()) to vertices: Scene::vertices with those meshes
    // posed (scene::Deformation::pose). Call it before topLevel() and the upload of the frame: it moves the levels'
    // bounds too.
    void refit(const scene::Scene& scene, std::span<const scene::Vertex> vertices);
    // The bottom levels (levels() indices) of deforming meshes, in ascending order; empty when nothing deforms.
    const std::vector<uint32_t>& deformedLevels() const { return mDeformedLevels; }

    // The top level at a pose (Scene::evaluate; instances the pose lacks are at rest): entry 0 the static
    // level, then one per dynamic instance, in dynamicInstances() order. Called once per frame.
    std::vector<GpuBvhInstance> topLevel(const scene::ScenePose& pose) const;

    const BvhArrays& arrays() const { return mArrays; }
    // One per scene primitive (GpuBvhPrimitive: where its indices and vertices are).
    const std::vector<GpuBvhPrimitive>& primitives() const { return mPrimitives; }
    // [0]: the static level; then one per mesh used by dynamic instances.
    const std::vector<BvhBottomLevel>& levels() const { return mLevels; }
    const std::vector<BvhDynamicInstance>& dynamicInstances() const { return mDynamic; }
    uint64_t sceneHash() const { return mSceneHash; }
    const BvhBuildOptions& options() const { return mOptions; }
    // What the GPU copy takes: nodes, triangles, refs, primitives and the top level.
    uint64_t gpuBytes() const;
    double buildMs() const { return mBuildMs; } // 0 when loaded

private:
    // One GpuBvhPrimitive per scene primitive. Its flags come from core/scene/closed_mesh.hpp, whose rules are not part
    // of the cache key: loadOrBuild() takes them from here, not from the cache.
    static std::vector<GpuBvhPrimitive> primitivesOf(const scene::Scene& scene);
    // The levels of mDynamic's instances whose mesh deforms (not stored in the cache either: the rule is
    // scene::Deformation's).
    static std::vector<uint32_t> deformedLevelsOf(const scene::Scene& scene,
                                                  const std::vector<BvhDynamicInstance>& dynamic);

    BvhArrays mArrays;
    std::vector<GpuBvhPrimitive> mPrimitives;
    std::vector<BvhBottomLevel> mLevels;
    std::vector<BvhDynamicInstance> mDynamic;
    std::vector<uint32_t> mDeformedLevels;
    uint64_t mSceneHash = 0;
    BvhBuildOptions mOptions;
    double mBuildMs = 0.0;
};

} // namespace vitrine::accel
