#include "core/graph/lifetimes.hpp"

#include <algorithm>
#include <numeric>

namespace vitrine {

bool lifetimesOverlap(const AliasRequest& a, const AliasRequest& b) {
    return a.firstPass <= b.lastPass && b.firstPass <= a.lastPass;
}

AliasPlan planAliasing(const std::vector<AliasRequest>& requests) {
    AliasPlan plan;
    plan.offsets.assign(requests.size(), 0);
    std::vector<size_t> order(requests.size());
    std::iota(order.begin(), order.end(), 0);
    std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return requests[a].size > requests[b].size; });

    std::vector<size_t> placed;
    for (size_t i : order) {
        const AliasRequest& r = requests[i];
        const uint64_t align = std::max<uint64_t>(1, r.alignment);
        plan.unaliasedSize += (r.size + align - 1) / align * align;
        // Memory ranges of placed resources alive at the same time, sorted by offset.
        std::vector<std::pair<uint64_t, uint64_t>> busy;
        for (size_t j : placed)
            if (lifetimesOverlap(r, requests[j])) busy.push_back({plan.offsets[j], plan.offsets[j] + requests[j].size});
        std::sort(busy.begin(), busy.end());
        uint64_t offset = 0;
        for (const auto& [begin, end] : busy) {
            if (offset + r.size <= begin) break;
            offset = std::max(offset, (end + align - 1) / align * align);
        }
        plan.offsets[i] = offset;
        plan.heapSize = std::max(plan.heapSize, offset + r.size);
        placed.push_back(i);
    }
    return plan;
}

} // namespace vitrine
