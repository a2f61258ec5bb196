#include "core/gpu/buffer_set.hpp"

#include "core/gpu/context.hpp"
#include "core/gpu/vk_check.hpp"

#include <utility>
#include <vector>

namespace vitrine {

StorageBufferSet::StorageBufferSet(Context& ctx, std::span<const VkBuffer> buffers, VkShaderStageFlags stages,
                                   const std::string& name)
    : mCtx(&ctx) {
    VkDevice device = ctx.device();
    const auto count = static_cast<uint32_t>(buffers.size());
    try {
        std::vector<VkDescriptorSetLayoutBinding> bindings(count);
        for (uint32_t i = 0; i < count; ++i) bindings[i] = {i, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, stages, nullptr};
        VkDescriptorSetLayoutCreateInfo li{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
        li.bindingCount = count;
        li.pBindings = bindings.data();
        VK_CHECK(vkCreateDescriptorSetLayout(device, &li, nullptr, &mLayout));
        VkDescriptorPoolSize size{VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, count};
        VkDescriptorPoolCreateInfo pi{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
        pi.maxSets = 1;
        pi.poolSizeCount = 1;
        pi.pPoolSizes = &size;
        VK_CHECK(vkCreateDescriptorPool(device, &pi, nullptr, &mPool));
        VkDescriptorSetAllocateInfo ai{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
        ai.descriptorPool = mPool;
        ai.descriptorSetCount = 1;
        ai.pSetLayouts = &mLayout;
        VK_CHECK(vkAllocateDescriptorSets(device, &ai, &mSet));
        std::vector<VkDescriptorBufferInfo> infos(count);
        std::vector<VkWriteDescriptorSet> writes(count);
        for (uint32_t i = 0; i < count; ++i) {
            infos[i] = {buffers[i], 0, VK_WHOLE_SIZE};
            writes[i] = {VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
            writes[i].dstSet = mSet;
            writes[i].dstBinding = i;
            writes[i].descriptorCount = 1;
            writes[i].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
            writes[i].pBufferInfo = &infos[i];
        }
        vkUpdateDescriptorSets(device, count, writes.data(), 0, nullptr);
        ctx.setName(reinterpret_cast<uint64_t>(mSet), VK_OBJECT_TYPE_DESCRIPTOR_SET, name);
    } catch (...) {
        release();
        throw;
    }
}

StorageBufferSet::~StorageBufferSet() { release(); }

StorageBufferSet::StorageBufferSet(StorageBufferSet&& other) noexcept
    : mCtx(std::exchange(other.mCtx, nullptr)), mLayout(std::exchange(other.mLayout, VK_NULL_HANDLE)),
      mPool(std::exchange(other.mPool, VK_NULL_HANDLE)), mSet(std::exchange(other.mSet, VK_NULL_HANDLE)) {}

StorageBufferSet& StorageBufferSet::operator=(StorageBufferSet&& other) noexcept {
    if (this != &other) {
        release();
        mCtx = std::exchange(other.mCtx, nullptr);
        mLayout = std::exchange(other.mLayout, VK_NULL_HANDLE);
        mPool = std::exchange(other.mPool, VK_NULL_HANDLE);
        mSet = std::exchange(other.mSet, VK_NULL_HANDLE);
    }
    return *this;
}

void StorageBufferSet::release() {
    if (!mCtx) return;
    VkDevice device = mCtx->device();
    VkDescriptorSetLayout layout = std::exchange(mLayout, VK_NULL_HANDLE);
    VkDescriptorPool pool = std::exchange(mPool, VK_NULL_HANDLE);
    mSet = VK_NULL_HANDLE;
    mCtx->destroyLater([device, layout, pool] {
        if (layout) vkDestroyDescriptorSetLayout(device, layout, nullptr);
        if (pool) vkDestroyDescriptorPool(device, pool, nullptr);
    });
    mCtx = nullptr;
}

} // namespace vitrine
