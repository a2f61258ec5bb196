#include "core/graph/registry.hpp"

#include "core/base/error.hpp"
#include "core/graph/node.hpp"

namespace vitrine {

NodeRegistry& NodeRegistry::global() {
    static NodeRegistry registry;
    return registry;
}

void NodeRegistry::add(NodeSchema schema, NodeFactory factory) {
    std::string type = schema.type;
    for (const auto& p : schema.params)
        if (!checkParam(p, p.defaultValue).empty())
            throw InternalError("node " + type + ": default of param '" + p.name + "' is not " + checkParam(p, p.defaultValue));
    if (!mEntries.emplace(type, Entry{std::move(schema), std::move(factory)}).second)
        throw InternalError("node type '" + type + "' registered twice");
}

const NodeSchema* NodeRegistry::find(const std::string& type) const {
    auto it = mEntries.find(type);
    return it == mEntries.end() ? nullptr : &it->second.schema;
}

std::unique_ptr<Node> NodeRegistry::create(const std::string& type) const {
    auto it = mEntries.find(type);
    if (it == mEntries.end()) throw InternalError("no node type '" + type + "'");
    return it->second.factory();
}

std::vector<const NodeSchema*> NodeRegistry::all() const {
    std::vector<const NodeSchema*> out;
    for (const auto& [name, entry] : mEntries) out.push_back(&entry.schema);
    return out;
}

nlohmann::json NodeRegistry::toJson() const {
    nlohmann::json j = nlohmann::json::array();
    for (const auto& [name, entry] : mEntries) j.push_back(entry.schema.toJson());
    return j;
}

NodeRegistration::NodeRegistration(NodeSchema schema, NodeFactory factory) {
    NodeRegistry::global().add(std::move(schema), std::move(factory));
}

} // namespace vitrine
