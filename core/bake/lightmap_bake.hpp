#pragma once
// The CPU half of bake.lightmap (MUSEUM_SPEC §3): what the GPU integrator (shaders/bake/lightmap.comp) is
// given to do, and what is made of its results.
//
// One bake lights two things with the same path tracer:
//   - every covered texel of the lightmap atlas (core/bake/lightmap_atlas.hpp, lightmap_raster.hpp):
//     irradiance E (lux) over the hemisphere of the texel's normal, from the sky, emissive surfaces and every
//     bounce of sun, sky and emitters, but WITHOUT the sun's direct light on the texel itself: the frame
//     draws that with its shadow maps (lighting.deferred), as the demo did;
//   - an irradiance volume for what has no lightmap (dynamic objects, meshes without TEXCOORD_1): a grid of
//     probes over the static scene, each the SH9 projection of the radiance arriving from every direction
//     (same light, the direct sun excluded too), evaluated with shIrradiance() at a normal.
// Surfaces reflect diffusely at bake time with their normal-incidence albedo (diffuse + F0 of the layered
// material at the hit, "albedo-only" as the demo baked with V-Ray), so the bake stays smooth and cheap.

#include "core/bake/cache.hpp"
#include "core/bake/lightmap_atlas.hpp"
#include "core/bake/lightmap_texels.hpp"

#include <glm/glm.hpp>

#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

namespace vitrine::scene {
struct Scene;
}

namespace vitrine::bake {

struct LightmapBakeSettings {
    LightmapAtlasOptions atlas;
    uint32_t samples = 64;    // paths per texel (and per probe ray)
    uint32_t maxBounces = 8;  // surfaces that reflect light along a path after the texel
    float probeSpacing = 2.0f; // metres between irradiance-volume probes
    uint32_t probeRays = 64;  // directions per probe
    uint32_t maxProbes = 4096; // the spacing grows when the scene would need more
    LightmapFilterOptions filter;
    float sunScale = 1.0f, skyScale = 1.0f, emissiveScale = 1.0f;
    // The paths' random sequence: 0 is the default; another value gives an independent bake of the same quality (two
    // seeds differ by the bake's noise). Dispatch d of seed s draws the sequence of index d + 65536 s.
    uint32_t seed = 0;
    // Texels over which a glossy surface's reflection of the sun (a caustic, e.g. off a polished floor onto the
    // ceiling) is spread: regularizedRoughness's footprint, 1 / atlas.texelsPerMeter metres per texel. 0: exact.
    float causticFootprint = 0.0f;
    float causticFootprintMeters() const { return causticFootprint / atlas.texelsPerMeter; }
    // The GGX lobe with its multiple-scattering compensation (common/brdf.glsl ggxMultiscatter) along the paths.
    bool multiscatter = false;
};

// A regular grid of probes: probe (x, y, z) sits at origin + spacing * (x, y, z).
struct IrradianceVolume {
    glm::vec3 origin{0.0f};
    float spacing = 1.0f;
    glm::uvec3 counts{0u};
    // Per probe 9 SH radiance coefficients (shaders/common/sh.glsl order); probe index x + cx (y + cy z).
    std::vector<std::array<glm::vec3, 9>> sh;
    // 1 for a probe that sees the scene from outside its geometry, 0 for one whose rays mostly hit back faces
    // (inside a wall): interpolation skips those.
    std::vector<float> validity;

    size_t probeCount() const { return size_t(counts.x) * counts.y * counts.z; }
    glm::vec3 position(uint32_t x, uint32_t y, uint32_t z) const { return origin + spacing * glm::vec3(x, y, z); }
};

// The grid over the bounds of the scene's static instances (empty when there are none).
IrradianceVolume planIrradianceVolume(const scene::Scene& scene, float spacing, uint32_t maxProbes);

// Ray `i` of `count` directions spread evenly over the sphere (spherical Fibonacci lattice).
glm::vec3 probeDirection(uint32_t i, uint32_t count);

// A probe's SH from the mean radiance along each of its probeDirection() rays; `backFaces` is the fraction
// of its rays whose first hit was a back face. Validity 0 when more than a quarter were.
void projectProbe(IrradianceVolume& volume, size_t probe, std::span<const glm::vec3> radiance, float backFaces);

// Work items of the GPU integrator: two vec4 per item. Texels: (position, 0), (normal, atlas index);
// probe rays: (probe position, 1), (direction, probe * rays + ray).
constexpr float kJobTexel = 0.0f, kJobProbeRay = 1.0f;
std::vector<glm::vec4> bakeJobs(const LightmapTexels& texels, const IrradianceVolume& volume, uint32_t probeRays,
                                size_t* texelJobs = nullptr);

// What a bake produces and the cache stores.
struct BakedLighting {
    uint32_t width = 0, height = 0;
    std::vector<uint32_t> lightmap; // E5B9G9R9, width x height
    IrradianceVolume volume;
    double bakeMs = 0.0;
};

std::vector<uint8_t> serializeBakedLighting(const BakedLighting& baked);
// nullopt when the bytes are not a whole, consistent BakedLighting of this format version.
std::optional<BakedLighting> deserializeBakedLighting(std::span<const uint8_t> bytes);

// Everything a bake depends on: the scene's content, the settings, and a hash of the lighting inputs (the
// sky cube map and the sun the bake was given).
BakeKey lightmapCacheKey(const scene::Scene& scene, const LightmapBakeSettings& settings, uint64_t lightingHash);

} // namespace vitrine::bake
