#include "core/graph/order.hpp"

#include "core/base/error.hpp"
#include "core/graph/json_util.hpp"

#include <algorithm>
#include <functional>

namespace vitrine {

GraphOrder orderGraph(const GraphDesc& g) {
    const size_t n = g.nodes.size();
    std::vector<bool> live(n, false);
    std::vector<uint32_t> stack;
    for (const auto& out : g.outputs) stack.push_back(static_cast<uint32_t>(g.findNode(out.source.node)));
    while (!stack.empty()) {
        uint32_t i = stack.back();
        stack.pop_back();
        if (live[i]) continue;
        live[i] = true;
        for (const auto& [port, ref] : g.nodes[i].inputs) stack.push_back(static_cast<uint32_t>(g.findNode(ref.node)));
    }

    // Edges producer -> consumer, same-frame reads only.
    std::vector<std::vector<uint32_t>> consumers(n);
    std::vector<uint32_t> indegree(n, 0);
    for (uint32_t i = 0; i < n; ++i) {
        if (!live[i]) continue;
        for (const auto& [port, ref] : g.nodes[i].inputs) {
            if (ref.previous) continue;
            uint32_t p = static_cast<uint32_t>(g.findNode(ref.node));
            consumers[p].push_back(i);
            ++indegree[i];
        }
    }

    GraphOrder result;
    std::vector<uint32_t> ready;
    for (uint32_t i = 0; i < n; ++i) {
        if (!live[i]) result.culled.push_back(i);
        else if (indegree[i] == 0) ready.push_back(i);
    }
    while (!ready.empty()) {
        auto it = std::min_element(ready.begin(), ready.end());
        uint32_t i = *it;
        ready.erase(it);
        result.order.push_back(i);
        for (uint32_t c : consumers[i])
            if (--indegree[c] == 0) ready.push_back(c);
    }

    size_t liveCount = static_cast<size_t>(std::count(live.begin(), live.end(), true));
    if (result.order.size() != liveCount) {
        // Walk same-frame inputs from a node left over until a node repeats: that loop is the cycle.
        uint32_t start = 0;
        while (!live[start] || indegree[start] == 0) ++start;
        std::vector<uint32_t> path;
        std::vector<int> position(n, -1);
        uint32_t cur = start;
        while (position[cur] < 0) {
            position[cur] = static_cast<int>(path.size());
            path.push_back(cur);
            for (const auto& [port, ref] : g.nodes[cur].inputs) {
                uint32_t p = static_cast<uint32_t>(g.findNode(ref.node));
                if (!ref.previous && indegree[p] > 0) {
                    cur = p;
                    break;
                }
            }
        }
        std::vector<uint32_t> cycle(path.begin() + position[cur], path.end());
        std::reverse(cycle.begin(), cycle.end()); // producer -> consumer order
        std::string text;
        for (uint32_t i : cycle) text += g.nodes[i].id + " -> ";
        text += g.nodes[cycle.front()].id;
        const NodeDecl& first = g.nodes[cycle.front()];
        std::string port;
        for (const auto& [name, ref] : first.inputs)
            if (ref.node == g.nodes[cycle.back()].id && !ref.previous) port = name;
        throw UserError(g.where(first.pointer() + "/in/" + pointerToken(port)) + ": the graph has a cycle: " + text +
                        " (to read last frame's value, use \"node.port@prev\")");
    }
    return result;
}

} // namespace vitrine
