#pragma once
// The lightmap's texel G-buffer: every lightmapped primitive of every static instance that has an atlas
// region (core/bake/lightmap_atlas.hpp) drawn at its lightmap UVs into that region, writing per texel the
// world position and normal the bake integrates irradiance at. Texels whose centre no triangle covers stay
// uncovered (region -1); the bake dilates into them afterwards.

#include "core/bake/lightmap_atlas.hpp"
#include "core/bake/lightmap_texels.hpp"

namespace vitrine {
class Context;
class GpuScene;
class ShaderCompiler;
} // namespace vitrine

namespace vitrine::bake {

// Draws with the scene's instance buffer as the GPU scene holds it (the caller has posed it with
// GpuScene::update) and reads the result back. Irradiance is left zero.
LightmapTexels rasterizeLightmapTexels(Context& ctx, ShaderCompiler& shaders, GpuScene& gpu,
                                       const scene::Scene& scene, const LightmapAtlas& atlas);

} // namespace vitrine::bake
