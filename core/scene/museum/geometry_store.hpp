#pragma once
// The museum's generated geometry to and from bytes for the bake cache (see geometry_store.cpp).
#include "core/scene/scene.hpp"

#include <cstdint>
#include <optional>
#include <span>
#include <vector>

namespace vitrine::scene::museum {

// The scene's vertices, indices, primitives, meshes, nodes and animations; nullopt for a scene with skins or morph
// targets (the museum has none).
std::optional<std::vector<uint8_t>> serializeGeometry(const Scene& scene);
// Replaces those arrays of `scene` with the stored ones; false (and `scene` unchanged) when the bytes do not parse
// back exactly (another format, truncated).
bool deserializeGeometry(std::span<const uint8_t> bytes, Scene& scene);

} // namespace vitrine::scene::museum
