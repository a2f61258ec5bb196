#include "core/graph/loader.hpp"

#include "core/base/error.hpp"
#include "core/base/json_text.hpp"
#include "core/graph/json_util.hpp"
#include "core/graph/registry.hpp"

#include <algorithm>

namespace vitrine {

namespace fs = std::filesystem;

namespace {

nlohmann::json mergeWithBases(nlohmann::json doc, const fs::path& file, std::vector<fs::path>& chain);

// A graph's relative `path`-typed params resolve from its own folder. The merged document of a variant resolves them
// from the variant's, so a base's are rewritten relative to that folder first (`from`: the base's folder, `to`: the
// variant's; both absolute). A bare file name that is not beside the base is left as it is: a node may look it up
// elsewhere (color.grade's `lut` in data/luts/).
void rebasePaths(nlohmann::json& base, const fs::path& from, const fs::path& to) {
    if (from == to) return;
    auto nodes = base.find("nodes");
    if (nodes == base.end() || !nodes->is_object()) return;
    for (auto& [name, node] : nodes->items()) {
        if (!node.is_object()) continue;
        auto type = node.find("type");
        auto params = node.find("params");
        if (type == node.end() || !type->is_string() || params == node.end() || !params->is_object()) continue;
        const NodeSchema* schema = NodeRegistry::global().find(type->get<std::string>());
        if (!schema) continue;
        for (const ParamSpec& spec : schema->params) {
            if (spec.type != ParamType::Path) continue;
            auto value = params->find(spec.name);
            if (value == params->end() || !value->is_string()) continue;
            const fs::path path(value->get<std::string>());
            if (path.empty() || path.is_absolute()) continue;
            std::error_code ec;
            if (!path.has_parent_path() && !fs::exists(from / path, ec)) continue;
            *value = (from / path).lexically_normal().lexically_relative(to).generic_string();
        }
    }
}

nlohmann::json loadWithBases(const fs::path& file, std::vector<fs::path>& chain) {
    return mergeWithBases(readJsonFile(file), file, chain);
}

nlohmann::json mergeWithBases(nlohmann::json doc, const fs::path& file, std::vector<fs::path>& chain) {
    std::error_code ec;
    fs::path canonical = fs::weakly_canonical(file, ec);
    if (ec) canonical = file.lexically_normal();
    if (std::find(chain.begin(), chain.end(), canonical) != chain.end()) {
        std::string cycle;
        for (const auto& p : chain) cycle += p.filename().string() + " -> ";
        throw UserError(file.string() + ": /extends: `extends` forms a cycle: " + cycle + file.filename().string());
    }
    chain.push_back(canonical);
    if (!doc.is_object()) throw UserError(file.string() + ": /: expected a JSON object (a vitrine graph)");
    auto it = doc.find("extends");
    if (it == doc.end()) return doc;
    if (!it->is_string()) throw UserError(file.string() + ": /extends: expected a path to the base graph, got " + brief(*it));
    fs::path base = file.parent_path() / it->get<std::string>();
    if (!fs::is_regular_file(base, ec))
        throw UserError(file.string() + ": /extends: base graph " + base.string() + " does not exist");
    nlohmann::json merged = loadWithBases(base, chain);
    fs::path baseCanonical = fs::weakly_canonical(base, ec);
    if (ec) baseCanonical = fs::absolute(base).lexically_normal();
    rebasePaths(merged, baseCanonical.parent_path(),
                canonical.is_absolute() ? canonical.parent_path() : fs::absolute(canonical).parent_path());
    doc.erase("extends");
    merged.merge_patch(doc);
    return merged;
}

} // namespace

nlohmann::json loadGraphDocument(const fs::path& file, const std::vector<std::string>& sets) {
    return mergeGraphDocument(readJsonFile(file), file, sets);
}

nlohmann::json mergeGraphDocument(nlohmann::json document, const fs::path& file, const std::vector<std::string>& sets) {
    std::vector<fs::path> chain;
    nlohmann::json doc = mergeWithBases(std::move(document), file, chain);
    for (const auto& s : sets) {
        try {
            applySet(doc, s);
        } catch (const UserError& e) {
            throw UserError(file.string() + ": " + e.what());
        }
    }
    return doc;
}

namespace {

// The value of a JSON array index token: decimal without leading zeros (RFC 6901), at most `size` (which appends);
// "-" appends too. -1 when the token is neither.
int64_t arrayIndex(const std::string& token, size_t size) {
    if (token == "-") return static_cast<int64_t>(size);
    if (token.empty() || token.size() > 9 || (token.size() > 1 && token[0] == '0') ||
        !std::all_of(token.begin(), token.end(), [](char c) { return c >= '0' && c <= '9'; }))
        return -1;
    int64_t index = std::stoll(token);
    return index <= static_cast<int64_t>(size) ? index : -1;
}

} // namespace

void applySet(nlohmann::json& doc, const std::string& assignment) {
    auto eq = assignment.find('=');
    if (eq == std::string::npos || eq == 0)
        throw UserError("--set " + assignment + ": expected KEY=VALUE, e.g. tonemap.params.exposure=1.5");
    try {
        (void)nlohmann::json(assignment).dump();
    } catch (const nlohmann::json::type_error&) {
        throw UserError("--set: the assignment is not valid UTF-8 text");
    }
    std::string key = assignment.substr(0, eq);
    std::string text = assignment.substr(eq + 1);
    std::vector<std::string> parts;
    for (size_t start = 0;;) {
        size_t dot = key.find('.', start);
        parts.push_back(key.substr(start, dot - start));
        if (dot == std::string::npos) break;
        start = dot + 1;
    }
    if (std::any_of(parts.begin(), parts.end(), [](const auto& p) { return p.empty(); }))
        throw UserError("--set " + assignment + ": empty component in key '" + key + "'");
    if (parts[0] != "frame" && parts[0] != "outputs") parts.insert(parts.begin(), "nodes");
    if (parts[0] == "nodes" && !(doc.contains("nodes") && doc["nodes"].is_object() && doc["nodes"].contains(parts[1])))
        throw UserError("/nodes/" + pointerToken(parts[1]) + ": --set " + assignment + ": the graph has no node '" +
                        parts[1] + "'");

    nlohmann::json value;
    JsonTextError error;
    if (std::optional<nlohmann::json> parsed = parseJsonText(text, error))
        value = std::move(*parsed);
    else if (error.kind == JsonTextError::Kind::Syntax)
        value = text;
    else
        throw UserError("--set " + assignment + ": " + error.message);

    // Walked by hand rather than with a json_pointer, which throws its own exceptions when a number stands where
    // the key needs an object or an index is malformed.
    nlohmann::json* at = &doc;
    std::string pointer;
    for (const std::string& part : parts) {
        const std::string parent = pointer.empty() ? "/" : pointer;
        pointer += "/" + pointerToken(part);
        if (at->is_null()) *at = nlohmann::json::object();
        if (at->is_object()) {
            at = &(*at)[part];
        } else if (at->is_array()) {
            int64_t index = arrayIndex(part, at->size());
            if (index < 0)
                throw UserError(pointer + ": --set " + assignment + ": expected an array index in [0, " +
                                std::to_string(at->size()) + "] or '-' (the last two append)");
            if (static_cast<size_t>(index) == at->size()) at->push_back(nullptr);
            at = &(*at)[static_cast<size_t>(index)];
        } else {
            throw UserError(parent + ": --set " + assignment + ": cannot set '" + part + "' inside " + brief(*at) +
                            "; expected an object here");
        }
    }
    *at = std::move(value);
}

GraphDesc loadGraph(const fs::path& file, const std::vector<std::string>& sets) {
    nlohmann::json doc = loadGraphDocument(file, sets);
    GraphDesc desc = validateGraph(doc, file.string(), NodeRegistry::global());
    desc.directory = file.parent_path();
    return desc;
}

} // namespace vitrine
