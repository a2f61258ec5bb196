#pragma once

// The museum's procedural textures. Each family is generated in one pass (one height field feeding
// albedo, data and normal map) and every texture tiles seamlessly unless noted. Data textures pack
// several scalar channels; the channel assignments below are what the museum's materials read.

#include "core/scene/museum/noise.hpp"
#include "core/scene/museum.hpp"
#include "core/scene/scene.hpp"

#include <cstdint>

namespace vitrine::scene::museum {

// Indices into Scene::textures.
struct MuseumTextures {
    // Polished marble, one tile = 1.5 m with 2 × 2 floor tiles. data: r shininess, g chequer mask (dark
    // tiles), b cavity (grout lines).
    int32_t marbleAlbedo = -1, marbleData = -1, marbleNormal = -1;
    // Sandstone without joints. data: r shininess, g ashlar-joint mask (blocks 1 × 0.5 of the tile, running
    // bond), b cavity (pits).
    int32_t stoneAlbedo = -1, stoneData = -1, stoneNormal = -1;
    // Walnut, grain along u. data: r intact-lacquer mask (0 where worn), g grain, b cavity (pores).
    int32_t woodAlbedo = -1, woodData = -1, woodNormal = -1;
    // Grime. data: r dirt mask (1 = dirty, gathers in crevices), g speckle, b cavity.
    int32_t dirt = -1;
    int32_t brushedNormal = -1; // streaks along u
    int32_t fineNormal = -1;    // engraved guilloché rosette over [0,1]² (clamped, not tiled): aliases
    int32_t clothAlbedo = -1, clothNormal = -1; // woven, 128 threads per tile
    int32_t plasterNormal = -1;
    int32_t paintings = -1; // four paintings in the quadrants of one image
};

// Generates the textures into `scene` (or loads them through options.loadTextures, storing fresh ones through
// storeTextures). `rng` advances the same way either way.
MuseumTextures makeTextures(Scene& scene, uint32_t size, Rng& rng, const MuseumOptions& options = {});

} // namespace vitrine::scene::museum
