#pragma once

#include <vulkan/vulkan.h>

#include <cstdint>
#include <string>
#include <vector>

namespace vitrine {

// What one memory heap of the device can still take.
struct HeapBudget {
    uint32_t heap = 0;
    VkDeviceSize size = 0;      // VkPhysicalDeviceMemoryProperties
    VkDeviceSize available = 0; // VK_EXT_memory_budget: budget − usage (other programs count); else `size`
    bool measured = false;      // `available` comes from VK_EXT_memory_budget
};

struct MemoryBudget {
    std::string device;
    std::vector<HeapBudget> heaps;    // indexed by heap
    std::vector<uint32_t> heapOfType; // memory type index -> heap index
    VkDeviceSize maxAllocation = 0;   // maxMemoryAllocationSize: the largest single vkAllocateMemory
    bool enforced = true;             // false: VITRINE_MEMORY_BUDGET=off
    std::string source;               // what `available` is: "" (the device), or "VITRINE_MEMORY_BUDGET"
};

// Reads heap sizes, the largest allocation and, when the device has VK_EXT_memory_budget, what each heap has left.
// VITRINE_MEMORY_BUDGET=MIB in the environment replaces what every heap has available (tests lower it; a device whose
// heap size is nominal, like lavapipe's 2 GiB of system memory, can be given more); =off turns the check off.
MemoryBudget queryMemoryBudget(VkPhysicalDevice physicalDevice);

// What a compiled graph will allocate for its textures, per memory type, before anything is allocated.
struct GraphMemoryPlan {
    struct Allocation {
        std::string what; // "the transient heap (12 textures, aliased)" or "texture gbuffer.normal"
        uint32_t memoryType = 0;
        VkDeviceSize bytes = 0;
    };
    std::vector<Allocation> allocations;
};

// "" when every allocation fits the single-allocation limit and each heap's total fits what the heap has available;
// else what does not fit, with the sizes (for a UserError: the graph is too large for this device).
std::string checkMemoryBudget(const GraphMemoryPlan& plan, const MemoryBudget& budget);

// 1.50 GiB, 12.0 MiB, 512 bytes.
std::string formatBytes(uint64_t bytes);

} // namespace vitrine
