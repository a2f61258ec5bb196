#pragma once

#include "core/graph/types.hpp"

#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

namespace vitrine {

class Node;
using NodeFactory = std::function<std::unique_ptr<Node>()>;

// All node types by dotted name. Nodes register themselves from their own .cpp through a
// static NodeRegistration; nodes/ is an OBJECT library so the linker keeps those objects.
class NodeRegistry {
public:
    static NodeRegistry& global();

    void add(NodeSchema schema, NodeFactory factory);
    const NodeSchema* find(const std::string& type) const;
    std::unique_ptr<Node> create(const std::string& type) const;
    std::vector<const NodeSchema*> all() const; // sorted by type name
    nlohmann::json toJson() const;

private:
    struct Entry {
        NodeSchema schema;
        NodeFactory factory;
    };
    std::map<std::string, Entry> mEntries;
};

struct NodeRegistration {
    NodeRegistration(NodeSchema schema, NodeFactory factory);
};

} // namespace vitrine
