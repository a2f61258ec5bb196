#pragma once
// The graph format as a JSON Schema (draft 2020-12), generated from the node registry: node types, each
// type's params (JSON type, range, enum values, default, doc) and port names, `node.port` / `node.port@prev`
// references. Text editors (VS Code and others) validate and complete graph and variant files with it; the
// shipped graphs name it in their `$schema` key. A variant (a file with `extends`) is checked as a JSON Merge
// Patch: node entries may be null or partial, and nothing is required.
#include <nlohmann/json.hpp>

namespace vitrine {

class NodeRegistry;

nlohmann::json graphJsonSchema(const NodeRegistry& registry);

} // namespace vitrine
