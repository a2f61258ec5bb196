#pragma once

// The GPU copy of a scene's BVH (core/accel/scene_bvh.hpp) and the descriptor set that
// shaders/accel/bvh.glsl reads: binding 0 nodes, 1 triangles, 2 triangle refs, 3 primitives, 4 the top
// level (a uvec4 header, then the entries). Bottom levels are uploaded once, in the constructor; the top
// level is host-visible and rewritten by update() every frame, and so are the nodes and triangles of the levels that
// deforming meshes refit (SceneBvh::deformedLevels(): then those two buffers are host-visible). A ray-tracing pass
// binds set() at the set index its shader gives VITRINE_BVH_SET (1 by default, beside the scene's set 0).

#include "core/accel/scene_bvh.hpp"
#include "core/gpu/buffer_set.hpp"
#include "core/gpu/resources.hpp"

#include <string>

namespace vitrine {

class Context;

class GpuBvh {
public:
    // bvh must outlive this object (update() reads its levels).
    GpuBvh(Context& ctx, const accel::SceneBvh& bvh, const std::string& name);
    ~GpuBvh();
    GpuBvh(const GpuBvh&) = delete;
    GpuBvh& operator=(const GpuBvh&) = delete;

    // Writes the top level for this pose (Scene::evaluate), and the deformed levels as the SceneBvh holds them (refit
    // it to the same pose first). Safe while recording: the render graph runs
    // one frame in flight, so the GPU is done with the last frame's; outside the graph, call it between
    // submissions.
    void update(const scene::ScenePose& pose);

    VkDescriptorSetLayout setLayout() const { return mSet.layout(); }
    VkDescriptorSet set() const { return mSet.set(); }
    uint64_t bytes() const { return mBytes; } // device memory of all five buffers
    double uploadMs() const { return mUploadMs; }

private:
    Context& mCtx;
    const accel::SceneBvh& mBvh;
    GpuBuffer mNodes, mTriangles, mRefs, mPrimitives, mTop;
    StorageBufferSet mSet;
    uint64_t mBytes = 0;
    double mUploadMs = 0.0;
};

} // namespace vitrine
