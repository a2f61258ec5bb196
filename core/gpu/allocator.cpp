#include "core/gpu/allocator.hpp"

#include "core/base/error.hpp"
#include "core/gpu/context.hpp"

#include <cstdlib>
#include <cstring>

namespace vitrine {

int debugPoisonMemoryByte() {
    // VITRINE_DEBUG_POISON_MEMORY=<0..255>: every host-visible sub-allocation is filled with that byte when handed out,
    // so a read of memory nothing wrote shows up (0xff is NaN in every float format) instead of reading whatever the
    // last owner of the range left there.
    static const int byte = [] {
        const char* v = std::getenv("VITRINE_DEBUG_POISON_MEMORY");
        if (!v || !*v) return -1;
        char* end = nullptr;
        long b = std::strtol(v, &end, 0);
        if (*end || b < 0 || b > 255) throw UserError(std::string("VITRINE_DEBUG_POISON_MEMORY='") + v + "': expected a byte value 0..255");
        return static_cast<int>(b);
    }();
    return byte;
}

void debugPoisonAllocation(const Allocation& a, const std::string& name) {
    if (!a.mapped || debugPoisonMemoryByte() < 0) return;
    static const std::string only = [] {
        const char* v = std::getenv("VITRINE_DEBUG_POISON_MEMORY_ONLY"); // a part of the resource's name
        return std::string(v ? v : "");
    }();
    if (!only.empty() && name.find(only) == std::string::npos) return;
    std::memset(a.mapped, debugPoisonMemoryByte(), a.size);
}

Allocator::Allocator(Context& ctx, VkDeviceSize blockSize) : mCtx(ctx), mBlockSize(blockSize) {
    vkGetPhysicalDeviceMemoryProperties(ctx.physicalDevice(), &mProperties);
}

Allocator::~Allocator() {
    for (auto& pool : mPools)
        for (auto& block : pool.blocks)
            if (block.memory) vkFreeMemory(mCtx.device(), block.memory, nullptr);
}

uint32_t Allocator::findMemoryType(uint32_t typeBits, VkMemoryPropertyFlags properties) const {
    for (uint32_t i = 0; i < mProperties.memoryTypeCount; ++i)
        if ((typeBits & (1u << i)) && (mProperties.memoryTypes[i].propertyFlags & properties) == properties) return i;
    throw InternalError("no Vulkan memory type with properties " + std::to_string(properties) + " in mask " +
                        std::to_string(typeBits));
}

Allocation Allocator::allocate(const VkMemoryRequirements& req, VkMemoryPropertyFlags properties, bool linear) {
    uint32_t type = findMemoryType(req.memoryTypeBits, properties);
    uint32_t poolIndex = 0;
    for (; poolIndex < mPools.size(); ++poolIndex)
        if (mPools[poolIndex].memoryType == type && mPools[poolIndex].linear == linear) break;
    if (poolIndex == mPools.size()) mPools.push_back(Pool{type, linear, {}});
    Pool& pool = mPools[poolIndex];
    const VkDeviceSize align = req.alignment ? req.alignment : 1;

    auto tryBlock = [&](uint32_t blockIndex) -> Allocation {
        Block& block = pool.blocks[blockIndex];
        for (auto it = block.freeRanges.begin(); it != block.freeRanges.end(); ++it) {
            VkDeviceSize start = (it->first + align - 1) / align * align;
            VkDeviceSize end = it->first + it->second;
            if (start + req.size > end) continue;
            VkDeviceSize rangeStart = it->first;
            block.freeRanges.erase(it);
            if (start > rangeStart) block.freeRanges[rangeStart] = start - rangeStart;
            if (start + req.size < end) block.freeRanges[start + req.size] = end - (start + req.size);
            block.used += req.size;
            Allocation a;
            a.memory = block.memory;
            a.offset = start;
            a.size = req.size;
            a.mapped = block.mapped ? static_cast<char*>(block.mapped) + start : nullptr;
            a.pool = poolIndex;
            a.block = blockIndex;
            return a;
        }
        return {};
    };

    for (uint32_t b = 0; b < pool.blocks.size(); ++b)
        if (pool.blocks[b].memory)
            if (Allocation a = tryBlock(b)) return a;

    Block block;
    block.size = std::max(mBlockSize, (req.size + align - 1) / align * align);
    VkMemoryAllocateInfo info{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    info.allocationSize = block.size;
    info.memoryTypeIndex = type;
    VK_CHECK(vkAllocateMemory(mCtx.device(), &info, nullptr, &block.memory));
    if (mProperties.memoryTypes[type].propertyFlags & VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT)
        VK_CHECK(vkMapMemory(mCtx.device(), block.memory, 0, VK_WHOLE_SIZE, 0, &block.mapped));
    block.freeRanges[0] = block.size;
    pool.blocks.push_back(std::move(block));
    Allocation a = tryBlock(static_cast<uint32_t>(pool.blocks.size() - 1));
    if (!a) throw InternalError("allocator: fresh block cannot hold " + std::to_string(req.size) + " bytes");
    return a;
}

void Allocator::free(const Allocation& a) {
    if (!a) return;
    Block& block = mPools.at(a.pool).blocks.at(a.block);
    block.used -= a.size;
    auto [it, inserted] = block.freeRanges.emplace(a.offset, a.size);
    if (!inserted) throw InternalError("allocator: double free");
    auto next = std::next(it);
    if (next != block.freeRanges.end() && it->first + it->second == next->first) {
        it->second += next->second;
        block.freeRanges.erase(next);
    }
    if (it != block.freeRanges.begin()) {
        auto prev = std::prev(it);
        if (prev->first + prev->second == it->first) {
            prev->second += it->second;
            block.freeRanges.erase(it);
        }
    }
    // Blocks are kept for reuse; an empty block past the first one of a pool is released.
    if (block.used == 0 && a.block > 0) {
        vkFreeMemory(mCtx.device(), block.memory, nullptr);
        block = Block{};
    }
}

AllocatorStats Allocator::stats() const {
    AllocatorStats s;
    for (const auto& pool : mPools)
        for (const auto& block : pool.blocks)
            if (block.memory) {
                s.reserved += block.size;
                s.used += block.used;
                ++s.blocks;
            }
    return s;
}

} // namespace vitrine
