// Phase 2 of the compiler: the JSON document -> GraphDesc, with every structural, type and
// reference error reported as "file: /json/pointer: what was expected".
#include "core/base/error.hpp"
#include "core/graph/json_util.hpp"
#include "core/graph/loader.hpp"
#include "core/graph/registry.hpp"

#include <regex>
#include <set>

namespace vitrine {

namespace {

using nlohmann::json;

class Validator {
public:
    Validator(const json& doc, const std::string& file, const NodeRegistry& registry,
              std::vector<std::string>* collect = nullptr)
        : mDoc(doc), mFile(file), mRegistry(registry), mCollect(collect) {}

    GraphDesc run() {
        GraphDesc g;
        g.file = mFile;
        g.document = mDoc;
        if (!mDoc.is_object()) fail("", "expected a JSON object (a vitrine graph)");
        static const std::set<std::string> kTop = {"$schema", "format", "description", "frame", "nodes", "outputs", "ui", "extends"};
        for (const auto& [key, value] : mDoc.items())
            attempt([&] {
                if (!kTop.count(key))
                    fail("/" + pointerToken(key), "unknown key; expected one of $schema, format, description, frame, nodes, outputs, ui");
            });
        attempt([&] {
            if (auto it = mDoc.find("format"); it != mDoc.end() && *it != "vitrine-graph/1")
                fail("/format", "expected \"vitrine-graph/1\", got " + brief(*it));
        });
        if (mDoc.contains("frame")) attempt([&] { g.frame = frame(mDoc["frame"]); });
        if (!mDoc.contains("nodes")) fail("/nodes", "missing; a graph needs an object of nodes keyed by id");
        const json& nodes = mDoc["nodes"];
        if (!nodes.is_object()) fail("/nodes", "expected an object keyed by node id, got " + brief(nodes));
        for (const auto& [id, value] : nodes.items())
            if (!attempt([&] { g.nodes.push_back(node(id, value)); })) mBroken.insert(id);
        for (auto& n : g.nodes) attempt([&] { inputs(g, n, nodes[n.id]); });
        attempt([&] { outputs(g); });
        return g;
    }

private:
    // Runs one independent check. Collecting (validateGraphErrors), its error is recorded and the checks after it
    // go on; otherwise it propagates. False when it failed.
    template <typename F>
    bool attempt(F&& check) const {
        if (!mCollect) {
            check();
            return true;
        }
        try {
            check();
            return true;
        } catch (const UserError& e) {
            mCollect->push_back(e.what());
            return false;
        } catch (const Skip&) {
            return false;
        }
    }

    [[noreturn]] void fail(const std::string& pointer, const std::string& message) const {
        throw UserError(mFile + ": " + (pointer.empty() ? "/" : pointer) + ": " + message);
    }

    uint32_t uintIn(const json& v, const std::string& ptr, uint32_t lo, uint32_t hi) const {
        if (!v.is_number_integer() || v.get<int64_t>() < lo || v.get<int64_t>() > hi)
            fail(ptr, "expected an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "], got " + brief(v));
        return v.get<uint32_t>();
    }

    FrameSettings frame(const json& f) const {
        FrameSettings s;
        if (!f.is_object()) fail("/frame", "expected an object {width, height, frames, write}, got " + brief(f));
        for (const auto& [key, value] : f.items()) {
            std::string ptr = "/frame/" + pointerToken(key);
            if (key == "width") s.width = uintIn(value, ptr, 1, 16384);
            else if (key == "height") s.height = uintIn(value, ptr, 1, 16384);
            else if (key == "frames") s.frames = uintIn(value, ptr, 1, 1000000);
            else if (key != "write") fail(ptr, "unknown key; expected width, height, frames or write");
        }
        if (auto it = f.find("write"); it != f.end()) {
            if (!it->is_array()) fail("/frame/write", "expected an array of frame indices, got " + brief(*it));
            for (size_t i = 0; i < it->size(); ++i)
                s.write.push_back(uintIn((*it)[i], "/frame/write/" + std::to_string(i), 0, s.frames - 1));
        }
        if (s.write.empty()) s.write.push_back(s.frames - 1);
        return s;
    }

    NodeDecl node(const std::string& id, const json& value) const {
        const std::string ptr = "/nodes/" + pointerToken(id);
        static const std::regex kId("[A-Za-z_][A-Za-z0-9_]*");
        if (!std::regex_match(id, kId)) fail(ptr, "node ids are letters, digits and '_', not starting with a digit");
        if (!value.is_object()) fail(ptr, "expected an object {type, params, in}, got " + brief(value));
        for (const auto& [key, v] : value.items())
            attempt([&] {
                if (key != "type" && key != "params" && key != "in" && key != "ui" && key != "doc")
                    fail(ptr + "/" + pointerToken(key), "unknown key; expected type, params, in, ui or doc");
            });
        auto type = value.find("type");
        if (type == value.end()) fail(ptr + "/type", "missing; every node needs a type (see `vitrine nodes`)");
        if (!type->is_string()) fail(ptr + "/type", "expected a node type name, got " + brief(*type));
        NodeDecl n;
        n.id = id;
        n.schema = mRegistry.find(type->get<std::string>());
        if (!n.schema) fail(ptr + "/type", "unknown node type \"" + type->get<std::string>() + "\"" + suggest(*type));
        n.params = json::object();
        const json* given = nullptr;
        if (auto p = value.find("params"); p != value.end()) {
            if (!p->is_object()) fail(ptr + "/params", "expected an object of params, got " + brief(*p));
            given = &*p;
            for (const auto& [key, v] : p->items())
                attempt([&] {
                    const ParamSpec* spec = n.schema->findParam(key);
                    std::string pptr = ptr + "/params/" + pointerToken(key);
                    if (!spec)
                        fail(pptr, "node type " + n.schema->type + " has no param '" + key + "'" + listParams(*n.schema));
                    std::string expected = checkParam(*spec, v);
                    if (!expected.empty()) fail(pptr, "expected " + expected + ", got " + brief(v));
                });
        }
        for (const auto& spec : n.schema->params)
            n.params[spec.name] = given && given->contains(spec.name) ? (*given)[spec.name] : spec.defaultValue;
        return n;
    }

    std::string suggest(const json& type) const {
        std::string t = type.get<std::string>(), best;
        for (const auto* s : mRegistry.all())
            if (!t.empty() && (s->type.find(t) != std::string::npos || t.find(s->type.substr(s->type.find('.') + 1)) != std::string::npos))
                best = s->type;
        return best.empty() ? "; `vitrine nodes` lists the types" : "; did you mean \"" + best + "\"?";
    }

    static std::string listParams(const NodeSchema& s) {
        std::string list;
        for (const auto& p : s.params) list += (list.empty() ? "" : ", ") + p.name;
        return list.empty() ? " (it takes none)" : " (it takes: " + list + ")";
    }

    PortRef parseRef(const json& v, const std::string& ptr, bool allowPrev) const {
        static const std::regex kRef(R"(([A-Za-z_][A-Za-z0-9_]*)\.([A-Za-z_][A-Za-z0-9_]*)(@prev)?)");
        std::smatch m;
        std::string text = v.is_string() ? v.get<std::string>() : "";
        if (!v.is_string() || !std::regex_match(text, m, kRef))
            fail(ptr, std::string("expected \"node.port\"") + (allowPrev ? " or \"node.port@prev\"" : "") + ", got " + brief(v));
        PortRef r{m[1], m[2], m[3].matched};
        if (r.previous && !allowPrev) fail(ptr, "a graph output cannot read last frame's value (@prev)");
        return r;
    }

    const OutputPort& resolve(const GraphDesc& g, const PortRef& r, const std::string& ptr) const {
        int idx = g.findNode(r.node);
        if (idx < 0 && mBroken.count(r.node)) throw Skip{}; // its own error is already recorded
        if (idx < 0) fail(ptr, "no node '" + r.node + "' in the graph (referenced as \"" + r.text() + "\")");
        const NodeSchema& s = *g.nodes[idx].schema;
        const OutputPort* out = s.findOutput(r.port);
        if (!out) {
            std::string list;
            for (const auto& o : s.outputs) list += (list.empty() ? "" : ", ") + o.name;
            fail(ptr, "node '" + r.node + "' (" + s.type + ") has no output '" + r.port + "'; its outputs: " + list);
        }
        return *out;
    }

    void inputs(GraphDesc& g, NodeDecl& n, const json& value) const {
        const std::string ptr = "/nodes/" + pointerToken(n.id) + "/in";
        if (auto in = value.find("in"); in != value.end()) {
            if (!in->is_object()) fail(ptr, "expected an object {port: \"node.port\"}, got " + brief(*in));
            for (const auto& [port, ref] : in->items()) attempt([&] {
                std::string pptr = ptr + "/" + pointerToken(port);
                const InputPort* ip = n.schema->findInput(port);
                if (!ip) {
                    std::string list;
                    for (const auto& i : n.schema->inputs) list += (list.empty() ? "" : ", ") + i.name;
                    fail(pptr, "node type " + n.schema->type + " has no input '" + port + "'" +
                                   (list.empty() ? " (it takes none)" : "; its inputs: " + list));
                }
                PortRef r = parseRef(ref, pptr, true);
                if (r.node == n.id && !r.previous)
                    fail(pptr, "node '" + n.id + "' reads its own output; use \"" + r.text() + "@prev\" for last frame's value");
                const OutputPort& out = resolve(g, r, pptr);
                if (out.kind != ip->kind)
                    fail(pptr, "input '" + port + "' takes a " + toString(ip->kind) + ", but " + r.text() + " is a " +
                                   toString(out.kind));
                if (r.previous && out.kind != PortKind::Texture)
                    fail(pptr, r.text() + ": only textures keep last frame's value; a " + toString(out.kind) +
                                   " is always the current frame's");
                n.inputs[port] = r;
            });
        }
        for (const auto& ip : n.schema->inputs)
            if (!ip.optional && !n.inputs.count(ip.name) && !(mCollect && value.contains("in") && value["in"].contains(ip.name)))
                attempt([&] { fail(ptr + "/" + pointerToken(ip.name), "missing required input '" + ip.name + "' (" + toString(ip.kind) +
                                                             ": " + ip.doc + ")"); });
    }

    void outputs(GraphDesc& g) const {
        auto it = mDoc.find("outputs");
        if (it == mDoc.end() || !it->is_object() || it->empty())
            fail("/outputs", "expected a non-empty object {name: \"node.port\"}; without outputs nothing is rendered");
        for (const auto& [name, ref] : it->items()) attempt([&] {
            std::string ptr = "/outputs/" + pointerToken(name);
            static const std::regex kName(R"([A-Za-z0-9_][A-Za-z0-9_./-]*)");
            if (!std::regex_match(name, kName) || name.find("..") != std::string::npos)
                fail(ptr, "output names are letters, digits, '_', '-', '.' and '/' (they become file names)");
            PortRef r = parseRef(ref, ptr, false);
            const OutputPort& out = resolve(g, r, ptr);
            if (out.kind != PortKind::Texture) fail(ptr, r.text() + " is a " + std::string(toString(out.kind)) + "; outputs must be textures");
            g.outputs.push_back({name, r});
        });
    }

    struct Skip {}; // a check that depends on a node whose declaration already failed (collecting only)

    const json& mDoc;
    std::string mFile;
    const NodeRegistry& mRegistry;
    std::vector<std::string>* mCollect;
    std::set<std::string> mBroken; // nodes whose declaration failed (collecting only)
};

} // namespace

int GraphDesc::findNode(const std::string& id) const {
    for (size_t i = 0; i < nodes.size(); ++i)
        if (nodes[i].id == id) return static_cast<int>(i);
    return -1;
}

GraphDesc validateGraph(const nlohmann::json& document, const std::string& file, const NodeRegistry& registry) {
    return Validator(document, file, registry).run();
}

std::vector<std::string> validateGraphErrors(const nlohmann::json& document, const std::string& file,
                                             const NodeRegistry& registry) {
    std::vector<std::string> errors;
    try {
        Validator(document, file, registry, &errors).run();
    } catch (const UserError& e) {
        errors.push_back(e.what()); // a structural error after which nothing else can be checked
    }
    return errors;
}

} // namespace vitrine
