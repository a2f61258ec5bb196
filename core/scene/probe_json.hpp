#pragma once

// Internal to core/scene: the JSON form of reflection probes (VITRINE_reflection_probes.md), read by the glTF
// loader and probe files (probes.cpp), written by the glTF exporter. One reader for both, so that a probe means
// the same thing wherever it is written; only the way a place is named in messages differs.

#include "core/scene/scene.hpp"

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace vitrine::scene::probejson {

using Json = nlohmann::json;

// Names places in a document for messages: glTF element paths (`scenes[0].extensions.X.probes[2].fade`) or JSON
// pointers (`/probes/2/fade`).
struct Where {
    std::string file;
    bool pointer = false;

    std::string key(const std::string& at, const std::string& key) const;
    std::string index(const std::string& at, size_t i) const;
    // UserError "file: at: what".
    [[noreturn]] void fail(const std::string& at, const std::string& what) const;
};

// The probes of `list` (which sits at `at`), checked: types, ranges, unknown keys, a unit rotation, the capture
// point inside the influence volume, names unique. A sphere comes back with halfExtents (r, r, r) and no rotation.
std::vector<ReflectionProbe> read(const Json& list, const Where& where, const std::string& at);

// The array read() reads back to the same probes (every float exactly).
Json write(const std::vector<ReflectionProbe>& probes);

} // namespace vitrine::scene::probejson
