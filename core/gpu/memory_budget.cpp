#include "core/gpu/memory_budget.hpp"

#include "core/base/error.hpp"

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>

namespace vitrine {

MemoryBudget queryMemoryBudget(VkPhysicalDevice physicalDevice) {
    uint32_t count = 0;
    vkEnumerateDeviceExtensionProperties(physicalDevice, nullptr, &count, nullptr);
    std::vector<VkExtensionProperties> extensions(count);
    vkEnumerateDeviceExtensionProperties(physicalDevice, nullptr, &count, extensions.data());
    bool hasBudget = false;
    for (const auto& e : extensions)
        hasBudget = hasBudget || std::strcmp(e.extensionName, VK_EXT_MEMORY_BUDGET_EXTENSION_NAME) == 0;

    // A physical-device query of a device extension needs only the extension's support, not its enabling.
    VkPhysicalDeviceMemoryBudgetPropertiesEXT budget{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_MEMORY_BUDGET_PROPERTIES_EXT};
    VkPhysicalDeviceMemoryProperties2 memory{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_MEMORY_PROPERTIES_2};
    if (hasBudget) memory.pNext = &budget;
    vkGetPhysicalDeviceMemoryProperties2(physicalDevice, &memory);

    VkPhysicalDeviceMaintenance3Properties maintenance3{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_MAINTENANCE_3_PROPERTIES};
    VkPhysicalDeviceProperties2 properties{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2};
    properties.pNext = &maintenance3;
    vkGetPhysicalDeviceProperties2(physicalDevice, &properties);

    MemoryBudget result;
    result.device = properties.properties.deviceName;
    result.maxAllocation = maintenance3.maxMemoryAllocationSize;
    const VkPhysicalDeviceMemoryProperties& m = memory.memoryProperties;
    for (uint32_t h = 0; h < m.memoryHeapCount; ++h) {
        HeapBudget heap{h, m.memoryHeaps[h].size, m.memoryHeaps[h].size, false};
        if (hasBudget && budget.heapBudget[h] > 0) {
            heap.available =
                budget.heapBudget[h] > budget.heapUsage[h] ? budget.heapBudget[h] - budget.heapUsage[h] : 0;
            heap.measured = true;
        }
        result.heaps.push_back(heap);
    }
    for (uint32_t t = 0; t < m.memoryTypeCount; ++t)
        result.heapOfType.push_back(m.memoryTypes[t].heapIndex);

    if (const char* env = std::getenv("VITRINE_MEMORY_BUDGET")) {
        std::string text = env;
        char* end = nullptr;
        unsigned long long mib = std::strtoull(env, &end, 10);
        if (text == "off") {
            result.enforced = false;
        } else if (text.empty() || *end != '\0' || mib > (1ull << 40)) {
            throw UserError("VITRINE_MEMORY_BUDGET: expected a size in MiB or off, got '" + text + "'");
        } else {
            for (HeapBudget& heap : result.heaps)
                heap.available = mib << 20;
            result.source = "VITRINE_MEMORY_BUDGET";
        }
    }
    return result;
}

std::string formatBytes(uint64_t bytes) {
    char text[32];
    if (bytes >= (1ull << 30))
        std::snprintf(text, sizeof text, "%.2f GiB", static_cast<double>(bytes) / (1ull << 30));
    else if (bytes >= (1ull << 20))
        std::snprintf(text, sizeof text, "%.1f MiB", static_cast<double>(bytes) / (1ull << 20));
    else
        std::snprintf(text, sizeof text, "%llu bytes", static_cast<unsigned long long>(bytes));
    return text;
}

std::string checkMemoryBudget(const GraphMemoryPlan& plan, const MemoryBudget& budget) {
    if (!budget.enforced) return "";
    for (const auto& a : plan.allocations) {
        if (budget.maxAllocation > 0 && a.bytes > budget.maxAllocation)
            return a.what + " needs one allocation of " + formatBytes(a.bytes) + ", but " + budget.device +
                   " allows at most " + formatBytes(budget.maxAllocation) + " per allocation (maxMemoryAllocationSize)";
    }
    std::map<uint32_t, VkDeviceSize> perHeap;
    std::map<uint32_t, std::string> largest;
    std::map<uint32_t, VkDeviceSize> largestBytes;
    for (const auto& a : plan.allocations) {
        uint32_t heap = a.memoryType < budget.heapOfType.size() ? budget.heapOfType[a.memoryType] : 0;
        perHeap[heap] += a.bytes;
        if (a.bytes > largestBytes[heap]) largestBytes[heap] = a.bytes, largest[heap] = a.what;
    }
    for (const auto& [heap, bytes] : perHeap) {
        if (heap >= budget.heaps.size()) continue;
        const HeapBudget& h = budget.heaps[heap];
        if (bytes <= h.available) continue;
        std::string has =
            "memory heap " + std::to_string(heap) + " of " + budget.device + " has " + formatBytes(h.size);
        if (!budget.source.empty())
            has += ", of which " + budget.source + " allows " + formatBytes(h.available);
        else if (h.measured)
            has += ", of which " + formatBytes(h.available) + " are available (VK_EXT_memory_budget)";
        return "the graph's textures need " + formatBytes(bytes) + " of device memory, but " + has +
               "; the largest part is " + largest[heap] + " (" + formatBytes(largestBytes[heap]) + ")";
    }
    return "";
}

} // namespace vitrine
