#pragma once

#include "core/graph/types.hpp"

#include <filesystem>
#include <map>
#include <string>
#include <vector>

namespace vitrine {

struct NodeSchema;

// `node.port` or `node.port@prev` (last frame's value of a temporal output).
struct PortRef {
    std::string node;
    std::string port;
    bool previous = false;
    std::string text() const { return node + "." + port + (previous ? "@prev" : ""); }
};

struct NodeDecl {
    std::string id;
    const NodeSchema* schema = nullptr;
    nlohmann::json params;                 // every declared param, defaults filled in
    std::map<std::string, PortRef> inputs; // by input port name
    std::string pointer() const { return "/nodes/" + id; }
};

struct OutputDecl {
    std::string name;
    PortRef source;
};

struct FrameSettings {
    uint32_t width = 1920;
    uint32_t height = 1080;
    uint32_t frames = 1;
    std::vector<uint32_t> write; // frames whose outputs are written; default: the last
};

// A loaded and validated graph: the merged JSON document plus the typed view of it.
struct GraphDesc {
    std::string file;                // for error messages
    std::filesystem::path directory; // relative paths in params resolve from here
    nlohmann::json document;         // after `extends`, merge patches and --set
    FrameSettings frame;
    std::vector<NodeDecl> nodes;
    std::vector<OutputDecl> outputs;

    int findNode(const std::string& id) const;
    std::string where(const std::string& pointer) const { return file + ": " + pointer; }
};

} // namespace vitrine
