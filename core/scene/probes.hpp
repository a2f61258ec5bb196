#pragma once

// Reflection probes beyond their struct (scene.hpp): the influence volume as geometry, probe files, and how a
// file's probes combine with a scene's. The JSON form is VITRINE_reflection_probes.md's, the same in a glTF file
// (loadGltf / exportGlb) and in a probe file (the scene nodes' `probes` param).

#include "core/scene/scene.hpp"

#include <cstdint>
#include <filesystem>
#include <vector>

namespace vitrine::scene {

// Signed distance from p to the border of the probe's influence volume in metres, positive inside. For a box it
// is the smallest of the three distances to the pairs of faces (in the box's own axes), so the fade band runs
// parallel to each face; for a sphere it is radius − |p − center|.
float influenceDepth(const ReflectionProbe& probe, const glm::vec3& p);

// True when p lies inside the influence volume grown by `margin` metres (border included).
inline bool insideInfluence(const ReflectionProbe& probe, const glm::vec3& p, float margin = 0.0f) {
    return influenceDepth(probe, p) >= -margin;
}

// Signed distance from p to the border of the probe's parallax proxy (its projection box, else the influence
// volume), positive inside.
float projectionDepth(const ReflectionProbe& probe, const glm::vec3& p);

// The fade weight of scene.hpp in [0, 1]: 0 on and outside the border, ramping linearly to 1 at `fade` metres
// inside (a step at the border when fade is 0). A probe's blend weight is this times 16^priority. The CPU
// reference of what ibl.localized draws.
float fadeWeight(const ReflectionProbe& probe, const glm::vec3& p);

// How a probe file combines with the scene's probes (scene nodes' `probes_mode`).
enum class ProbeMerge : uint8_t {
    Merge,   // a file probe named like a scene probe replaces it in place; the others are appended
    Replace, // the file's probes replace all of the scene's (an empty list removes them)
};

// Reads a probe file, `{"probes": [...]}` (VITRINE_reflection_probes.md). UserError naming the file, the JSON
// pointer (`/probes/3/fade`) and what was expected.
std::vector<ReflectionProbe> readProbeFile(const std::filesystem::path& file);

// `into` after combining it with `probes` as `mode` says.
void applyProbes(std::vector<ReflectionProbe>& into, const std::vector<ReflectionProbe>& probes, ProbeMerge mode);

} // namespace vitrine::scene
