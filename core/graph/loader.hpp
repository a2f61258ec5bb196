#pragma once

#include "core/graph/graph_desc.hpp"

#include <filesystem>
#include <string>
#include <vector>

namespace vitrine {

class NodeRegistry;

// Phase 1 of the compiler: the JSON document. Reads `file`, follows `extends` (a path
// relative to the extending file) and applies each file as a JSON Merge Patch (RFC 7396) of
// its base, then applies the `--set` assignments in order.
nlohmann::json loadGraphDocument(const std::filesystem::path& file, const std::vector<std::string>& sets = {});

// loadGraphDocument() of a document already read, standing for `file` (which need not exist): its `extends` resolves
// from file's directory and errors name `file`. `vitrine serve` renders documents the editor sends this way.
nlohmann::json mergeGraphDocument(nlohmann::json document, const std::filesystem::path& file,
                                  const std::vector<std::string>& sets = {});

// `node.params.key=value`, `frame.width=640` or `outputs.name=node.port`. The value is JSON
// when it parses as JSON, else a string.
void applySet(nlohmann::json& document, const std::string& assignment);

// Phase 2: checks the document against the node registry and builds the typed graph.
// Every error names the file, the JSON pointer and what was expected.
GraphDesc validateGraph(const nlohmann::json& document, const std::string& file, const NodeRegistry& registry);

// Phase 2 reporting every error it can find rather than the first: each param, input, output and top-level key is
// checked on its own (a reference to a node whose declaration failed is not reported again). Empty when
// validateGraph() would succeed. `vitrine serve` answers /api/validate with these, for the editor to mark them all.
std::vector<std::string> validateGraphErrors(const nlohmann::json& document, const std::string& file,
                                             const NodeRegistry& registry);

// Phases 1 and 2.
GraphDesc loadGraph(const std::filesystem::path& file, const std::vector<std::string>& sets = {});

} // namespace vitrine
