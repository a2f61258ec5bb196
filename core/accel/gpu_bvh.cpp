#include "core/accel/gpu_bvh.hpp"

#include "core/base/error.hpp"
#include "core/gpu/context.hpp"
#include "core/gpu/transfer.hpp"
#include "core/gpu/vk_check.hpp"

#include <chrono>
#include <cstring>
#include <utility>

namespace vitrine {

using namespace gpu_types;

namespace {

template <typename T> GpuBuffer upload(Context& ctx, const std::vector<T>& v, const std::string& name) {
    return uploadBuffer(ctx, v.data(), v.size() * sizeof(T), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, name);
}

constexpr uint32_t kBindings = 5;

} // namespace

GpuBvh::GpuBvh(Context& ctx, const accel::SceneBvh& bvh, const std::string& name) : mCtx(ctx), mBvh(bvh) {
    const auto start = std::chrono::steady_clock::now();
    try {
        const accel::BvhArrays& a = bvh.arrays();
        mNodes = upload(ctx, a.nodes, name + ".bvh.nodes");
        mTriangles = upload(ctx, a.triangles, name + ".bvh.triangles");
        mRefs = upload(ctx, a.refs, name + ".bvh.refs");
        mPrimitives = upload(ctx, bvh.primitives(), name + ".bvh.primitives");
        const size_t topBytes = 16 + (1 + bvh.dynamicInstances().size()) * sizeof(GpuBvhInstance);
        mTop = GpuBuffer(ctx, topBytes, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, true, name + ".bvh.top");
        mBytes = mNodes.size() + mTriangles.size() + mRefs.size() + mPrimitives.size() + mTop.size();
        update({});

        VkDevice device = ctx.device();
        VkDescriptorSetLayoutBinding b[kBindings];
        for (uint32_t i = 0; i < kBindings; ++i)
            b[i] = {i, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, VK_SHADER_STAGE_COMPUTE_BIT | VK_SHADER_STAGE_FRAGMENT_BIT,
                    nullptr};
        VkDescriptorSetLayoutCreateInfo li{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
        li.bindingCount = kBindings;
        li.pBindings = b;
        VK_CHECK(vkCreateDescriptorSetLayout(device, &li, nullptr, &mSetLayout));
        VkDescriptorPoolSize size{VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, kBindings};
        VkDescriptorPoolCreateInfo pi{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
        pi.maxSets = 1;
        pi.poolSizeCount = 1;
        pi.pPoolSizes = &size;
        VK_CHECK(vkCreateDescriptorPool(device, &pi, nullptr, &mPool));
        VkDescriptorSetAllocateInfo ai{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
        ai.descriptorPool = mPool;
        ai.descriptorSetCount = 1;
        ai.pSetLayouts = &mSetLayout;
        VK_CHECK(vkAllocateDescriptorSets(device, &ai, &mSet));
        const GpuBuffer* buffers[kBindings] = {&mNodes, &mTriangles, &mRefs, &mPrimitives, &mTop};
        VkDescriptorBufferInfo infos[kBindings];
        VkWriteDescriptorSet writes[kBindings];
        for (uint32_t i = 0; i < kBindings; ++i) {
            infos[i] = {buffers[i]->buffer(), 0, VK_WHOLE_SIZE};
            writes[i] = {VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
            writes[i].dstSet = mSet;
            writes[i].dstBinding = i;
            writes[i].descriptorCount = 1;
            writes[i].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
            writes[i].pBufferInfo = &infos[i];
        }
        vkUpdateDescriptorSets(device, kBindings, writes, 0, nullptr);
    } catch (...) {
        release();
        throw;
    }
    mUploadMs = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

GpuBvh::~GpuBvh() {
    release();
}

void GpuBvh::release() {
    VkDevice device = mCtx.device();
    VkDescriptorSetLayout layout = std::exchange(mSetLayout, VK_NULL_HANDLE);
    VkDescriptorPool pool = std::exchange(mPool, VK_NULL_HANDLE);
    mCtx.destroyLater([device, layout, pool] {
        if (layout) vkDestroyDescriptorSetLayout(device, layout, nullptr);
        if (pool) vkDestroyDescriptorPool(device, pool, nullptr);
    });
}

void GpuBvh::update(const scene::ScenePose& pose) {
    const std::vector<GpuBvhInstance> top = mBvh.topLevel(pose);
    if (16 + top.size() * sizeof(GpuBvhInstance) > mTop.size())
        throw InternalError("GpuBvh::update: the top level outgrew its buffer");
    auto* p = static_cast<uint8_t*>(mTop.mapped());
    const glm::uvec4 header(static_cast<uint32_t>(top.size()), 0u, 0u, 0u);
    std::memcpy(p, &header, sizeof header);
    std::memcpy(p + 16, top.data(), top.size() * sizeof(GpuBvhInstance));
}

} // namespace vitrine
