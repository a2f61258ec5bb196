#pragma once

// Bottom levels of the ray-tracing BVH: a binned-SAH builder that writes straight into the GPU layout of
// shaders/accel/bvh.h (GpuBvhNode: a binary tree whose nodes hold both children's boxes; triangles and
// their refs in leaf order). core/accel/scene_bvh.hpp builds a scene's levels with it.

#include "shaders/accel/bvh.h"

#include <glm/glm.hpp>

#include <bit>
#include <cstdint>
#include <functional>
#include <span>
#include <vector>

namespace vitrine::accel {

using gpu_types::GpuBvhNode;
using gpu_types::GpuBvhPrimitive;
using gpu_types::GpuBvhTriangle;
using gpu_types::GpuBvhTriangleRef;

inline constexpr uint32_t kNone = VITRINE_BVH_NONE;
inline constexpr uint32_t kMaxDepth = VITRINE_BVH_STACK_SIZE;

struct BvhBuildOptions {
    uint32_t bins = 16;       // SAH candidate planes per axis and node: bins - 1
    uint32_t maxLeafSize = 4; // triangles; SAH may stop splitting below it
    // SAH cost of one node visit (two box tests) relative to one triangle test.
    float traversalCost = 1.0f;
    // Levels of nodes at most, <= kMaxDepth (the traversal stack). Binned SAH stays far below it on real
    // scenes (the museum: 24); subtrees that would go deeper switch to object-median splits.
    uint32_t maxDepth = kMaxDepth;
    // Whether transparent primitives (alpha blend, KHR_materials_transmission: scene::Material::transparent()) are in
    // it. Left out by default, as the shadow maps leave them: the bake and the twins see through glass untouched.
    // render.pathtrace's `transparent` traces them (shaders/pathtrace/surface.glsl pathSeeThrough).
    bool transparent = false;

    bool operator==(const BvhBuildOptions&) const = default;
};

struct BvhBox {
    glm::vec3 min{3.0e38f};
    glm::vec3 max{-3.0e38f};

    bool empty() const { return min.x > max.x; }
    void expand(const glm::vec3& p) {
        min = glm::min(min, p);
        max = glm::max(max, p);
    }
    void expand(const BvhBox& b) {
        min = glm::min(min, b.min);
        max = glm::max(max, b.max);
    }
    bool contains(const BvhBox& b) const {
        return glm::all(glm::lessThanEqual(min, b.min)) && glm::all(glm::greaterThanEqual(max, b.max));
    }
    float halfArea() const {
        glm::vec3 e = glm::max(max - min, glm::vec3(0.0f));
        return e.x * e.y + e.y * e.z + e.z * e.x;
    }
};

// A child slot of a node, decoded from the w bits.
struct BvhChild {
    BvhBox box;
    uint32_t link = kNone; // node index (inner), first triangle (leaf), kNone (absent)
    uint32_t count = 0;    // triangles; 0: inner node
    bool leaf() const { return count > 0; }
    bool absent() const { return link == kNone; }
};

inline BvhChild childOf(const GpuBvhNode& n, int which) {
    const glm::vec4& lo = which == 0 ? n.aMin : n.bMin;
    const glm::vec4& hi = which == 0 ? n.aMax : n.bMax;
    return {{glm::vec3(lo), glm::vec3(hi)}, std::bit_cast<uint32_t>(lo.w), std::bit_cast<uint32_t>(hi.w)};
}

inline void setChild(GpuBvhNode& n, int which, const BvhChild& c) {
    glm::vec4 lo(c.box.min, std::bit_cast<float>(c.link)), hi(c.box.max, std::bit_cast<float>(c.count));
    (which == 0 ? n.aMin : n.bMin) = lo;
    (which == 0 ? n.aMax : n.bMax) = hi;
}

// One input triangle of a bottom level.
struct BvhBuildTriangle {
    glm::vec3 v0, v1, v2;
    GpuBvhTriangleRef ref;
};

// One bottom level inside the shared node and triangle arrays.
struct BvhBottomLevel {
    uint32_t root = 0;
    uint32_t firstNode = 0, nodeCount = 0;
    uint32_t firstTriangle = 0, triangleCount = 0;
    uint32_t depth = 0;   // levels of nodes, the root's being 1
    float sahCost = 0.0f; // expected cost of a ray through the root box, in triangle tests
    BvhBox bounds;
};

// The arrays every bottom level of a scene is appended to (indices in them are absolute).
struct BvhArrays {
    std::vector<GpuBvhNode> nodes;
    std::vector<GpuBvhTriangle> triangles;
    std::vector<GpuBvhTriangleRef> refs;
};

// Builds a bottom level over triangles with a binned SAH (centroid bins on all three axes) and appends it
// to out. Triangles go to out in leaf order, each exactly once; degenerate ones are kept (they never hit).
// Depth stays within options.maxDepth: deep subtrees switch to object-median splits.
BvhBottomLevel buildBottomLevel(std::span<const BvhBuildTriangle> triangles, const BvhBuildOptions& options,
                                BvhArrays& out);

// Moves the triangles of a bottom level that `arrays` holds to new corners (corners(ref, v) writes the three of the
// triangle whose GpuBvhTriangleRef is ref) and recomputes every box of its nodes bottom up, and level.bounds. The tree
// stays as it was built: a refit is one pass over the level, and it stays exact (every box holds its triangles) while
// traversal slows as far as the triangles moved from where the SAH split them.
void refitBottomLevel(BvhBottomLevel& level, BvhArrays& arrays,
                      const std::function<void(const GpuBvhTriangleRef&, glm::vec3 (&)[3])>& corners);

} // namespace vitrine::accel
