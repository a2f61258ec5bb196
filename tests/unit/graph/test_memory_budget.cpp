// checkMemoryBudget(): the arithmetic that decides, before anything is allocated, whether a compiled graph's
// textures fit the device (per heap, and per single allocation). No GPU: the budget is written by hand.
#include "core/gpu/memory_budget.hpp"

#include <gtest/gtest.h>

namespace vitrine {
namespace {

constexpr VkDeviceSize kMiB = 1ull << 20;

// Two heaps: types 0 and 1 in heap 0 (1 GiB), type 2 in heap 1 (256 MiB); at most 512 MiB per allocation.
MemoryBudget twoHeaps() {
    MemoryBudget b;
    b.device = "test device";
    b.heaps = {{0, 1024 * kMiB, 1024 * kMiB, false}, {1, 256 * kMiB, 256 * kMiB, false}};
    b.heapOfType = {0, 0, 1};
    b.maxAllocation = 512 * kMiB;
    return b;
}

TEST(MemoryBudget, FitsWhenEveryHeapHoldsItsShare) {
    GraphMemoryPlan plan;
    plan.allocations = {
        {"the transient heap", 0, 500 * kMiB}, {"texture a.color", 1, 500 * kMiB}, {"texture b.color", 2, 256 * kMiB}};
    EXPECT_EQ(checkMemoryBudget(plan, twoHeaps()), "");
}

TEST(MemoryBudget, SumsAllocationsOfOneHeapAcrossMemoryTypes) {
    GraphMemoryPlan plan;
    plan.allocations = {
        {"the transient heap", 0, 500 * kMiB}, {"texture a.color", 1, 500 * kMiB}, {"texture b.color", 1, 100 * kMiB}};
    const std::string message = checkMemoryBudget(plan, twoHeaps());
    EXPECT_NE(message.find("need 1.07 GiB of device memory, but memory heap 0 of test device has 1.00 GiB"),
              std::string::npos)
        << message;
    EXPECT_NE(message.find("the largest part is the transient heap (500.0 MiB)"), std::string::npos) << message;
}

TEST(MemoryBudget, ChecksTheHeapOfTheMemoryType) {
    GraphMemoryPlan plan;
    plan.allocations = {{"texture b.color", 2, 200 * kMiB}, {"texture c.color", 2, 100 * kMiB}};
    const std::string message = checkMemoryBudget(plan, twoHeaps());
    EXPECT_NE(message.find("need 300.0 MiB of device memory, but memory heap 1 of test device has 256.0 MiB"),
              std::string::npos)
        << message;
}

TEST(MemoryBudget, OneAllocationAboveTheLimitFailsEvenWhenTheHeapHasRoom) {
    GraphMemoryPlan plan;
    plan.allocations = {{"the transient heap (3 textures, aliased)", 0, 513 * kMiB}};
    const std::string message = checkMemoryBudget(plan, twoHeaps());
    EXPECT_NE(message.find("the transient heap (3 textures, aliased) needs one allocation of 513.0 MiB, but test "
                           "device allows at most 512.0 MiB per allocation"),
              std::string::npos)
        << message;
}

TEST(MemoryBudget, MeasuredBudgetIsWhatCounts) {
    MemoryBudget b = twoHeaps();
    b.heaps[0].available = 300 * kMiB;
    b.heaps[0].measured = true;
    GraphMemoryPlan plan;
    plan.allocations = {{"texture a.color", 0, 400 * kMiB}};
    const std::string message = checkMemoryBudget(plan, b);
    EXPECT_NE(message.find("has 1.00 GiB, of which 300.0 MiB are available (VK_EXT_memory_budget)"), std::string::npos)
        << message;
    b.enforced = false;
    EXPECT_EQ(checkMemoryBudget(plan, b), "");
}

} // namespace
} // namespace vitrine
