#include "core/graph/loader.hpp"

#include "core/base/error.hpp"
#include "core/graph/json_util.hpp"
#include "core/graph/registry.hpp"

#include <algorithm>

namespace vitrine {

namespace fs = std::filesystem;

namespace {

nlohmann::json loadWithBases(const fs::path& file, std::vector<fs::path>& chain) {
    fs::path canonical = fs::weakly_canonical(file);
    if (std::find(chain.begin(), chain.end(), canonical) != chain.end()) {
        std::string cycle;
        for (const auto& p : chain) cycle += p.filename().string() + " -> ";
        throw UserError(file.string() + ": /extends: `extends` forms a cycle: " + cycle + file.filename().string());
    }
    chain.push_back(canonical);
    nlohmann::json doc = readJsonFile(file);
    if (!doc.is_object()) throw UserError(file.string() + ": /: expected a JSON object (a vitrine graph)");
    auto it = doc.find("extends");
    if (it == doc.end()) return doc;
    if (!it->is_string()) throw UserError(file.string() + ": /extends: expected a path to the base graph, got " + brief(*it));
    fs::path base = file.parent_path() / it->get<std::string>();
    std::error_code ec;
    if (!fs::is_regular_file(base, ec))
        throw UserError(file.string() + ": /extends: base graph " + base.string() + " does not exist");
    nlohmann::json merged = loadWithBases(base, chain);
    doc.erase("extends");
    merged.merge_patch(doc);
    return merged;
}

} // namespace

nlohmann::json loadGraphDocument(const fs::path& file, const std::vector<std::string>& sets) {
    std::vector<fs::path> chain;
    nlohmann::json doc = loadWithBases(file, chain);
    for (const auto& s : sets) {
        try {
            applySet(doc, s);
        } catch (const UserError& e) {
            throw UserError(file.string() + ": " + e.what());
        }
    }
    return doc;
}

void applySet(nlohmann::json& doc, const std::string& assignment) {
    auto eq = assignment.find('=');
    if (eq == std::string::npos || eq == 0)
        throw UserError("--set " + assignment + ": expected KEY=VALUE, e.g. tonemap.params.exposure=1.5");
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
    std::string pointer;
    if (parts[0] != "frame" && parts[0] != "outputs") pointer = "/nodes";
    for (const auto& p : parts) pointer += "/" + pointerToken(p);
    nlohmann::json value = nlohmann::json::parse(text, nullptr, false);
    if (value.is_discarded()) value = text;
    nlohmann::json::json_pointer ptr(pointer);
    if (pointer.rfind("/nodes/", 0) == 0 && !doc.contains(nlohmann::json::json_pointer("/nodes/" + pointerToken(parts[0]))))
        throw UserError("/nodes/" + pointerToken(parts[0]) + ": --set " + assignment + ": the graph has no node '" +
                        parts[0] + "'");
    doc[ptr] = value;
}

GraphDesc loadGraph(const fs::path& file, const std::vector<std::string>& sets) {
    nlohmann::json doc = loadGraphDocument(file, sets);
    GraphDesc desc = validateGraph(doc, file.string(), NodeRegistry::global());
    desc.directory = file.parent_path();
    return desc;
}

} // namespace vitrine
