#pragma once

#include "core/graph/graph_desc.hpp"

#include <filesystem>
#include <stdexcept>
#include <string>

// What `vitrine serve` may read and write: files under the served directory only. Every path a request names (graph
// files) and every file a served graph makes the renderer open (`extends` bases, `path` params: images, glTF and the
// files a .gltf names, HDRIs, LUTs, probe lists, lens data) is resolved with symlinks followed and refused unless it
// lies inside that directory, so that a graph cannot read files elsewhere through the server.
namespace vitrine::serve {

// A request that names a path outside the served directory (or a malformed one). The server answers 403 with what().
class PathRefused : public std::runtime_error {
public:
    explicit PathRefused(const std::string& message) : std::runtime_error(message) {}
};

class Sandbox {
public:
    // `root` must exist and be a directory; it is kept canonical (symlinks resolved).
    explicit Sandbox(const std::filesystem::path& root);

    const std::filesystem::path& root() const { return mRoot; }

    // A path from a URL or a request body, relative to the root: refused when empty, absolute, containing a `..`
    // component, a backslash or a NUL, or resolving (after symlinks) outside the root. Returns the canonical path.
    std::filesystem::path resolve(const std::string& relative) const;

    // True when `path` (any path; symlinks are followed as far as it exists) lies inside the root.
    bool contains(const std::filesystem::path& path) const;

    // The path of `canonical` (inside the root) relative to the root, with '/' separators.
    std::string relative(const std::filesystem::path& canonical) const;

    // The `extends` chain of a document read from `directory` (a graph file's directory, inside the root): every
    // base graph it names must lie inside the root. `file` names the document in errors.
    void checkExtends(const nlohmann::json& document, const std::filesystem::path& directory,
                      const std::string& file) const;

    // Every `path`-typed param of every node of a validated graph, resolved as the renderer resolves it (relative to
    // desc.directory), and the external buffers and images of a .gltf file it names: each must lie inside the root.
    // PathRefused names the graph file and the param's JSON pointer.
    void checkPathParams(const GraphDesc& desc) const;

    // The same for a graph document before it is validated (after `extends` and "set" are merged): every `path`
    // param it sets, on nodes of any known type, whatever else is wrong with the graph. `directory` is where its
    // relative paths resolve from; `file` names it in errors.
    void checkPathParams(const nlohmann::json& document, const std::filesystem::path& directory,
                         const std::string& file) const;

private:
    // One path param's value (`where`: "FILE: /nodes/ID/params/NAME"): refused when absolute, when it has a
    // percent-encoded '.', '/' or '\\', or when it resolves outside the root. Errors never echo an absolute path.
    void checkPathValue(const std::string& text, const std::filesystem::path& directory,
                        const std::string& where) const;
    void checkGltfUris(const std::filesystem::path& gltf, const std::string& where) const;

    std::filesystem::path mRoot;
};

// Whether `path` is `root` or below it, component by component (both already canonical: nothing is resolved here).
bool isInside(const std::filesystem::path& root, const std::filesystem::path& path);

} // namespace vitrine::serve
