#pragma once
// A descriptor set of storage buffers (binding i = buffers[i], whole size) with its own layout and pool: the
// sets that passes tracing the scene bind beside the graph's set 0 (the BVH, the scene's geometry, a bake's
// job lists). Move-only; destruction is deferred through Context::destroyLater.

#include <vulkan/vulkan.h>

#include <span>
#include <string>

namespace vitrine {

class Context;

class StorageBufferSet {
public:
    StorageBufferSet() = default;
    StorageBufferSet(Context& ctx, std::span<const VkBuffer> buffers, VkShaderStageFlags stages, const std::string& name);
    ~StorageBufferSet();
    StorageBufferSet(StorageBufferSet&& other) noexcept;
    StorageBufferSet& operator=(StorageBufferSet&& other) noexcept;
    StorageBufferSet(const StorageBufferSet&) = delete;
    StorageBufferSet& operator=(const StorageBufferSet&) = delete;

    VkDescriptorSetLayout layout() const { return mLayout; }
    VkDescriptorSet set() const { return mSet; }
    explicit operator bool() const { return mSet != VK_NULL_HANDLE; }

private:
    void release();

    Context* mCtx = nullptr;
    VkDescriptorSetLayout mLayout = VK_NULL_HANDLE;
    VkDescriptorPool mPool = VK_NULL_HANDLE;
    VkDescriptorSet mSet = VK_NULL_HANDLE;
};

} // namespace vitrine
