#pragma once

// What of a scene deforms over time, and its vertices at a pose. A mesh deforms when a moving skin poses it (a
// skinned primitive drawn by a dynamic node with a skin) or when an animation drives morph weights and it has
// targets. Everything that draws or traces the scene poses those meshes with this one rule: the G-buffer's vertex
// buffer and last frame's positions (core/scene/gpu_scene.hpp), the ray-tracing BVH's refit
// (core/accel/scene_bvh.hpp) and the CPU path tracer.

#include "core/scene/scene.hpp"

#include <span>
#include <vector>

namespace vitrine::scene {

class Deformation {
public:
    explicit Deformation(const Scene& scene);

    // Whether any mesh deforms; when none does, pose() writes nothing.
    bool any() const { return mAny; }
    bool meshDeforms(uint32_t mesh) const { return mesh < mDeformed.size() && mDeformed[mesh]; }
    // Per mesh: meshDeforms().
    const std::vector<bool>& deformedMeshes() const { return mDeformed; }
    // Per mesh: posed by a moving skin (its skinned primitives ignore the morph weights of the pose: the skin's
    // bind-space vertices carry the rest weights).
    bool meshSkinned(uint32_t mesh) const { return mesh < mSkinnedNode.size() && mSkinnedNode[mesh] >= 0; }
    // The vertex ranges (Scene::vertices) that pose() writes: one per primitive of a deformed mesh.
    struct Range {
        uint32_t first = 0, count = 0;
    };
    const std::vector<Range>& ranges() const { return mRanges; }

    // Writes the vertices of every deformed mesh at pose into out, indexed as Scene::vertices (whose size it
    // has); the rest of out is left as it is. A skinned mesh is posed by the first node that draws it with its
    // skin (one vertex range per mesh); a pose without node transforms leaves skinned primitives untouched. Morph
    // weights the pose lacks for a mesh are its rest weights.
    void pose(const ScenePose& pose, std::span<Vertex> out) const;
    // Scene::vertices with the deformed meshes at pose.
    std::vector<Vertex> posedVertices(const ScenePose& pose) const;

private:
    const Scene& mScene;
    bool mAny = false;
    std::vector<bool> mDeformed;
    std::vector<int32_t> mSkinnedNode; // per mesh: the node whose skin poses it, or -1
    std::vector<Range> mRanges;
};

} // namespace vitrine::scene
