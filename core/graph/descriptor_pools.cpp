#include "core/graph/descriptor_pools.hpp"

#include "core/base/error.hpp"
#include "core/gpu/vk_check.hpp"

#include <string>

namespace vitrine {

DescriptorPools::DescriptorPools(VkDevice device, Capacity capacity) : mDevice(device), mCapacity(capacity) {
    mPools.push_back(createPool());
}

DescriptorPools::~DescriptorPools() {
    for (VkDescriptorPool pool : mPools) vkDestroyDescriptorPool(mDevice, pool, nullptr);
}

DescriptorPools::Counts DescriptorPools::countsOf(std::span<const VkDescriptorType> bindings) {
    Counts counts{};
    for (VkDescriptorType type : bindings) {
        size_t i = 0;
        while (i < kTypes.size() && kTypes[i] != type) ++i;
        if (i == kTypes.size())
            throw InternalError("descriptor type " + std::to_string(static_cast<int>(type)) +
                                " is not one the executor's pools hold");
        ++counts[i];
    }
    return counts;
}

VkDescriptorPool DescriptorPools::createPool() const {
    std::vector<VkDescriptorPoolSize> sizes;
    for (size_t i = 0; i < kTypes.size(); ++i)
        if (mCapacity.descriptors[i]) sizes.push_back({kTypes[i], mCapacity.descriptors[i]});
    VkDescriptorPoolCreateInfo info{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
    info.maxSets = mCapacity.sets;
    info.poolSizeCount = static_cast<uint32_t>(sizes.size());
    info.pPoolSizes = sizes.data();
    VkDescriptorPool pool = VK_NULL_HANDLE;
    VK_CHECK(vkCreateDescriptorPool(mDevice, &info, nullptr, &pool));
    return pool;
}

VkDescriptorSet DescriptorPools::allocate(VkDescriptorSetLayout layout, const Counts& counts) {
    for (size_t i = 0; i < kTypes.size(); ++i)
        if (counts[i] > mCapacity.descriptors[i])
            throw InternalError("a descriptor set of " + std::to_string(counts[i]) + " descriptors of type " +
                                std::to_string(static_cast<int>(kTypes[i])) + " is larger than a whole pool (" +
                                std::to_string(mCapacity.descriptors[i]) + ")");
    bool fits = mSetsUsed < mCapacity.sets;
    for (size_t i = 0; i < kTypes.size(); ++i) fits = fits && mUsed[i] + counts[i] <= mCapacity.descriptors[i];
    if (!fits) {
        ++mCurrent;
        if (mCurrent == mPools.size()) mPools.push_back(createPool());
        mSetsUsed = 0;
        mUsed = {};
    }
    VkDescriptorSetAllocateInfo info{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
    info.descriptorPool = mPools[mCurrent];
    info.descriptorSetCount = 1;
    info.pSetLayouts = &layout;
    VkDescriptorSet set = VK_NULL_HANDLE;
    VK_CHECK(vkAllocateDescriptorSets(mDevice, &info, &set));
    ++mSetsUsed;
    for (size_t i = 0; i < kTypes.size(); ++i) mUsed[i] += counts[i];
    return set;
}

void DescriptorPools::reset() {
    for (size_t i = 0; i <= mCurrent && i < mPools.size(); ++i) VK_CHECK(vkResetDescriptorPool(mDevice, mPools[i], 0));
    mCurrent = 0;
    mSetsUsed = 0;
    mUsed = {};
}

} // namespace vitrine
