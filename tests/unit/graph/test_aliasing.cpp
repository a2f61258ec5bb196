// Phase 5: planAliasing. The invariants are checked directly on the plan (byte ranges, lifetimes,
// alignment), never against a second run of the planner.
#include "core/graph/lifetimes.hpp"

#include <gtest/gtest-spi.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <random>

namespace vitrine {
namespace {

bool passesOverlap(const AliasRequest& a, const AliasRequest& b) {
    return a.firstPass <= b.lastPass && b.firstPass <= a.lastPass;
}

uint64_t alignUp(uint64_t v, uint64_t a) {
    return (v + a - 1) / a * a;
}

// Checks every invariant of a plan; `uniformAlignment` says whether all requests share one
// alignment, the case in which the heap can never outgrow separate allocations.
void expectValidPlan(const std::vector<AliasRequest>& requests, const AliasPlan& plan, bool uniformAlignment,
                     const std::string& what) {
    ASSERT_EQ(plan.offsets.size(), requests.size()) << what;
    uint64_t maxSize = 0, separate = 0;
    for (size_t i = 0; i < requests.size(); ++i) {
        const AliasRequest& r = requests[i];
        maxSize = std::max(maxSize, r.size);
        separate += alignUp(r.size, std::max<uint64_t>(1, r.alignment));
        EXPECT_EQ(plan.offsets[i] % std::max<uint64_t>(1, r.alignment), 0u) << what << ": request " << i;
        EXPECT_LE(plan.offsets[i] + r.size, plan.heapSize) << what << ": request " << i << " ends outside the heap";
        for (size_t j = i + 1; j < requests.size(); ++j) {
            if (!passesOverlap(r, requests[j])) continue;
            bool bytesOverlap =
                plan.offsets[i] < plan.offsets[j] + requests[j].size && plan.offsets[j] < plan.offsets[i] + r.size;
            EXPECT_FALSE(bytesOverlap) << what << ": requests " << i << " and " << j << " are alive together (passes "
                                       << r.firstPass << "-" << r.lastPass << " and " << requests[j].firstPass << "-"
                                       << requests[j].lastPass << ") but share bytes [" << plan.offsets[i] << ", "
                                       << plan.offsets[i] + r.size << ") and [" << plan.offsets[j] << ", "
                                       << plan.offsets[j] + requests[j].size << ")";
        }
    }
    EXPECT_EQ(plan.unaliasedSize, separate) << what;
    EXPECT_GE(plan.heapSize, maxSize) << what;
    if (uniformAlignment) {
        EXPECT_LE(plan.heapSize, plan.unaliasedSize) << what;
    }
}

TEST(GraphAliasing, InvariantCheckCatchesABadPlan) {
    // The checker used below must be able to fail: hand-made plans that break each invariant.
    std::vector<AliasRequest> requests = {{100, 64, 0, 1}, {100, 64, 1, 2}};
    AliasPlan overlapping{{0, 64}, 164, 256};
    EXPECT_NONFATAL_FAILURE(expectValidPlan(requests, overlapping, true, "bad"), "share bytes");
    AliasPlan misaligned{{0, 100}, 200, 256};
    EXPECT_NONFATAL_FAILURE(expectValidPlan(requests, misaligned, true, "bad"), "request 1");
    AliasPlan tooBig{{0, 128}, 1000, 256};
    EXPECT_NONFATAL_FAILURE(expectValidPlan(requests, tooBig, true, "bad"), "unaliasedSize");
}

TEST(GraphAliasing, RandomRequestSetsNeverShareBytesWhileAlive) {
    std::mt19937 rng(20240611);
    const uint64_t kAlignments[] = {1, 256, 1024, 4096, 65536};
    int aliasedSets = 0;
    for (int set = 0; set < 200; ++set) {
        const uint32_t passes = 1 + rng() % 12;
        const size_t count = 1 + rng() % 24;
        // Even sets use one alignment for all requests (as images of one memory type usually
        // have); odd sets mix alignments and sizes that are not multiples of them.
        const bool uniform = set % 2 == 0;
        const uint64_t setAlignment = kAlignments[rng() % 5];
        std::vector<AliasRequest> requests(count);
        for (auto& r : requests) {
            r.alignment = uniform ? setAlignment : kAlignments[rng() % 5];
            r.size = uniform && rng() % 2 ? (1 + rng() % 64) * r.alignment : 1 + rng() % (1u << 20);
            r.firstPass = rng() % passes;
            r.lastPass = r.firstPass + rng() % (passes - r.firstPass);
        }
        AliasPlan plan = planAliasing(requests);
        expectValidPlan(requests, plan, uniform, "set " + std::to_string(set));
        if (plan.heapSize < plan.unaliasedSize) ++aliasedSets;
    }
    // The sets are random enough that aliasing must have saved memory in many of them.
    EXPECT_GT(aliasedSets, 50);
}

TEST(GraphAliasing, DisjointNeighboursShareMemory) {
    // A lives in passes 0-1, B in 1-2, C in 2-3: A and C never coexist, B overlaps both.
    const uint64_t size = 3 * 65536;
    std::vector<AliasRequest> requests = {{size, 65536, 0, 1}, {size, 65536, 1, 2}, {size, 65536, 2, 3}};
    AliasPlan plan = planAliasing(requests);
    expectValidPlan(requests, plan, true, "A, B, C");
    EXPECT_EQ(plan.offsets[0], plan.offsets[2]) << "A and C should reuse the same memory";
    EXPECT_NE(plan.offsets[0], plan.offsets[1]);
    EXPECT_EQ(plan.heapSize, 2 * size);
    EXPECT_EQ(plan.unaliasedSize, 3 * size);
}

TEST(GraphAliasing, SamePassResourcesNeverAlias) {
    // Lifetimes are inclusive: two resources that both touch pass 2 are alive together.
    std::vector<AliasRequest> requests = {{1000, 1, 0, 2}, {1000, 1, 2, 4}};
    AliasPlan plan = planAliasing(requests);
    expectValidPlan(requests, plan, true, "touching");
    EXPECT_EQ(plan.heapSize, 2000u);
}

TEST(GraphAliasing, SmallResourceFitsIntoAGapWithAlignment) {
    // big0 (0-0) and big1 (2-2) are never alive together and share offset 0; mid (0-2)
    // overlaps both, so it goes above them at 1024 (aligned). small (1-1) overlaps only mid
    // and fits below it at 0.
    std::vector<AliasRequest> requests = {{1000, 256, 0, 0}, {1000, 256, 2, 2}, {500, 512, 0, 2}, {100, 256, 1, 1}};
    AliasPlan plan = planAliasing(requests);
    expectValidPlan(requests, plan, false, "gap");
    EXPECT_EQ(plan.offsets[0], 0u);
    EXPECT_EQ(plan.offsets[1], 0u);
    EXPECT_EQ(plan.offsets[2], 1024u);
    EXPECT_EQ(plan.offsets[3], 0u);
    EXPECT_EQ(plan.heapSize, 1524u);
}

TEST(GraphAliasing, EmptyRequestListNeedsNoHeap) {
    AliasPlan plan = planAliasing({});
    EXPECT_TRUE(plan.offsets.empty());
    EXPECT_EQ(plan.heapSize, 0u);
    EXPECT_EQ(plan.unaliasedSize, 0u);
}

} // namespace
} // namespace vitrine
