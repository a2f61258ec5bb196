#pragma once
// A node's own descriptor sets: a layout from a list of bindings, a pool sized for up to N sets of it, and the
// samplers its image bindings use. Nodes that bind a set beside the graph's (ibl.localized, forward.transparent,
// ibl.capture) make one on their first execute, allocate their set(s) from it and fill them with DescriptorWrites.
// Move-only; destruction (samplers, layout, pool and with it the sets) is deferred through Context::destroyLater.

#include <vulkan/vulkan.h>

#include <span>
#include <string>
#include <vector>

namespace vitrine {

class Context;

// A sampler that clamps to the edge and reaches every mip (maxLod unclamped); the rest of VkSamplerCreateInfo is 0.
struct SamplerDesc {
    VkFilter filter = VK_FILTER_LINEAR;
    VkSamplerMipmapMode mipmap = VK_SAMPLER_MIPMAP_MODE_NEAREST;
};

class DescriptorSets {
public:
    DescriptorSets() = default;
    // The pool holds maxSets sets: for each descriptor type, maxSets times the bindings' descriptors of that type.
    DescriptorSets(Context& ctx, std::span<const VkDescriptorSetLayoutBinding> bindings, uint32_t maxSets,
                   std::span<const SamplerDesc> samplers, const std::string& name);
    ~DescriptorSets();
    DescriptorSets(DescriptorSets&& other) noexcept;
    DescriptorSets& operator=(DescriptorSets&& other) noexcept;
    DescriptorSets(const DescriptorSets&) = delete;
    DescriptorSets& operator=(const DescriptorSets&) = delete;

    VkDescriptorSetLayout layout() const { return mLayout; }
    // The i-th of the samplers given at construction.
    VkSampler sampler(size_t i) const { return mSamplers.at(i); }
    // One more set of the layout from the pool (at most maxSets until reset()).
    VkDescriptorSet allocate();
    // Frees every set allocated so far; the caller makes sure the GPU no longer reads them.
    void reset();
    explicit operator bool() const { return mLayout != VK_NULL_HANDLE; }

private:
    void release();

    Context* mCtx = nullptr;
    VkDescriptorSetLayout mLayout = VK_NULL_HANDLE;
    VkDescriptorPool mPool = VK_NULL_HANDLE;
    std::vector<VkSampler> mSamplers;
};

// The descriptors of one set, written by one vkUpdateDescriptorSets in the order they were added.
class DescriptorWrites {
public:
    explicit DescriptorWrites(VkDescriptorSet set) : mSet(set) {}
    DescriptorWrites& buffer(uint32_t binding, VkDescriptorType type, const VkDescriptorBufferInfo& info);
    DescriptorWrites& image(uint32_t binding, VkDescriptorType type, const VkDescriptorImageInfo& info);
    void update(VkDevice device) const;

private:
    struct Entry {
        uint32_t binding;
        VkDescriptorType type;
        VkDescriptorBufferInfo buffer;
        VkDescriptorImageInfo image;
    };
    VkDescriptorSet mSet;
    std::vector<Entry> mEntries;
};

} // namespace vitrine
