#pragma once
// Where each static instance's lightmap lives (MUSEUM_SPEC §3). A lightmapped primitive's Vertex::uv1 maps
// its surface into [0, 1]² (Primitive::lightmapUvs); every static instance of such a mesh gets a square
// region of one atlas texture, sized from the instance's world-space area so that texel density is about
// `texelsPerMeter` everywhere — or more, where the mesh's charts lie closer than `minChartGap` texels apart
// (Mesh::lightmapChartGap) — and placed with a gutter around it so that bilinear filtering and the bake's
// dilation never mix two instances (nor, by the chart gap, two charts of one instance). Dynamic instances and meshes
// without lightmap UVs get no region: they are lit by probes (the plan lists them with the reason).
//
// The plan is pure CPU data, deterministic for a scene and options: the bake node, the G-buffer (which
// maps uv1 through `scaleOffset`) and the bake cache key all derive it from the same inputs.

#include <glm/glm.hpp>

#include <cstdint>
#include <string>
#include <vector>

namespace vitrine::scene {
struct Scene;
}

namespace vitrine::bake {

struct LightmapAtlasOptions {
    float texelsPerMeter = 8.0f;
    uint32_t minSize = 8;     // texels per side of the smallest region
    uint32_t maxSize = 1024;  // ... and of the largest
    uint32_t gutter = 2;      // texels kept free on every side of a region
    // Texels between two charts of a region, at least, where the mesh says how far apart they are: a chart's border
    // texel and its dilated neighbour are the chart's own, and the next chart's dilation starts a texel further.
    float minChartGap = 3.0f;
    uint32_t atlasWidth = 2048;
};

struct LightmapRegion {
    uint32_t instance = 0; // Scene::instances
    uint32_t x = 0, y = 0; // top-left texel of the region (gutter excluded)
    uint32_t size = 0;     // texels per side
    // atlas uv = uv1 * scaleOffset.xy + scaleOffset.zw
    glm::vec4 scaleOffset{0.0f};
};

struct LightmapAtlas {
    uint32_t width = 0, height = 0;
    std::vector<LightmapRegion> regions;
    // -1 for instances without a region; else the index into `regions`.
    std::vector<int32_t> regionOfInstance;
    // Instances without a lightmap and why ("dynamic", "no lightmap UVs (TEXCOORD_1)").
    std::vector<std::pair<uint32_t, std::string>> skipped;
    // Instances whose charts stay closer than minChartGap texels because maxSize capped their region, with the gap
    // they got (texels): their charts' borders may take some of their neighbours' light.
    std::vector<std::pair<uint32_t, float>> narrowChartGaps;

    double coverage() const; // region texels / atlas texels
};

// UserError when the options are out of range (sizes of zero, a region wider than the atlas).
LightmapAtlas planLightmapAtlas(const scene::Scene& scene, const LightmapAtlasOptions& options = {});

} // namespace vitrine::bake
