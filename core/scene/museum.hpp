#pragma once

// `scene.museum`: the built-in procedural museum, made from code alone (no asset files) and deterministic
// from its seed. Built by the scene.museum node of the render graph and by tests.
//
// What it holds (metres, +Y up): a 32 × 14 × 9 m gallery hall with a polished chequered marble floor, an
// arcade of fluted columns and arches on each side, tall south windows with mullions and louvred
// skylights through which the sun falls in patches and shafts; three side galleries (west: sculpture,
// east: metals, north: paintings) through framed doorways; baseboards, cornices, framed procedural
// paintings, benches, thin railings; exhibits on pedestals that span the material space (mirror sphere,
// brushed steel, gold with a dirt layer, rough stone bust, draped cloth, lacquered wood, a finely
// engraved plate that aliases); a walking robot (dynamic, animated). Rooms are recorded as named boxes;
// 41 reflection probes (box influence volumes: 8 nave slices, 18 aisle bays, 3 doorways, 2 × 2 per gallery);
// camera paths "walkthrough", "dolly" and "static"; one sun.

#include "core/scene/scene.hpp"

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <vector>

namespace vitrine::scene {

// Bytes a store hands back: valid while keepAlive lives (a mapped cache file, say).
struct StoredBytes {
    std::span<const uint8_t> bytes;
    std::shared_ptr<const void> keepAlive;
};

struct MuseumOptions {
    // Changes the procedural textures, painting contents, small placement jitter and the robot's gait.
    uint64_t seed = 1;
    // Edge of every procedural texture in texels (power of two, 16..4096). 1024 matches the demo's
    // assets; tests use less where texture detail does not matter.
    uint32_t textureSize = 1024;
    // Optional store for the procedural textures, about 90 % of the build time: `key` hashes everything they
    // depend on (the seed's texture streams, the size, and the generator's source files: museumTextureSourceHash());
    // loadTextures returns the images stored under it, in order (or nothing: they are generated), storeTextures
    // keeps freshly generated ones. scene.museum wires both to the bake cache; without them nothing is stored.
    std::function<std::optional<std::vector<TextureImage>>(uint64_t key)> loadTextures;
    std::function<void(uint64_t key, const std::vector<TextureImage>&)> storeTextures;
    // Optional store for the generated geometry (vertices, indices, primitives, meshes, nodes, animations: the rest of
    // a build whose textures are stored), as bytes: `key` hashes the seed and the generator's source files
    // (museumGeometrySourceHash()). loadGeometry returns the stored bytes (or nothing: the geometry is built; bytes
    // that do not parse are ignored the same way), storeGeometry keeps those of a fresh build.
    std::function<std::optional<StoredBytes>(uint64_t key)> loadGeometry;
    std::function<void(uint64_t key, const std::vector<uint8_t>&)> storeGeometry;
};

// The default museum's geometry (seed 1: 134,335 vertices, 523,326 indices), which buildMuseum reserves up front:
// growing the vectors mesh by mesh copies them and touches fresh memory at every doubling (about 20 ms of a warm
// start's 130 ms build, measured 2026-12-05). A hint: another seed or an edit may need a little more, which then
// grows as before (test Museum.GeometryFitsTheReservedHint keeps it in step).
inline constexpr size_t kMuseumVertexReserve = 140000;
inline constexpr size_t kMuseumIndexReserve = 540000;

// A hash of the source files that generate the museum's textures (computed at build time): part of the texture
// cache key, so an edit to the generator never loads textures the old code made.
uint64_t museumTextureSourceHash();
// The same for the sources that generate the geometry (every file of core/scene/museum, the scene's structures and
// the store's format): part of the geometry cache key.
uint64_t museumGeometrySourceHash();
// The geometry cache key of a museum of this seed (what MuseumOptions::loadGeometry is called with).
uint64_t museumGeometryKey(uint64_t seed);

// The daylight the museum is lit by: graphs/museum.json's sky.procedural turbidity (Preetham). The scene's sun takes
// its colour and illuminance from the same model (shading::PreethamSky::sunIlluminance()), so the KHR_lights_punctual
// sun that export-scene writes is the sun the museum is rendered with (test GltfExport.MuseumSunIsTheSkyNodesSun).
inline constexpr double kMuseumSkyTurbidity = 2.5;

// UserError when an option is out of range. The result is finalized and valid.
Scene buildMuseum(const MuseumOptions& options = {});

} // namespace vitrine::scene
