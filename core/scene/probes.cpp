// Reflection probes: influence-volume geometry, the JSON form (probe_json.hpp) and probe files.

#include "core/scene/probes.hpp"
#include "core/scene/probe_json.hpp"

#include "core/base/error.hpp"
#include "core/base/json_text.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <sstream>

namespace vitrine::scene {

namespace {

// Signed distance from p to the border of a box (centre, half extents, box -> world rotation), positive inside.
float boxDepth(const glm::vec3& center, const glm::vec3& halfExtents, const glm::quat& rotation, const glm::vec3& p) {
    glm::vec3 d = halfExtents - glm::abs(glm::conjugate(rotation) * (p - center));
    return std::min(std::min(d.x, d.y), d.z);
}

} // namespace

float influenceDepth(const ReflectionProbe& probe, const glm::vec3& p) {
    if (probe.shape == ProbeShape::Sphere) return probe.halfExtents.x - glm::length(p - probe.center);
    return boxDepth(probe.center, probe.halfExtents, probe.rotation, p);
}

float projectionDepth(const ReflectionProbe& probe, const glm::vec3& p) {
    if (!probe.hasProjection()) return influenceDepth(probe, p);
    return boxDepth(probe.projectionCenter, probe.projectionHalfExtents, probe.rotation, p);
}

float fadeWeight(const ReflectionProbe& probe, const glm::vec3& p) {
    float depth = influenceDepth(probe, p);
    if (probe.fade <= 0.0f) return depth >= 0.0f ? 1.0f : 0.0f;
    return std::clamp(depth / probe.fade, 0.0f, 1.0f);
}

void applyProbes(std::vector<ReflectionProbe>& into, const std::vector<ReflectionProbe>& probes, ProbeMerge mode) {
    if (mode == ProbeMerge::Replace) {
        into = probes;
        return;
    }
    for (const ReflectionProbe& p : probes) {
        auto same = std::find_if(into.begin(), into.end(), [&](const ReflectionProbe& q) {
            return !p.name.empty() && q.name == p.name;
        });
        if (same != into.end())
            *same = p;
        else
            into.push_back(p);
    }
}

namespace probejson {

namespace {

constexpr int32_t kMaxPriority = 8; // weights 16^±8 still fit a float with room for sums

// Short rendering of a value for messages; never throws on bad UTF-8.
std::string brief(const Json& v) {
    std::string s = v.dump(-1, ' ', false, Json::error_handler_t::replace);
    return s.size() > 60 ? s.substr(0, 57) + "..." : s;
}

std::string format(const glm::vec3& v) {
    char text[96];
    std::snprintf(text, sizeof text, "[%g, %g, %g]", double(v.x), double(v.y), double(v.z));
    return text;
}

class Reader {
public:
    Reader(const Where& where, const Json& obj, const std::string& at) : mWhere(where), mObj(obj), mAt(at) {}

    const Json* find(const char* key) const {
        auto it = mObj.find(key);
        return it == mObj.end() ? nullptr : &*it;
    }
    std::string at(const char* key) const { return mWhere.key(mAt, key); }
    [[noreturn]] void fail(const char* key, const std::string& what) const { mWhere.fail(at(key), what); }

    // A number >= 0 (or > 0 when `positive`).
    float distance(const char* key, float def, bool positive) const {
        const Json* v = find(key);
        if (!v) return def;
        float f = v->is_number() ? v->get<float>() : -1.0f;
        if (!std::isfinite(f) || f < 0.0f || (positive && f == 0.0f))
            fail(key, std::string("expected a number ") + (positive ? "> 0" : ">= 0") + " (metres), got " + brief(*v));
        return f;
    }
    // n finite numbers; `required` fails when absent, else def.
    glm::vec4 numbers(const char* key, int n, glm::vec4 def, bool required) const {
        const Json* v = find(key);
        if (!v) {
            if (required) fail(key, "missing; expected an array of " + std::to_string(n) + " numbers");
            return def;
        }
        if (!v->is_array() || v->size() != size_t(n))
            fail(key, "expected an array of " + std::to_string(n) + " numbers, got " + brief(*v));
        for (int i = 0; i < n; ++i) {
            const Json& x = (*v)[size_t(i)];
            if (!x.is_number() || !std::isfinite(x.get<float>()))
                fail(key, "expected an array of " + std::to_string(n) + " finite numbers, got " + brief(*v));
            def[i] = x.get<float>();
        }
        return def;
    }
    std::string string(const char* key, const std::string& def) const {
        const Json* v = find(key);
        if (!v) return def;
        if (!v->is_string()) fail(key, "expected a string, got " + brief(*v));
        return v->get<std::string>();
    }

private:
    const Where& mWhere;
    const Json& mObj;
    std::string mAt;
};

const char* const kKeys[] = {
    "name",     "position", "shape",    "center",           "halfExtents",           "radius",
    "rotation", "fade",     "priority", "projectionCenter", "projectionHalfExtents", "extensions",
    "extras"};

ReflectionProbe readProbe(const Json& j, const Where& where, const std::string& at) {
    if (!j.is_object()) where.fail(at, "expected a JSON object (a probe), got " + brief(j));
    for (const auto& item : j.items()) {
        if (std::find(std::begin(kKeys), std::end(kKeys), item.key()) == std::end(kKeys)) {
            where.fail(where.key(at, item.key()), "unknown key; expected name, position, shape, center, halfExtents "
                                                  "(box), radius (sphere), rotation (box), fade, priority, "
                                                  "projectionCenter, projectionHalfExtents (box)");
        }
    }
    Reader r(where, j, at);
    ReflectionProbe p;
    p.name = r.string("name", "");
    std::string shape = r.string("shape", "box");
    if (shape == "sphere")
        p.shape = ProbeShape::Sphere;
    else if (shape != "box")
        r.fail("shape", "'" + shape + "'; expected box or sphere");
    p.position = glm::vec3(r.numbers("position", 3, glm::vec4(0.0f), true));
    p.center = glm::vec3(r.numbers("center", 3, glm::vec4(p.position, 0.0f), false));
    if (p.shape == ProbeShape::Box) {
        if (r.find("radius")) r.fail("radius", "a box takes halfExtents; radius is for shape sphere");
        p.halfExtents = glm::vec3(r.numbers("halfExtents", 3, glm::vec4(0.0f), true));
        if (!(p.halfExtents.x > 0.0f && p.halfExtents.y > 0.0f && p.halfExtents.z > 0.0f))
            r.fail("halfExtents", "expected three numbers > 0, got " + brief(*r.find("halfExtents")));
        glm::vec4 q = r.numbers("rotation", 4, glm::vec4(0, 0, 0, 1), false);
        glm::quat rotation(q.w, q.x, q.y, q.z);
        float length = glm::length(rotation);
        if (!(std::abs(length - 1.0f) <= 1e-3f))
            r.fail("rotation", "expected a unit quaternion [x, y, z, w], got " + brief(*r.find("rotation")));
        // Unit quaternions written with float precision come back unchanged; only fix visible errors.
        p.rotation = std::abs(length - 1.0f) > 1e-6f ? rotation / length : rotation;
        if (r.find("projectionHalfExtents")) {
            p.projectionHalfExtents = glm::vec3(r.numbers("projectionHalfExtents", 3, glm::vec4(0.0f), true));
            if (!(p.projectionHalfExtents.x > 0.0f && p.projectionHalfExtents.y > 0.0f &&
                  p.projectionHalfExtents.z > 0.0f))
                r.fail("projectionHalfExtents",
                       "expected three numbers > 0, got " + brief(*r.find("projectionHalfExtents")));
            p.projectionCenter = glm::vec3(r.numbers("projectionCenter", 3, glm::vec4(p.center, 0.0f), false));
        } else if (r.find("projectionCenter")) {
            r.fail("projectionCenter", "given without projectionHalfExtents; expected both (the parallax proxy box) "
                                       "or neither (the influence volume is the proxy)");
        }
    } else {
        for (const char* key : {"projectionCenter", "projectionHalfExtents"})
            if (r.find(key)) r.fail(key, "a sphere's parallax proxy is the sphere; projection boxes are for shape box");
        if (r.find("halfExtents")) r.fail("halfExtents", "a sphere takes radius; halfExtents is for shape box");
        if (r.find("rotation")) r.fail("rotation", "a sphere has no rotation; rotation is for shape box");
        if (!r.find("radius")) r.fail("radius", "missing; expected the sphere's radius in metres (> 0)");
        p.halfExtents = glm::vec3(r.distance("radius", 0.0f, true));
    }
    p.fade = r.distance("fade", p.fade, false);
    if (const Json* v = r.find("priority")) {
        if (!v->is_number_integer() || v->get<int64_t>() < -kMaxPriority || v->get<int64_t>() > kMaxPriority) {
            r.fail("priority", "expected an integer in [" + std::to_string(-kMaxPriority) + ", " +
                                   std::to_string(kMaxPriority) + "], got " + brief(*v));
        }
        p.priority = static_cast<int32_t>(v->get<int64_t>());
    }
    // A millimetre of slack: a capture point written on the border must survive float rounding.
    if (!insideInfluence(p, p.position, 1e-3f)) {
        r.fail("position", "the capture point " + format(p.position) + " lies outside the influence volume (" +
                               std::to_string(-influenceDepth(p, p.position)) +
                               " m beyond its border); expected it inside: ibl.capture renders from it and the "
                               "parallax correction intersects the volume from it");
    }
    if (p.hasProjection() && projectionDepth(p, p.position) < -1e-3f) {
        r.fail("position", "the capture point " + format(p.position) + " lies outside the projection box (" +
                               std::to_string(-projectionDepth(p, p.position)) +
                               " m beyond its border); expected it inside: the parallax correction looks up the "
                               "cube from it towards where reflected rays leave that box");
    }
    return p;
}

} // namespace

std::string Where::key(const std::string& at, const std::string& key) const {
    if (!pointer) return at.empty() ? key : at + "." + key;
    std::string token;
    for (char c : key)
        token += c == '~' ? std::string("~0") : c == '/' ? std::string("~1") : std::string(1, c);
    return at + "/" + token;
}

std::string Where::index(const std::string& at, size_t i) const {
    return pointer ? at + "/" + std::to_string(i) : at + "[" + std::to_string(i) + "]";
}

void Where::fail(const std::string& at, const std::string& what) const {
    throw UserError(file + ": " + (at.empty() ? std::string("/") : at) + ": " + what);
}

std::vector<ReflectionProbe> read(const Json& list, const Where& where, const std::string& at) {
    if (!list.is_array()) where.fail(at, "expected an array of probes, got " + brief(list));
    std::vector<ReflectionProbe> probes;
    std::map<std::string, size_t> named;
    for (size_t i = 0; i < list.size(); ++i) {
        std::string e = where.index(at, i);
        probes.push_back(readProbe(list[i], where, e));
        const std::string& name = probes.back().name;
        if (name.empty()) continue;
        auto [it, fresh] = named.emplace(name, i);
        if (!fresh) {
            where.fail(where.key(e, "name"), "'" + name + "' is also the name of " + where.index(at, it->second) +
                                                 "; expected unique names (a probe file overrides probes by name)");
        }
    }
    return probes;
}

Json write(const std::vector<ReflectionProbe>& probes) {
    auto vec3 = [](const glm::vec3& v) { return Json::array({v.x, v.y, v.z}); };
    Json list = Json::array();
    for (const ReflectionProbe& p : probes) {
        Json j = Json::object();
        if (!p.name.empty()) j["name"] = p.name;
        j["position"] = vec3(p.position);
        j["shape"] = p.shape == ProbeShape::Sphere ? "sphere" : "box";
        j["center"] = vec3(p.center);
        if (p.shape == ProbeShape::Sphere) {
            j["radius"] = p.halfExtents.x;
        } else {
            j["halfExtents"] = vec3(p.halfExtents);
            j["rotation"] = Json::array({p.rotation.x, p.rotation.y, p.rotation.z, p.rotation.w});
            if (p.hasProjection()) {
                j["projectionCenter"] = vec3(p.projectionCenter);
                j["projectionHalfExtents"] = vec3(p.projectionHalfExtents);
            }
        }
        j["fade"] = p.fade;
        j["priority"] = p.priority;
        list.push_back(j);
    }
    return list;
}

} // namespace probejson

std::vector<ReflectionProbe> readProbeFile(const std::filesystem::path& file) {
    std::ifstream in(file, std::ios::binary);
    if (!in) throw UserError(file.string() + ": cannot open the probe file");
    std::stringstream text;
    text << in.rdbuf();
    JsonTextError error;
    std::optional<nlohmann::json> doc = parseJsonText(text.str(), error);
    if (!doc) {
        throw UserError(file.string() + ":" + std::to_string(error.line) + ":" + std::to_string(error.column) + ": " +
                        error.describe());
    }
    probejson::Where where{file.string(), true};
    if (!doc->is_object()) where.fail("", "expected a JSON object {\"probes\": [...]}, got " + probejson::brief(*doc));
    for (const auto& item : doc->items()) {
        if (item.key() != "probes") where.fail(where.key("", item.key()), "unknown key; expected probes");
    }
    auto list = doc->find("probes");
    if (list == doc->end()) where.fail("/probes", "missing; expected an array of probes");
    return probejson::read(*list, where, "/probes");
}

} // namespace vitrine::scene
