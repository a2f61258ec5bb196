#include "core/graph/json_schema.hpp"

#include "core/graph/registry.hpp"

namespace vitrine {

namespace {

using nlohmann::json;

// The same patterns validate.cpp enforces.
constexpr const char* kIdPattern = "^[A-Za-z_][A-Za-z0-9_]*$";
constexpr const char* kRefPattern = "^[A-Za-z_][A-Za-z0-9_]*\\.[A-Za-z_][A-Za-z0-9_]*(@prev)?$";
constexpr const char* kOutputRefPattern = "^[A-Za-z_][A-Za-z0-9_]*\\.[A-Za-z_][A-Za-z0-9_]*$";
constexpr const char* kOutputNamePattern = "^[A-Za-z0-9_][A-Za-z0-9_./-]*$";

json paramSchema(const ParamSpec& p) {
    json s;
    auto range = [&](json& target) {
        if (p.min) target["minimum"] = *p.min;
        if (p.max) target["maximum"] = *p.max;
    };
    switch (p.type) {
    case ParamType::Bool: s["type"] = "boolean"; break;
    case ParamType::Int:
        s["type"] = "integer";
        range(s);
        break;
    case ParamType::Float:
        s["type"] = "number";
        range(s);
        break;
    case ParamType::Vec2:
    case ParamType::Vec3:
    case ParamType::Vec4: {
        size_t n = p.type == ParamType::Vec2 ? 2 : p.type == ParamType::Vec3 ? 3 : 4;
        json item{{"type", "number"}};
        range(item);
        s = {{"type", "array"}, {"items", item}, {"minItems", n}, {"maxItems", n}};
        break;
    }
    case ParamType::String: s["type"] = "string"; break;
    case ParamType::Path: s["type"] = "string"; break;
    case ParamType::Enum: s["enum"] = p.choices; break;
    }
    s["description"] = p.doc + (p.type == ParamType::Path ? " (a path, relative to the working directory)" : "");
    s["default"] = p.defaultValue;
    return s;
}

// What one node type allows in `params` and `in`. `patch`: a variant's entry, where every value may also be
// null (a merge patch deletes it) and required inputs are not required.
json typeSchema(const NodeSchema& t, bool patch) {
    json params{{"type", "object"}, {"properties", json::object()}, {"additionalProperties", false}};
    for (const ParamSpec& p : t.params) {
        json ps = paramSchema(p);
        params["properties"][p.name] = patch ? json{{"anyOf", {ps, {{"type", "null"}}}}} : ps;
    }
    json in{{"type", "object"}, {"properties", json::object()}, {"additionalProperties", false}};
    json required = json::array();
    for (const InputPort& port : t.inputs) {
        json ref{{"type", "string"}, {"pattern", kRefPattern},
                 {"description", std::string(toString(port.kind)) + (port.optional ? " (optional)" : "") + ": " + port.doc}};
        in["properties"][port.name] = patch ? json{{"anyOf", {ref, {{"type", "null"}}}}} : ref;
        if (!port.optional) required.push_back(port.name);
    }
    if (!patch && !required.empty()) in["required"] = required;
    json s{{"description", t.doc}, {"properties", {{"params", params}, {"in", in}}}};
    if (!patch && !required.empty()) s["required"] = {"in"};
    if (patch) { // null deletes the whole block; `properties` only constrains objects, so no anyOf is needed
        s["properties"]["params"]["type"] = {"object", "null"};
        s["properties"]["in"]["type"] = {"object", "null"};
    }
    return s;
}

json nodeSchema(const NodeRegistry& registry, bool patch) {
    json types = json::array();
    json byType = json::array();
    for (const NodeSchema* t : registry.all()) {
        types.push_back(t->type);
        byType.push_back({{"if", {{"properties", {{"type", {{"const", t->type}}}}}, {"required", {"type"}}}},
                          {"then", typeSchema(*t, patch)}});
    }
    json s{{"type", patch ? json{"object", "null"} : json("object")},
           {"properties",
            {{"type", {{"enum", types}, {"description", "The node type (`vitrine nodes` lists them)"}}},
             {"params", {{"type", patch ? json{"object", "null"} : json("object")}}},
             {"in", {{"type", patch ? json{"object", "null"} : json("object")}}},
             {"ui", {{"description", "Editor state (positions); ignored by the renderer"}}},
             {"doc", {{"type", "string"}}}}},
           {"additionalProperties", false},
           {"allOf", byType}};
    if (!patch) s["required"] = {"type"};
    return s;
}

json frameSchema(bool patch) {
    auto maybeNull = [&](json s) { return patch ? json{{"anyOf", {s, {{"type", "null"}}}}} : s; };
    json frame{{"type", "object"},
               {"description", "Frame size, frame count and the frames whose outputs are written (default: the last)"},
               {"properties",
                {{"width", maybeNull({{"type", "integer"}, {"minimum", 1}, {"maximum", 16384}})},
                 {"height", maybeNull({{"type", "integer"}, {"minimum", 1}, {"maximum", 16384}})},
                 {"frames", maybeNull({{"type", "integer"}, {"minimum", 1}, {"maximum", 1000000}})},
                 {"write", maybeNull({{"type", "array"}, {"items", {{"type", "integer"}, {"minimum", 0}}}})}}},
               {"additionalProperties", false}};
    return frame;
}

json outputsSchema(bool patch) {
    json ref{{"type", "string"}, {"pattern", kOutputRefPattern}, {"description", "\"node.port\" of a texture output"}};
    return {{"type", "object"},
            {"propertyNames", {{"pattern", kOutputNamePattern}}},
            {"additionalProperties", patch ? json{{"anyOf", {ref, {{"type", "null"}}}}} : ref}};
}

} // namespace

json graphJsonSchema(const NodeRegistry& registry) {
    json nodesFull{{"type", "object"},
                   {"propertyNames", {{"pattern", kIdPattern}}},
                   {"additionalProperties", {{"$ref", "#/$defs/node"}}}};
    json nodesPatch{{"type", "object"},
                    {"propertyNames", {{"pattern", kIdPattern}}},
                    {"additionalProperties", {{"$ref", "#/$defs/nodePatch"}}}}; // an object or null
    json s;
    s["$schema"] = "https://json-schema.org/draft/2020-12/schema";
    s["title"] = "vitrine-graph/1";
    s["description"] = "A vitrine render graph (README: \"The graph format\"), or a variant of one (a file with "
                       "`extends`, applied to its base as a JSON Merge Patch). Generated by `vitrine schema`.";
    s["type"] = "object";
    s["properties"] = {
        {"$schema", {{"type", "string"}}},
        {"format", {{"const", "vitrine-graph/1"}}},
        {"description", {{"type", "string"}}},
        {"extends", {{"type", "string"}, {"description", "Path of the base graph, relative to this file"}}},
        {"frame", {{"$ref", "#/$defs/frame"}}},
        {"nodes", {{"type", "object"}}},
        {"outputs", {{"type", "object"}}},
        {"ui", {{"description", "Editor state; ignored by the renderer"}}},
    };
    s["additionalProperties"] = false;
    s["if"] = {{"required", {"extends"}}};
    s["then"] = {{"properties",
                  {{"nodes", nodesPatch}, {"outputs", outputsSchema(true)}, {"frame", {{"$ref", "#/$defs/framePatch"}}}}}};
    s["else"] = {{"required", {"nodes", "outputs"}},
                 {"properties", {{"nodes", nodesFull}, {"outputs", outputsSchema(false)}}}};
    s["$defs"] = {{"node", nodeSchema(registry, false)},
                  {"nodePatch", nodeSchema(registry, true)},
                  {"frame", frameSchema(false)},
                  {"framePatch", frameSchema(true)}};
    return s;
}

} // namespace vitrine
