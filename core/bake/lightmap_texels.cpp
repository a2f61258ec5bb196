#include "core/bake/lightmap_texels.hpp"

#include <algorithm>
#include <cmath>

namespace vitrine::bake {

namespace {
float luminanceOf(glm::vec3 c) { return 0.2126f * c.r + 0.7152f * c.g + 0.0722f * c.b; }
} // namespace

void filterLightmap(LightmapTexels& t, const LightmapFilterOptions& o) {
    // The B3-spline kernel of the à-trous transform, separable weights 1/16, 4/16, 6/16, 4/16, 1/16.
    static constexpr float kKernel[5] = {1.0f / 16, 4.0f / 16, 6.0f / 16, 4.0f / 16, 1.0f / 16};
    const float inv2Sigma2 = 1.0f / (2.0f * o.positionSigma * o.positionSigma);
    const bool guided = t.variance.size() == t.irradiance.size() && o.luminanceSigma > 0.0f;
    std::vector<glm::vec3> next(t.irradiance.size());
    std::vector<float> variance = guided ? t.variance : std::vector<float>{};
    std::vector<float> nextVariance(variance.size());
    for (int it = 0, step = 1; it < o.iterations; ++it, step *= 2) {
        const float reach = 6.0f * float(step) * o.texelSize, reach2 = reach * reach;
        // The noise estimate of a texel from few samples is itself noisy (0 where every sample happened to
        // agree): the luminance test uses its 3x3 mean over the region, as SVGF does.
        std::vector<float> blurred;
        if (guided) {
            blurred.assign(variance.size(), 0.0f);
            for (uint32_t y = 0; y < t.height; ++y)
                for (uint32_t x = 0; x < t.width; ++x) {
                    const size_t c = t.index(x, y);
                    if (t.region[c] < 0) continue;
                    float sum = 0.0f;
                    int n = 0;
                    for (int j = -1; j <= 1; ++j)
                        for (int i = -1; i <= 1; ++i) {
                            const int sx = int(x) + i, sy = int(y) + j;
                            if (sx < 0 || sy < 0 || sx >= int(t.width) || sy >= int(t.height)) continue;
                            const size_t s = t.index(uint32_t(sx), uint32_t(sy));
                            if (t.region[s] != t.region[c]) continue;
                            sum += variance[s];
                            ++n;
                        }
                    blurred[c] = sum / float(n);
                }
        }
        for (uint32_t y = 0; y < t.height; ++y)
            for (uint32_t x = 0; x < t.width; ++x) {
                const size_t c = t.index(x, y);
                next[c] = t.irradiance[c];
                if (guided) nextVariance[c] = variance[c];
                if (t.region[c] < 0) continue;
                const float lc = luminanceOf(t.irradiance[c]);
                glm::vec3 sum(0.0f);
                // kept: the weight the luminance test takes from neighbours, which stays with the centre texel.
                float weight = 0.0f, weight2Variance = 0.0f, kept = 0.0f;
                for (int j = -2; j <= 2; ++j)
                    for (int i = -2; i <= 2; ++i) {
                        const int sx = int(x) + i * step, sy = int(y) + j * step;
                        if (sx < 0 || sy < 0 || sx >= int(t.width) || sy >= int(t.height)) continue;
                        const size_t s = t.index(uint32_t(sx), uint32_t(sy));
                        if (t.region[s] != t.region[c]) continue;
                        const glm::vec3 d = t.position[s] - t.position[c];
                        if (o.texelSize > 0.0f && glm::dot(d, d) > reach2) continue;
                        const float plane = glm::dot(d, t.normal[c]);
                        const float wp = std::exp(-plane * plane * inv2Sigma2);
                        const float wn = std::pow(std::max(glm::dot(t.normal[s], t.normal[c]), 0.0f), o.normalPower);
                        const float k = kKernel[i + 2] * kKernel[j + 2] * wp * wn;
                        float wl = 1.0f;
                        if (guided) {
                            // The deviation the difference of the two texels may have from noise alone: both
                            // estimates' noise, so that the test is the same from either side.
                            const float noise =
                                o.luminanceSigma * std::sqrt(std::max(blurred[c], 0.0f) + std::max(blurred[s], 0.0f));
                            const float dl = std::abs(luminanceOf(t.irradiance[s]) - lc);
                            wl = std::exp(-dl / (noise + 1e-6f * (lc + 1.0f)));
                        }
                        // A neighbour the luminance test rejects gives its weight back to the centre rather than
                        // dropping it: the weights of a pair are then symmetric, and what a bright texel keeps from
                        // its dim neighbours is what they keep from it, so the filter moves light between texels
                        // without losing any (dropping the weight darkened the rare bright texels that carry the
                        // sun's light through an aperture and left their neighbours as they were).
                        sum += k * wl * t.irradiance[s];
                        weight += k;
                        kept += k * (1.0f - wl);
                        if (guided) weight2Variance += (k * wl) * (k * wl) * variance[s];
                    }
                sum += kept * t.irradiance[c];
                next[c] = sum / weight; // the centre's own weight is > 0, so weight > 0
                if (guided) {
                    // The centre's coefficient is its own kernel weight kc plus the weight kept for it.
                    const float kc = kKernel[2] * kKernel[2], centre = kc + kept;
                    weight2Variance += (centre * centre - kc * kc) * variance[c];
                    nextVariance[c] = weight2Variance / (weight * weight);
                }
            }
        t.irradiance.swap(next);
        if (guided) variance.swap(nextVariance);
    }
}

void dilateLightmap(LightmapTexels& t, int radius) {
    // Reads only covered texels and writes only uncovered ones, so one pass sees no value it wrote itself.
    std::vector<glm::vec3> value = t.irradiance;
    for (uint32_t y = 0; y < t.height; ++y)
        for (uint32_t x = 0; x < t.width; ++x) {
            const size_t c = t.index(x, y);
            if (t.region[c] >= 0) continue;
            for (int r = 1; r <= radius; ++r) {
                glm::vec3 sum(0.0f);
                int n = 0;
                for (int j = -r; j <= r; ++j)
                    for (int i = -r; i <= r; ++i) {
                        if (std::max(std::abs(i), std::abs(j)) != r) continue; // the ring at distance r only
                        const int sx = int(x) + i, sy = int(y) + j;
                        if (sx < 0 || sy < 0 || sx >= int(t.width) || sy >= int(t.height)) continue;
                        const size_t s = t.index(uint32_t(sx), uint32_t(sy));
                        if (t.region[s] < 0) continue;
                        sum += t.irradiance[s];
                        ++n;
                    }
                if (n > 0) {
                    value[c] = sum / float(n);
                    break;
                }
            }
        }
    t.irradiance.swap(value); // dilated texels keep region -1: coverage stays what was rasterised
}

} // namespace vitrine::bake
