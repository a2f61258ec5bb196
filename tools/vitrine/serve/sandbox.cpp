#include "tools/vitrine/serve/sandbox.hpp"

#include "core/base/error.hpp"
#include "core/graph/json_util.hpp"
#include "core/graph/registry.hpp"

#include <algorithm>
#include <cctype>

namespace vitrine::serve {

namespace fs = std::filesystem;

namespace {

fs::path canonicalOf(const fs::path& path) {
    std::error_code ec;
    fs::path c = fs::weakly_canonical(path, ec);
    if (ec) throw PathRefused(path.string() + ": cannot resolve the path (" + ec.message() + ")");
    return c;
}

// glTF URIs are URI references: %XX escapes decode to bytes before they name a file (as tinygltf does).
std::string percentDecoded(const std::string& uri) {
    std::string out;
    for (size_t i = 0; i < uri.size(); ++i) {
        if (uri[i] == '%' && i + 2 < uri.size() && std::isxdigit(static_cast<unsigned char>(uri[i + 1])) &&
            std::isxdigit(static_cast<unsigned char>(uri[i + 2]))) {
            out += static_cast<char>(std::stoi(uri.substr(i + 1, 2), nullptr, 16));
            i += 2;
        } else {
            out += uri[i];
        }
    }
    return out;
}

std::string lower(std::string s) {
    std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::tolower(c); });
    return s;
}

} // namespace

bool isInside(const fs::path& root, const fs::path& path) {
    auto r = root.begin();
    auto c = path.begin();
    for (; r != root.end(); ++r, ++c)
        if (c == path.end() || *r != *c) return false;
    return true;
}

Sandbox::Sandbox(const fs::path& root) {
    std::error_code ec;
    if (!fs::is_directory(root, ec)) throw UserError(root.string() + ": not a directory (serve DIR)");
    mRoot = fs::canonical(root);
}

bool Sandbox::contains(const fs::path& path) const {
    return isInside(mRoot, canonicalOf(path));
}

fs::path Sandbox::resolve(const std::string& relative) const {
    const std::string shown = "'" + relative + "'";
    if (relative.empty()) throw PathRefused("empty path; expected a path relative to the served directory");
    if (relative.find('\0') != std::string::npos || relative.find('\\') != std::string::npos)
        throw PathRefused(shown + ": refused: NUL or backslash in the path");
    fs::path p(relative);
    if (p.is_absolute() || relative[0] == '/')
        throw PathRefused(shown + ": refused: absolute path; expected a path relative to the served directory");
    for (const fs::path& part : p)
        if (part == "..") throw PathRefused(shown + ": refused: '..' in the path");
    fs::path c = canonicalOf(mRoot / p);
    if (!isInside(mRoot, c))
        throw PathRefused(shown + ": refused: resolves (through a symbolic link) outside the served directory");
    return c;
}

std::string Sandbox::relative(const fs::path& canonical) const {
    return canonical.lexically_relative(mRoot).generic_string();
}

void Sandbox::checkExtends(const nlohmann::json& document, const fs::path& directory, const std::string& file) const {
    nlohmann::json doc = document;
    fs::path dir = directory;
    std::string where = file;
    // The loader itself refuses cycles; the bound only keeps this walk finite before it gets there.
    for (int depth = 0; depth < 64; ++depth) {
        if (!doc.is_object() || !doc.contains("extends") || !doc["extends"].is_string()) return;
        const std::string base = doc["extends"].get<std::string>();
        fs::path p(base);
        if (p.is_absolute())
            throw PathRefused(where + ": /extends: refused: an absolute path (vitrine serve reads files "
                                      "under the served directory only)");
        fs::path c = canonicalOf(dir / p);
        if (!isInside(mRoot, c))
            throw PathRefused(where + ": /extends: refused: '" + base + "' lies outside the served directory");
        std::error_code ec;
        if (!fs::is_regular_file(c, ec)) return; // the loader reports the missing base with its own message
        doc = readJsonFile(c);
        dir = c.parent_path();
        where = relative(c);
    }
}

void Sandbox::checkPathValue(const std::string& text, const fs::path& directory, const std::string& where) const {
    // Renderers open the value as it is (no URL decoding); an escaped dot or slash there is a probe, never a file.
    const std::string escaped = lower(text);
    for (const char* code : {"%2e", "%2f", "%5c"})
        if (escaped.find(code) != std::string::npos)
            throw PathRefused(where + ": refused: a percent-encoded '.', '/' or '\\' in the path; give a plain path "
                                      "relative to the graph file, under the served directory");
    fs::path p(text);
    if (p.is_absolute() || (!text.empty() && (text[0] == '/' || text[0] == '\\')))
        throw PathRefused(where + ": refused: an absolute path; vitrine serve reads files under the served "
                                  "directory only (give a path relative to the graph file)");
    for (const fs::path& part : p)
        if (part == "..") {
            // `..` may stay inside (a graph in graphs/ naming ../images/x.png): refused only when it leads out.
            if (!isInside(mRoot, canonicalOf(directory / p)))
                throw PathRefused(where + ": refused: '" + text + "' leads outside the served directory; " +
                                  "vitrine serve reads files under it only");
            break;
        }
    fs::path c = canonicalOf(directory / p);
    if (!isInside(mRoot, c))
        throw PathRefused(where + ": refused: '" + text +
                          "' lies outside the served directory (through a symbolic link); vitrine serve reads files "
                          "under it only");
    if (lower(c.extension().string()) == ".gltf") checkGltfUris(c, where);
}

void Sandbox::checkPathParams(const GraphDesc& desc) const {
    for (const NodeDecl& node : desc.nodes) {
        if (!node.schema) continue;
        for (const ParamSpec& spec : node.schema->params) {
            if (spec.type != ParamType::Path || !node.params.contains(spec.name)) continue;
            const nlohmann::json& value = node.params[spec.name];
            if (!value.is_string() || value.get<std::string>().empty()) continue;
            checkPathValue(value.get<std::string>(), desc.directory,
                           desc.where(node.pointer() + "/params/" + pointerToken(spec.name)));
        }
    }
}

void Sandbox::checkPathParams(const nlohmann::json& document, const fs::path& directory,
                              const std::string& file) const {
    if (!document.is_object() || !document.contains("nodes") || !document["nodes"].is_object()) return;
    for (const auto& [id, node] : document["nodes"].items()) {
        if (!node.is_object() || !node.contains("type") || !node["type"].is_string()) continue;
        if (!node.contains("params") || !node["params"].is_object()) continue;
        const NodeSchema* schema = NodeRegistry::global().find(node["type"].get<std::string>());
        if (!schema) continue; // validation reports the unknown type
        for (const ParamSpec& spec : schema->params) {
            if (spec.type != ParamType::Path || !node["params"].contains(spec.name)) continue;
            const nlohmann::json& value = node["params"][spec.name];
            if (!value.is_string() || value.get<std::string>().empty()) continue;
            checkPathValue(value.get<std::string>(), directory,
                           file + ": /nodes/" + pointerToken(id) + "/params/" + pointerToken(spec.name));
        }
    }
}

void Sandbox::checkGltfUris(const fs::path& gltf, const std::string& where) const {
    std::error_code ec;
    if (!fs::is_regular_file(gltf, ec)) return; // the scene node reports the missing file
    nlohmann::json doc;
    try {
        doc = readJsonFile(gltf);
    } catch (const UserError&) {
        return; // not JSON: the glTF loader reports it
    }
    for (const char* array : {"buffers", "images"}) {
        if (!doc.is_object() || !doc.contains(array) || !doc[array].is_array()) continue;
        for (size_t i = 0; i < doc[array].size(); ++i) {
            const nlohmann::json& item = doc[array][i];
            if (!item.is_object() || !item.contains("uri") || !item["uri"].is_string()) continue;
            const std::string uri = item["uri"].get<std::string>();
            if (uri.rfind("data:", 0) == 0) continue;
            const std::string decoded = percentDecoded(uri);
            const std::string at = where + ": " + relative(gltf) + ": /" + array + "/" + std::to_string(i) + "/uri";
            if (fs::path(decoded).is_absolute() || decoded.find("://") != std::string::npos)
                throw PathRefused(at + ": refused: '" + uri + "' is not a path relative to the glTF file");
            if (!isInside(mRoot, canonicalOf(gltf.parent_path() / decoded)))
                throw PathRefused(at + ": refused: '" + uri + "' lies outside the served directory");
        }
    }
}

} // namespace vitrine::serve
