#include "core/accel/gpu_bvh.hpp"

#include "core/base/error.hpp"
#include "core/gpu/context.hpp"
#include "core/gpu/transfer.hpp"
#include "core/gpu/vk_check.hpp"

#include <algorithm>
#include <chrono>
#include <cstring>
#include <utility>

namespace vitrine {

using namespace gpu_types;

namespace {

template <typename T> GpuBuffer upload(Context& ctx, const std::vector<T>& v, const std::string& name) {
    return uploadBuffer(ctx, v.data(), v.size() * sizeof(T), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, name);
}

template <typename T> GpuBuffer hostVisible(Context& ctx, const std::vector<T>& v, const std::string& name) {
    GpuBuffer b(ctx, std::max<size_t>(1, v.size()) * sizeof(T), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, true, name);
    std::memcpy(b.mapped(), v.data(), v.size() * sizeof(T));
    return b;
}

// Copies elements [first, first + count) of v to the same place in the mapped buffer b.
template <typename T> void write(GpuBuffer& b, const std::vector<T>& v, uint32_t first, uint32_t count) {
    std::memcpy(static_cast<T*>(b.mapped()) + first, v.data() + first, size_t(count) * sizeof(T));
}

constexpr uint32_t kBindings = 5;

} // namespace

GpuBvh::GpuBvh(Context& ctx, const accel::SceneBvh& bvh, const std::string& name) : mCtx(ctx), mBvh(bvh) {
    const auto start = std::chrono::steady_clock::now();
    const accel::BvhArrays& a = bvh.arrays();
    if (bvh.deformedLevels().empty()) {
        mNodes = upload(ctx, a.nodes, name + ".bvh.nodes");
        mTriangles = upload(ctx, a.triangles, name + ".bvh.triangles");
    } else {
        // Deforming meshes' levels are refit every frame: nodes and triangles stay where the CPU writes them.
        mNodes = hostVisible(ctx, a.nodes, name + ".bvh.nodes");
        mTriangles = hostVisible(ctx, a.triangles, name + ".bvh.triangles");
    }
    mRefs = upload(ctx, a.refs, name + ".bvh.refs");
    mPrimitives = upload(ctx, bvh.primitives(), name + ".bvh.primitives");
    const size_t topBytes = 16 + (1 + bvh.dynamicInstances().size()) * sizeof(GpuBvhInstance);
    mTop = GpuBuffer(ctx, topBytes, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, true, name + ".bvh.top");
    mBytes = mNodes.size() + mTriangles.size() + mRefs.size() + mPrimitives.size() + mTop.size();
    update({});

    const VkBuffer buffers[kBindings] = {mNodes.buffer(), mTriangles.buffer(), mRefs.buffer(), mPrimitives.buffer(),
                                         mTop.buffer()};
    mSet = StorageBufferSet(ctx, buffers, VK_SHADER_STAGE_COMPUTE_BIT | VK_SHADER_STAGE_FRAGMENT_BIT, name + ".bvh");
    mUploadMs = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

GpuBvh::~GpuBvh() = default;

void GpuBvh::update(const scene::ScenePose& pose) {
    for (uint32_t l : mBvh.deformedLevels()) {
        const accel::BvhBottomLevel& level = mBvh.levels()[l];
        write(mNodes, mBvh.arrays().nodes, level.firstNode, level.nodeCount);
        write(mTriangles, mBvh.arrays().triangles, level.firstTriangle, level.triangleCount);
    }
    const std::vector<GpuBvhInstance> top = mBvh.topLevel(pose);
    if (16 + top.size() * sizeof(GpuBvhInstance) > mTop.size())
        throw InternalError("GpuBvh::update: the top level outgrew its buffer");
    auto* p = static_cast<uint8_t*>(mTop.mapped());
    const glm::uvec4 header(static_cast<uint32_t>(top.size()), 0u, 0u, 0u);
    std::memcpy(p, &header, sizeof header);
    std::memcpy(p + 16, top.data(), top.size() * sizeof(GpuBvhInstance));
}

} // namespace vitrine
