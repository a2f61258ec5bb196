#pragma once

#include "core/gpu/vk_check.hpp"

#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace vitrine {


class Context;

struct Allocation {
    VkDeviceMemory memory = VK_NULL_HANDLE;
    VkDeviceSize offset = 0;
    VkDeviceSize size = 0;
    void* mapped = nullptr; // host pointer at `offset` for host-visible memory
    uint32_t pool = UINT32_MAX;
    uint32_t block = UINT32_MAX;
    explicit operator bool() const { return memory != VK_NULL_HANDLE; }
};

struct AllocatorStats {
    VkDeviceSize reserved = 0; // device memory held in blocks
    VkDeviceSize used = 0;     // bytes handed out
    uint32_t blocks = 0;
};

// Sub-allocates resources from large VkDeviceMemory blocks (64 MiB by default), one pool per
// memory type and per linear/optimal tiling so bufferImageGranularity never matters. Free
// ranges are kept sorted by offset and coalesced. Not thread-safe: the render graph records
// on one thread.
class Allocator {
public:
    explicit Allocator(Context& ctx, VkDeviceSize blockSize = 64ull << 20);
    ~Allocator();
    Allocator(const Allocator&) = delete;
    Allocator& operator=(const Allocator&) = delete;

    Allocation allocate(const VkMemoryRequirements& requirements, VkMemoryPropertyFlags properties, bool linear);
    void free(const Allocation& allocation);
    uint32_t findMemoryType(uint32_t typeBits, VkMemoryPropertyFlags properties) const;
    AllocatorStats stats() const;
    const VkPhysicalDeviceMemoryProperties& properties() const { return mProperties; }

private:
    struct Block {
        VkDeviceMemory memory = VK_NULL_HANDLE;
        VkDeviceSize size = 0;
        void* mapped = nullptr;
        std::map<VkDeviceSize, VkDeviceSize> freeRanges; // offset -> size
        VkDeviceSize used = 0;
    };
    struct Pool {
        uint32_t memoryType;
        bool linear;
        std::vector<Block> blocks;
    };

    Context& mCtx;
    VkDeviceSize mBlockSize;
    VkPhysicalDeviceMemoryProperties mProperties{};
    std::vector<Pool> mPools;
};

// Debugging reads of memory nothing wrote (see allocator.cpp): -1 unless VITRINE_DEBUG_POISON_MEMORY is set.
int debugPoisonMemoryByte();
// Fills a fresh host-visible allocation with that byte (when VITRINE_DEBUG_POISON_MEMORY_ONLY is empty or part of name).
void debugPoisonAllocation(const Allocation& allocation, const std::string& name);

} // namespace vitrine
