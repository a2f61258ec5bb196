#include "core/graph/types.hpp"

#include "core/gpu/formats.hpp"

namespace vitrine {

const char* toString(PortKind kind) {
    switch (kind) {
    case PortKind::Texture: return "texture";
    case PortKind::Buffer: return "buffer";
    case PortKind::Scene: return "scene";
    case PortKind::Camera: return "camera";
    }
    return "?";
}

const char* toString(ParamType type) {
    switch (type) {
    case ParamType::Bool: return "bool";
    case ParamType::Int: return "int";
    case ParamType::Float: return "float";
    case ParamType::Vec2: return "vec2";
    case ParamType::Vec3: return "vec3";
    case ParamType::Vec4: return "vec4";
    case ParamType::String: return "string";
    case ParamType::Enum: return "enum";
    case ParamType::Path: return "path";
    }
    return "?";
}

const InputPort* NodeSchema::findInput(const std::string& name) const {
    for (const auto& p : inputs)
        if (p.name == name) return &p;
    return nullptr;
}

const OutputPort* NodeSchema::findOutput(const std::string& name) const {
    for (const auto& p : outputs)
        if (p.name == name) return &p;
    return nullptr;
}

const ParamSpec* NodeSchema::findParam(const std::string& name) const {
    for (const auto& p : params)
        if (p.name == name) return &p;
    return nullptr;
}

namespace {

std::string describeRange(const ParamSpec& s) {
    if (s.min && s.max) return " in [" + nlohmann::json(*s.min).dump() + ", " + nlohmann::json(*s.max).dump() + "]";
    if (s.min) return " >= " + nlohmann::json(*s.min).dump();
    if (s.max) return " <= " + nlohmann::json(*s.max).dump();
    return "";
}

bool inRange(const ParamSpec& s, double v) { return (!s.min || v >= *s.min) && (!s.max || v <= *s.max); }

} // namespace

std::string checkParam(const ParamSpec& s, const nlohmann::json& v) {
    auto vector = [&](size_t n) -> std::string {
        std::string expected = "an array of " + std::to_string(n) + " numbers" + describeRange(s);
        if (!v.is_array() || v.size() != n) return expected;
        for (const auto& e : v)
            if (!e.is_number() || !inRange(s, e.get<double>())) return expected;
        return "";
    };
    switch (s.type) {
    case ParamType::Bool: return v.is_boolean() ? "" : "true or false";
    case ParamType::Int:
        if (!v.is_number_integer()) return "an integer" + describeRange(s);
        return inRange(s, v.get<double>()) ? "" : "an integer" + describeRange(s);
    case ParamType::Float:
        if (!v.is_number()) return "a number" + describeRange(s);
        return inRange(s, v.get<double>()) ? "" : "a number" + describeRange(s);
    case ParamType::Vec2: return vector(2);
    case ParamType::Vec3: return vector(3);
    case ParamType::Vec4: return vector(4);
    case ParamType::String:
    case ParamType::Path: return v.is_string() ? "" : "a string";
    case ParamType::Enum: {
        std::string list;
        for (const auto& c : s.choices) list += (list.empty() ? "" : ", ") + ("\"" + c + "\"");
        if (v.is_string())
            for (const auto& c : s.choices)
                if (v.get<std::string>() == c) return "";
        return "one of " + list;
    }
    }
    return "a valid value";
}

nlohmann::json NodeSchema::toJson() const {
    using nlohmann::json;
    auto formats = [](const std::vector<VkFormat>& fs) {
        json a = json::array();
        for (VkFormat f : fs) a.push_back(formatName(f));
        return a;
    };
    auto sizeJson = [](const SizeRule& r) -> json {
        switch (r.mode) {
        case SizeRule::Mode::Frame: return {{"relative", "frame"}, {"scale", r.scale}};
        case SizeRule::Mode::Input: return {{"relative", "input"}, {"input", r.input}, {"scale", r.scale}};
        case SizeRule::Mode::Absolute: return {{"absolute", {r.width, r.height}}};
        }
        return nullptr;
    };
    json j{{"type", type}, {"doc", doc}, {"pass", pass == PassKind::Compute ? "compute" : pass == PassKind::Raster ? "raster" : "transfer"}};
    j["inputs"] = json::array();
    for (const auto& p : inputs)
        j["inputs"].push_back({{"name", p.name}, {"kind", toString(p.kind)}, {"formats", formats(p.formats)},
                               {"optional", p.optional}, {"doc", p.doc}});
    j["outputs"] = json::array();
    for (const auto& p : outputs) {
        json o{{"name", p.name}, {"kind", toString(p.kind)}, {"doc", p.doc}, {"size", sizeJson(p.size)},
               {"persistent", p.persistent}};
        if (p.formatFrom.empty()) o["format"] = formatName(p.format);
        else o["formatFrom"] = p.formatFrom;
        j["outputs"].push_back(o);
    }
    j["params"] = json::array();
    for (const auto& p : params) {
        json o{{"name", p.name}, {"type", toString(p.type)}, {"default", p.defaultValue}, {"doc", p.doc}};
        if (p.min) o["min"] = *p.min;
        if (p.max) o["max"] = *p.max;
        if (!p.choices.empty()) o["choices"] = p.choices;
        j["params"].push_back(o);
    }
    return j;
}

} // namespace vitrine
