#include "tools/vitrine/sweep/sweep_file.hpp"

#include "core/base/error.hpp"
#include "core/graph/loader.hpp"
#include "core/graph/registry.hpp"
#include "core/graph/types.hpp"

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <sstream>

namespace vitrine::sweep {

namespace fs = std::filesystem;

const std::vector<std::string> kMetricNames = {"flip", "ssim", "psnr", "flicker", "gpu_ms", "memory"};
const std::vector<std::string> kKeepNames = {"image", "reference", "diff", "flip", "report"};

std::string FrameSpec::text() const {
    if (graphDefault) return "";
    return temporal ? std::to_string(first) + ":" + std::to_string(last) : std::to_string(last);
}

namespace {

bool isIndex(const std::string& s) {
    return !s.empty() && s.size() <= 6 && std::all_of(s.begin(), s.end(), ::isdigit);
}

// Errors name the sweep file and a JSON pointer into it.
struct Checker {
    std::string file;
    [[noreturn]] void fail(const std::string& pointer, const std::string& message) const {
        throw UserError(file + ": " + (pointer.empty() ? "/" : pointer) + ": " + message);
    }
    void onlyKeys(const nlohmann::json& object, const std::string& pointer, const std::vector<std::string>& keys) const {
        for (const auto& [key, value] : object.items())
            if (std::find(keys.begin(), keys.end(), key) == keys.end()) {
                std::string list;
                for (const std::string& k : keys) list += (list.empty() ? "" : ", ") + k;
                fail(pointer + "/" + key, "unknown key; expected one of " + list);
            }
    }
    std::string string(const nlohmann::json& object, const std::string& key, const std::string& pointer) const {
        if (!object.contains(key)) fail(pointer, "missing \"" + key + "\"");
        if (!object[key].is_string() || object[key].get<std::string>().empty())
            fail(pointer + "/" + key, "expected a non-empty string, got " + object[key].dump());
        return object[key].get<std::string>();
    }
    fs::path existingFile(const nlohmann::json& value, const std::string& pointer, const fs::path& base,
                          const std::string& what) const {
        if (!value.is_string() || value.get<std::string>().empty())
            fail(pointer, "expected the path of " + what + " (relative to the sweep file), got " + value.dump());
        fs::path p = (base / value.get<std::string>()).lexically_normal();
        std::error_code ec;
        if (!fs::is_regular_file(p, ec)) fail(pointer, what + " " + p.string() + " not found");
        return p;
    }
};

// `KEY=...` of a --set axis or fixed set: frame.width / frame.height / frame.frames, or NODE.params.PARAM with NODE a
// node of the base graph and PARAM a param of its type.
void checkSetKey(const Checker& c, const std::string& key, const std::string& pointer, const nlohmann::json& base,
                 const fs::path& graph) {
    if (key == "frame.width" || key == "frame.height") return;
    const auto dot1 = key.find('.');
    const auto dot2 = dot1 == std::string::npos ? std::string::npos : key.find('.', dot1 + 1);
    const std::string expected = "expected NODE.params.PARAM (a node of " + graph.string() +
                                 ") or frame.width / frame.height, got '" + key + "'";
    if (dot2 == std::string::npos || key.substr(dot1 + 1, dot2 - dot1 - 1) != "params") c.fail(pointer, expected);
    const std::string node = key.substr(0, dot1), param = key.substr(dot2 + 1);
    if (param.empty() || param.find('.') != std::string::npos) c.fail(pointer, expected);
    const nlohmann::json& nodes = base.contains("nodes") ? base["nodes"] : nlohmann::json::object();
    if (!nodes.is_object() || !nodes.contains(node) || !nodes[node].is_object()) {
        std::string list;
        if (nodes.is_object())
            for (const auto& [id, n] : nodes.items()) if (n.is_object()) list += (list.empty() ? "" : ", ") + id;
        c.fail(pointer, "--set " + key + ": the base graph " + graph.string() + " has no node '" + node +
                            "'; it has " + list);
    }
    const nlohmann::json& decl = nodes[node];
    const std::string type = decl.contains("type") && decl["type"].is_string() ? decl["type"].get<std::string>() : "";
    const NodeSchema* schema = NodeRegistry::global().find(type);
    if (!schema) c.fail(pointer, "--set " + key + ": node '" + node + "' has unknown type '" + type + "'");
    if (!schema->findParam(param)) {
        std::string list;
        for (const ParamSpec& p : schema->params) list += (list.empty() ? "" : ", ") + p.name;
        c.fail(pointer, "--set " + key + ": node '" + node + "' (" + type + ") has no param '" + param +
                            "'; expected one of " + (list.empty() ? "(none)" : list));
    }
}

FrameSpec frameSpecOrFail(const Checker& c, const nlohmann::json& value, const std::string& pointer) {
    auto spec = parseFrameSpec(value);
    if (!spec) c.fail(pointer, "expected a frame index N or a range \"FIRST:LAST\" with FIRST < LAST, got " + value.dump());
    return *spec;
}

std::string valueText(const nlohmann::json& v) {
    return v.is_string() ? v.get<std::string>() : v.dump();
}

} // namespace

std::optional<FrameSpec> parseFrameSpec(const nlohmann::json& value) {
    FrameSpec s;
    s.graphDefault = false;
    if (value.is_number_unsigned()) {
        if (value.get<uint64_t>() > 99999) return std::nullopt;
        s.first = s.last = value.get<uint32_t>();
        return s;
    }
    if (!value.is_string()) return std::nullopt;
    const std::string text = value.get<std::string>();
    const auto colon = text.find(':');
    if (colon == std::string::npos) {
        if (!isIndex(text)) return std::nullopt;
        s.first = s.last = static_cast<uint32_t>(std::stoul(text));
        return s;
    }
    const std::string a = text.substr(0, colon), b = text.substr(colon + 1);
    if (!isIndex(a) || !isIndex(b)) return std::nullopt;
    s.first = static_cast<uint32_t>(std::stoul(a));
    s.last = static_cast<uint32_t>(std::stoul(b));
    if (s.first >= s.last) return std::nullopt;
    s.temporal = true;
    return s;
}

bool SweepFile::wants(const std::string& metric) const {
    return std::find(metrics.begin(), metrics.end(), metric) != metrics.end();
}

std::vector<std::string> SweepFile::sizeSets() const {
    std::vector<std::string> sets;
    if (width) sets.push_back("frame.width=" + std::to_string(width));
    if (height) sets.push_back("frame.height=" + std::to_string(height));
    return sets;
}

SweepFile parseSweepFile(const fs::path& path) {
    Checker c{path.string()};
    std::ifstream in(path);
    if (!in) throw UserError(path.string() + ": cannot read the sweep file");
    std::stringstream text;
    text << in.rdbuf();
    SweepFile s;
    s.file = path;
    try {
        s.document = nlohmann::json::parse(text.str());
    } catch (const nlohmann::json::parse_error& e) {
        throw UserError(path.string() + ": not valid JSON: " + e.what());
    }
    const nlohmann::json& d = s.document;
    if (!d.is_object()) c.fail("", "expected a JSON object (a vitrine-sweep/1 file)");
    c.onlyKeys(d, "", {"$schema", "format", "description", "graph", "reference", "output", "frame", "frames", "set",
                       "axes", "combine", "points", "metrics", "keep", "slurm"}); // "slurm": sweep/slurm.cpp
    if (!d.contains("format") || d["format"] != kFormat)
        c.fail("/format", std::string("expected \"") + kFormat + "\", got " +
                              (d.contains("format") ? d["format"].dump() : std::string("nothing")));
    if (d.contains("$schema") && !d["$schema"].is_string()) c.fail("/$schema", "expected a string");
    if (d.contains("description")) {
        if (!d["description"].is_string()) c.fail("/description", "expected a string");
        s.description = d["description"];
    }
    const fs::path base = path.parent_path();
    if (!d.contains("graph")) c.fail("", "missing \"graph\": the base graph (a path relative to the sweep file)");
    s.graph = c.existingFile(d["graph"], "/graph", base, "graph");
    if (d.contains("reference")) s.reference = c.existingFile(d["reference"], "/reference", base, "reference graph");
    if (d.contains("output")) s.output = c.string(d, "output", "");
    nlohmann::json graphDoc;
    try {
        graphDoc = loadGraphDocument(s.graph);
    } catch (const UserError& e) {
        c.fail("/graph", std::string("the base graph does not load: ") + e.what());
    }
    if (d.contains("frame")) {
        const nlohmann::json& f = d["frame"];
        if (!f.is_object()) c.fail("/frame", "expected {\"width\": W, \"height\": H}");
        c.onlyKeys(f, "/frame", {"width", "height"});
        for (const char* key : {"width", "height"}) {
            if (!f.contains(key)) continue;
            if (!f[key].is_number_unsigned() || f[key].get<uint64_t>() == 0 || f[key].get<uint64_t>() > 16384)
                c.fail(std::string("/frame/") + key, "expected a pixel count in [1, 16384], got " + f[key].dump());
            (std::string(key) == "width" ? s.width : s.height) = f[key].get<uint32_t>();
        }
    }
    if (d.contains("frames")) s.frames = frameSpecOrFail(c, d["frames"], "/frames");
    if (d.contains("set")) {
        if (!d["set"].is_object()) c.fail("/set", "expected an object {\"NODE.params.PARAM\": value, ...}");
        for (const auto& [key, value] : d["set"].items()) {
            checkSetKey(c, key, "/set/" + key, graphDoc, s.graph);
            s.sets.push_back(key + "=" + value.dump());
        }
    }

    if (d.contains("combine")) {
        if (d["combine"] != "product" && d["combine"] != "zip")
            c.fail("/combine", "expected \"product\" or \"zip\", got " + d["combine"].dump());
        s.zip = d["combine"] == "zip";
    }
    if (d.contains("axes") && !d["axes"].is_array()) c.fail("/axes", "expected an array of axes");
    std::set<std::string> names;
    const nlohmann::json axes = d.value("axes", nlohmann::json::array());
    for (size_t i = 0; i < axes.size(); ++i) {
        const std::string p = "/axes/" + std::to_string(i);
        const nlohmann::json& a = axes[i];
        if (!a.is_object()) c.fail(p, "expected an axis object {\"name\", and one of \"set\", \"variants\", \"frames\"}");
        c.onlyKeys(a, p, {"name", "set", "values", "variants", "frames"});
        Axis axis;
        const int kinds = a.contains("set") + a.contains("variants") + a.contains("frames");
        if (kinds != 1)
            c.fail(p, "expected exactly one axis kind: \"set\" (with \"values\"), \"variants\" or \"frames\"; got " +
                          std::to_string(kinds));
        std::string listKey;
        if (a.contains("set")) {
            axis.kind = AxisKind::Set;
            axis.key = c.string(a, "set", p);
            checkSetKey(c, axis.key, p + "/set", graphDoc, s.graph);
            listKey = "values";
            if (!a.contains("values")) c.fail(p, "missing \"values\": the values of " + axis.key);
        } else if (a.contains("variants")) {
            axis.kind = AxisKind::Variant;
            listKey = "variants";
            if (a.contains("values")) c.fail(p + "/values", "a variants axis lists its files in \"variants\"");
        } else {
            axis.kind = AxisKind::Frames;
            listKey = "frames";
            if (a.contains("values")) c.fail(p + "/values", "a frames axis lists its ranges in \"frames\"");
        }
        const nlohmann::json& list = a[listKey];
        if (!list.is_array() || list.empty()) c.fail(p + "/" + listKey, "expected a non-empty array");
        for (size_t v = 0; v < list.size(); ++v) {
            const std::string vp = p + "/" + listKey + "/" + std::to_string(v);
            axis.values.push_back(list[v]);
            if (axis.kind == AxisKind::Variant)
                axis.variantPaths.push_back(c.existingFile(list[v], vp, base, "variant file"));
            if (axis.kind == AxisKind::Frames) axis.frameSpecs.push_back(frameSpecOrFail(c, list[v], vp));
            if (axis.kind == AxisKind::Set && (list[v].is_object() || list[v].is_null()))
                c.fail(vp, "expected a number, string, boolean or array value for " + axis.key);
        }
        if (a.contains("name")) {
            axis.name = c.string(a, "name", p);
        } else {
            axis.name = axis.kind == AxisKind::Set ? axis.key.substr(axis.key.rfind('.') + 1)
                        : axis.kind == AxisKind::Variant ? "variant" : "frames";
        }
        if (!names.insert(axis.name).second)
            c.fail(p + "/name", "axis name '" + axis.name + "' is used twice; give each axis its own \"name\"");
        if (s.zip && !s.axes.empty() && axis.values.size() != s.axes[0].values.size())
            c.fail(p + "/" + listKey, "\"combine\": \"zip\" needs axes of equal length: /axes/0 has " +
                                          std::to_string(s.axes[0].values.size()) + " values, this one " +
                                          std::to_string(axis.values.size()));
        s.axes.push_back(std::move(axis));
    }
    if (d.contains("points")) {
        if (!d["points"].is_array()) c.fail("/points", "expected an array of points");
        for (size_t i = 0; i < d["points"].size(); ++i) {
            const std::string p = "/points/" + std::to_string(i);
            const nlohmann::json& e = d["points"][i];
            if (!e.is_object()) c.fail(p, "expected {\"variant\": FILE, \"set\": {KEY: VALUE}, \"frames\": RANGE}");
            c.onlyKeys(e, p, {"variant", "set", "frames"});
            Point point;
            point.graph = s.graph;
            std::vector<std::string> parts;
            if (e.contains("variant")) {
                point.graph = c.existingFile(e["variant"], p + "/variant", base, "variant file");
                parts.push_back("variant=" + point.graph.stem().string());
                point.values["variant"] = point.graph.stem().string();
            }
            if (e.contains("set")) {
                if (!e["set"].is_object()) c.fail(p + "/set", "expected an object {\"NODE.params.PARAM\": value}");
                for (const auto& [key, value] : e["set"].items()) {
                    checkSetKey(c, key, p + "/set/" + key, graphDoc, s.graph);
                    point.sets.push_back(key + "=" + value.dump());
                    const std::string shortName = key.substr(key.rfind('.') + 1);
                    parts.push_back(shortName + "=" + valueText(value));
                    point.values[shortName] = value;
                }
            }
            point.frames = s.frames;
            if (e.contains("frames")) {
                point.frames = frameSpecOrFail(c, e["frames"], p + "/frames");
                parts.push_back("frames=" + point.frames.text());
            }
            for (const std::string& part : parts) point.label += (point.label.empty() ? "" : ", ") + part;
            if (point.label.empty()) point.label = "base";
            s.extraPoints.push_back(std::move(point));
        }
    }
    if (s.axes.empty() && s.extraPoints.empty()) c.fail("/axes", "expected at least one axis or one of \"points\"");

    if (d.contains("metrics")) {
        if (!d["metrics"].is_array() || d["metrics"].empty()) c.fail("/metrics", "expected a non-empty array of metric names");
        for (size_t i = 0; i < d["metrics"].size(); ++i) {
            const nlohmann::json& m = d["metrics"][i];
            const std::string p = "/metrics/" + std::to_string(i);
            if (!m.is_string() || std::find(kMetricNames.begin(), kMetricNames.end(), m.get<std::string>()) == kMetricNames.end())
                c.fail(p, "expected one of flip, ssim, psnr, flicker, gpu_ms, memory; got " + m.dump());
            const std::string name = m;
            if ((name == "flip" || name == "ssim" || name == "psnr") && !s.reference)
                c.fail(p, "metric '" + name + "' compares with the reference: the sweep needs \"reference\"");
            if (!s.wants(name)) s.metrics.push_back(name);
        }
    } else {
        s.metrics = s.reference ? std::vector<std::string>{"flip", "ssim", "psnr", "gpu_ms", "memory"}
                                : std::vector<std::string>{"gpu_ms", "memory"};
        bool temporal = s.frames.temporal;
        for (const Axis& a : s.axes)
            for (const FrameSpec& f : a.frameSpecs) temporal = temporal || f.temporal;
        if (temporal) s.metrics.insert(s.metrics.begin() + (s.reference ? 3 : 0), "flicker");
    }
    if (d.contains("keep")) {
        if (!d["keep"].is_array()) c.fail("/keep", "expected an array of image names");
        for (size_t i = 0; i < d["keep"].size(); ++i) {
            const nlohmann::json& k = d["keep"][i];
            if (!k.is_string() || std::find(kKeepNames.begin(), kKeepNames.end(), k.get<std::string>()) == kKeepNames.end())
                c.fail("/keep/" + std::to_string(i), "expected one of image, reference, diff, flip, report; got " + k.dump());
            if (k != "image" && !s.reference)
                c.fail("/keep/" + std::to_string(i), "'" + k.get<std::string>() + "' needs a \"reference\"");
            s.keep.insert(k.get<std::string>());
        }
    } else {
        s.keep = s.reference ? std::set<std::string>{"image", "flip", "report"} : std::set<std::string>{"image"};
    }
    return s;
}

std::vector<Point> expandPoints(const SweepFile& s) {
    std::vector<Point> points;
    // Index tuples: product (first axis slowest) or zip.
    std::vector<std::vector<size_t>> tuples;
    if (!s.axes.empty()) {
        if (s.zip) {
            for (size_t i = 0; i < s.axes[0].values.size(); ++i) tuples.push_back(std::vector<size_t>(s.axes.size(), i));
        } else {
            tuples.push_back({});
            for (const Axis& a : s.axes) {
                std::vector<std::vector<size_t>> next;
                for (const auto& t : tuples)
                    for (size_t v = 0; v < a.values.size(); ++v) {
                        next.push_back(t);
                        next.back().push_back(v);
                    }
                tuples = std::move(next);
            }
        }
    }
    for (const auto& t : tuples) {
        Point p;
        p.graph = s.graph;
        p.frames = s.frames;
        for (size_t a = 0; a < s.axes.size(); ++a) {
            const Axis& axis = s.axes[a];
            const size_t v = t[a];
            std::string text;
            switch (axis.kind) {
            case AxisKind::Set:
                p.sets.push_back(axis.key + "=" + axis.values[v].dump());
                text = valueText(axis.values[v]);
                p.values[axis.name] = axis.values[v];
                break;
            case AxisKind::Variant:
                p.graph = axis.variantPaths[v];
                text = axis.variantPaths[v].stem().string();
                p.values[axis.name] = text;
                break;
            case AxisKind::Frames:
                p.frames = axis.frameSpecs[v];
                text = p.frames.text();
                p.values[axis.name] = text;
                break;
            }
            p.label += (p.label.empty() ? "" : ", ") + axis.name + "=" + text;
        }
        points.push_back(std::move(p));
    }
    for (const Point& extra : s.extraPoints) points.push_back(extra);
    for (size_t i = 0; i < points.size(); ++i) {
        char id[16];
        std::snprintf(id, sizeof id, "p%04zu", i);
        points[i].id = id;
        std::vector<std::string> sets = s.sizeSets();
        sets.insert(sets.end(), s.sets.begin(), s.sets.end());
        sets.insert(sets.end(), points[i].sets.begin(), points[i].sets.end());
        points[i].sets = std::move(sets);
    }
    return points;
}

const Point& findPoint(const std::vector<Point>& points, const std::string& idOrIndex) {
    for (const Point& p : points)
        if (p.id == idOrIndex) return p;
    if (isIndex(idOrIndex) && std::stoul(idOrIndex) < points.size()) return points[std::stoul(idOrIndex)];
    throw UserError("--point " + idOrIndex + ": no such point; expected an id p0000..p" +
                    (points.empty() ? std::string("0000") : points.back().id.substr(1)) + " or an index 0.." +
                    std::to_string(points.size() - 1));
}

} // namespace vitrine::sweep
