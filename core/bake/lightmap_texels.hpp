#pragma once
// CPU passes over a baked lightmap atlas (MUSEUM_SPEC §3), run once per bake after the GPU integrator has
// written noisy irradiance per texel:
//   - an edge-aware filter that removes the remaining noise without blurring across geometry (à-trous
//     wavelet iterations whose weights compare the texels' world positions and normals, never reaching into
//     another region);
//   - dilation of every region into its gutter, so bilinear filtering at chart borders never reads black;
//   - shared-exponent packing to E5B9G9R9 (VK_FORMAT_E5B9G9R9_UFLOAT_PACK32, 4 bytes a texel), the compact
//     HDR format the lightmap is cached and sampled in.

#include "core/image/rgb9e5.hpp"

#include <glm/glm.hpp>

#include <cstdint>
#include <vector>

namespace vitrine::bake {

// One atlas of width x height texels. `region` is -1 where no surface was rasterised (gutters, empty
// space), else the index of the region (LightmapAtlas::regions) the texel belongs to.
struct LightmapTexels {
    uint32_t width = 0, height = 0;
    std::vector<glm::vec3> irradiance; // lux (or any linear HDR quantity)
    std::vector<glm::vec3> position;   // world space, metres
    std::vector<glm::vec3> normal;     // unit
    std::vector<int32_t> region;
    // Variance of each texel's estimate of the mean luminance of its irradiance (from the bake's samples);
    // empty when unknown. With it, the filter also stops at differences the noise cannot explain.
    std::vector<float> variance;

    size_t index(uint32_t x, uint32_t y) const { return size_t(y) * width + x; }
};

struct LightmapFilterOptions {
    int iterations = 3;            // à-trous steps 1, 2, 4 ... texels
    float positionSigma = 0.25f;   // metres off the centre texel's tangent plane: texels farther than this barely mix
    float normalPower = 32.0f;     // weight = max(dot(n, n'), 0)^normalPower
    // With LightmapTexels::variance: taps whose luminance differs from the centre's by more than
    // luminanceSigma standard deviations of the difference (as the filter has reduced them) barely mix, so
    // real gradients (contact shadows, the edge of a sunlit patch) survive while noise is smoothed
    // [Schied et al. 2017, SVGF].
    float luminanceSigma = 3.0f;
    // World size of a texel (m); > 0: a tap farther from the centre than 6 x step x texelSize (a neighbour in
    // the atlas but not on the surface: across a chart seam) is left out. 0: no such limit.
    float texelSize = 0.0f;
};

// Edge-aware smoothing of `irradiance` over covered texels of the same region.
void filterLightmap(LightmapTexels& texels, const LightmapFilterOptions& options = {});

// Gives every uncovered texel within `radius` texels of a covered one the value of the nearest covered
// texel (Chebyshev rings, the nearest ring wins, ties averaged). Texels farther away stay as they are.
void dilateLightmap(LightmapTexels& texels, int radius);

// E5B9G9R9 packing (core/image/rgb9e5.hpp), the format the lightmap is cached and sampled in.
using vitrine::packRgb9e5;
using vitrine::unpackRgb9e5;

} // namespace vitrine::bake
