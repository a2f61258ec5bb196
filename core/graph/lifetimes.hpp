#pragma once

#include <cstdint>
#include <vector>

namespace vitrine {

// One transient resource for the aliasing planner: its memory needs and the passes (inclusive
// indices into the pass order) between its first write and its last read.
struct AliasRequest {
    uint64_t size = 0;
    uint64_t alignment = 1;
    uint32_t firstPass = 0;
    uint32_t lastPass = 0;
};

struct AliasPlan {
    std::vector<uint64_t> offsets; // per request, in one shared heap
    uint64_t heapSize = 0;         // memory with aliasing
    uint64_t unaliasedSize = 0;    // memory if every resource had its own (aligned) allocation
};

// Phase 5: places resources with disjoint lifetimes at overlapping offsets of one heap. Greedy
// by decreasing size: each resource takes the lowest aligned offset that overlaps no placed
// resource whose lifetime overlaps its own. Resources whose lifetimes overlap never share
// bytes; the tests check this invariant on random inputs.
AliasPlan planAliasing(const std::vector<AliasRequest>& requests);

bool lifetimesOverlap(const AliasRequest& a, const AliasRequest& b);

} // namespace vitrine
