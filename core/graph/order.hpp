#pragma once

#include "core/graph/graph_desc.hpp"

#include <cstdint>
#include <vector>

namespace vitrine {

struct GraphOrder {
    std::vector<uint32_t> order;  // indices into GraphDesc::nodes, producers before consumers
    std::vector<uint32_t> culled; // nodes no output depends on, in declaration order
};

// Phase 3: culls nodes no output needs, then orders the rest topologically (Kahn, ties broken
// by declaration order so the order is stable). `x@prev` edges keep x alive but do not order
// it before its reader. A cycle is a UserError naming every node on it.
GraphOrder orderGraph(const GraphDesc& graph);

} // namespace vitrine
