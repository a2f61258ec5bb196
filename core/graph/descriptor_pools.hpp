#pragma once
// The descriptor sets the executor allocates for each dispatch and draw: a chain of pools that grows when a frame
// (or the part of it between two submissions) needs more than one pool holds, reset as a whole when the GPU is done
// with the sets. The chain counts what it hands out itself rather than waiting for vkAllocateDescriptorSets to
// fail: lavapipe never refuses an allocation past a pool's sizes, the NVIDIA driver does (VK_ERROR_OUT_OF_POOL_MEMORY,
// seen on an H200 when render.pathtrace converged for hundreds of batches in one frame), so the switch to the next
// pool happens at the same point on every device.
#include <vulkan/vulkan.h>

#include <array>
#include <cstdint>
#include <span>
#include <vector>

namespace vitrine {

class DescriptorPools {
public:
    // The descriptor types the executor binds, in the order of a Counts array.
    static constexpr std::array<VkDescriptorType, 5> kTypes = {
        VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE,
        VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER};
    using Counts = std::array<uint32_t, kTypes.size()>;

    // Capacity of each pool: sets and descriptors of each type.
    struct Capacity {
        uint32_t sets = 2048;
        Counts descriptors = {4096, 1024, 4096, 256, 256};
    };

    DescriptorPools(VkDevice device, Capacity capacity);
    DescriptorPools(VkDevice device) : DescriptorPools(device, Capacity{}) {}
    ~DescriptorPools();
    DescriptorPools(const DescriptorPools&) = delete;
    DescriptorPools& operator=(const DescriptorPools&) = delete;

    // What one set of these bindings takes (one descriptor per binding).
    static Counts countsOf(std::span<const VkDescriptorType> bindings);

    // A set of `layout`, which holds `counts` descriptors; from the current pool while it has room, else from the
    // next one (created the first time it is needed). Throws InternalError for a layout larger than a whole pool.
    VkDescriptorSet allocate(VkDescriptorSetLayout layout, const Counts& counts);

    // Every set handed out is free again: call only once the GPU has finished the work that binds them.
    void reset();

    size_t poolCount() const { return mPools.size(); }

private:
    VkDescriptorPool createPool() const;

    VkDevice mDevice;
    Capacity mCapacity;
    std::vector<VkDescriptorPool> mPools;
    size_t mCurrent = 0;
    uint32_t mSetsUsed = 0;
    Counts mUsed{};
};

} // namespace vitrine
