#include "core/gpu/descriptors.hpp"

#include "core/gpu/context.hpp"
#include "core/gpu/vk_check.hpp"

#include <utility>

namespace vitrine {

DescriptorSets::DescriptorSets(Context& ctx, std::span<const VkDescriptorSetLayoutBinding> bindings, uint32_t maxSets,
                               std::span<const SamplerDesc> samplers, const std::string& name)
    : mCtx(&ctx) {
    VkDevice device = ctx.device();
    try {
        VkDescriptorSetLayoutCreateInfo li{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
        li.bindingCount = static_cast<uint32_t>(bindings.size());
        li.pBindings = bindings.data();
        VK_CHECK(vkCreateDescriptorSetLayout(device, &li, nullptr, &mLayout));
        ctx.setName(reinterpret_cast<uint64_t>(mLayout), VK_OBJECT_TYPE_DESCRIPTOR_SET_LAYOUT, name);
        // One pool size per descriptor type, in the order the types first appear.
        std::vector<VkDescriptorPoolSize> sizes;
        for (const VkDescriptorSetLayoutBinding& b : bindings) {
            auto it = sizes.begin();
            while (it != sizes.end() && it->type != b.descriptorType)
                ++it;
            if (it == sizes.end()) it = sizes.insert(it, {b.descriptorType, 0});
            it->descriptorCount += b.descriptorCount * maxSets;
        }
        VkDescriptorPoolCreateInfo pi{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
        pi.maxSets = maxSets;
        pi.poolSizeCount = static_cast<uint32_t>(sizes.size());
        pi.pPoolSizes = sizes.data();
        VK_CHECK(vkCreateDescriptorPool(device, &pi, nullptr, &mPool));
        ctx.setName(reinterpret_cast<uint64_t>(mPool), VK_OBJECT_TYPE_DESCRIPTOR_POOL, name);
        for (const SamplerDesc& s : samplers) {
            VkSamplerCreateInfo si{VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO};
            si.magFilter = si.minFilter = s.filter;
            si.mipmapMode = s.mipmap;
            si.addressModeU = si.addressModeV = si.addressModeW = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE;
            si.maxLod = VK_LOD_CLAMP_NONE;
            VkSampler sampler = VK_NULL_HANDLE;
            VK_CHECK(vkCreateSampler(device, &si, nullptr, &sampler));
            mSamplers.push_back(sampler);
        }
    } catch (...) {
        release();
        throw;
    }
}

DescriptorSets::~DescriptorSets() {
    release();
}

DescriptorSets::DescriptorSets(DescriptorSets&& other) noexcept
    : mCtx(std::exchange(other.mCtx, nullptr)), mLayout(std::exchange(other.mLayout, VK_NULL_HANDLE)),
      mPool(std::exchange(other.mPool, VK_NULL_HANDLE)), mSamplers(std::exchange(other.mSamplers, {})) {}

DescriptorSets& DescriptorSets::operator=(DescriptorSets&& other) noexcept {
    if (this != &other) {
        release();
        mCtx = std::exchange(other.mCtx, nullptr);
        mLayout = std::exchange(other.mLayout, VK_NULL_HANDLE);
        mPool = std::exchange(other.mPool, VK_NULL_HANDLE);
        mSamplers = std::exchange(other.mSamplers, {});
    }
    return *this;
}

VkDescriptorSet DescriptorSets::allocate() {
    VkDescriptorSetAllocateInfo ai{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
    ai.descriptorPool = mPool;
    ai.descriptorSetCount = 1;
    ai.pSetLayouts = &mLayout;
    VkDescriptorSet set = VK_NULL_HANDLE;
    VK_CHECK(vkAllocateDescriptorSets(mCtx->device(), &ai, &set));
    return set;
}

void DescriptorSets::reset() {
    VK_CHECK(vkResetDescriptorPool(mCtx->device(), mPool, 0));
}

void DescriptorSets::release() {
    if (!mCtx) return;
    VkDevice device = mCtx->device();
    VkDescriptorSetLayout layout = std::exchange(mLayout, VK_NULL_HANDLE);
    VkDescriptorPool pool = std::exchange(mPool, VK_NULL_HANDLE);
    std::vector<VkSampler> samplers = std::exchange(mSamplers, {});
    mCtx->destroyLater([device, layout, pool, samplers] {
        for (VkSampler s : samplers)
            vkDestroySampler(device, s, nullptr);
        if (layout) vkDestroyDescriptorSetLayout(device, layout, nullptr);
        if (pool) vkDestroyDescriptorPool(device, pool, nullptr);
    });
    mCtx = nullptr;
}

DescriptorWrites& DescriptorWrites::buffer(uint32_t binding, VkDescriptorType type,
                                           const VkDescriptorBufferInfo& info) {
    mEntries.push_back({binding, type, info, {}});
    return *this;
}

DescriptorWrites& DescriptorWrites::image(uint32_t binding, VkDescriptorType type, const VkDescriptorImageInfo& info) {
    mEntries.push_back({binding, type, {}, info});
    return *this;
}

void DescriptorWrites::update(VkDevice device) const {
    std::vector<VkWriteDescriptorSet> writes(mEntries.size());
    for (size_t i = 0; i < mEntries.size(); ++i) {
        const Entry& e = mEntries[i];
        const bool isBuffer =
            e.type == VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER || e.type == VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
        writes[i] = {VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
        writes[i].dstSet = mSet;
        writes[i].dstBinding = e.binding;
        writes[i].descriptorCount = 1;
        writes[i].descriptorType = e.type;
        if (isBuffer)
            writes[i].pBufferInfo = &e.buffer;
        else
            writes[i].pImageInfo = &e.image;
    }
    vkUpdateDescriptorSets(device, static_cast<uint32_t>(writes.size()), writes.data(), 0, nullptr);
}

} // namespace vitrine
