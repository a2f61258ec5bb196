#include "core/bake/lightmap_texels.hpp"

#include <algorithm>
#include <cmath>

namespace vitrine::bake {

void filterLightmap(LightmapTexels& t, const LightmapFilterOptions& o) {
    // The B3-spline kernel of the à-trous transform, separable weights 1/16, 4/16, 6/16, 4/16, 1/16.
    static constexpr float kKernel[5] = {1.0f / 16, 4.0f / 16, 6.0f / 16, 4.0f / 16, 1.0f / 16};
    const float inv2Sigma2 = 1.0f / (2.0f * o.positionSigma * o.positionSigma);
    std::vector<glm::vec3> next(t.irradiance.size());
    for (int it = 0, step = 1; it < o.iterations; ++it, step *= 2) {
        for (uint32_t y = 0; y < t.height; ++y)
            for (uint32_t x = 0; x < t.width; ++x) {
                const size_t c = t.index(x, y);
                next[c] = t.irradiance[c];
                if (t.region[c] < 0) continue;
                glm::vec3 sum(0.0f);
                float weight = 0.0f;
                for (int j = -2; j <= 2; ++j)
                    for (int i = -2; i <= 2; ++i) {
                        const int sx = int(x) + i * step, sy = int(y) + j * step;
                        if (sx < 0 || sy < 0 || sx >= int(t.width) || sy >= int(t.height)) continue;
                        const size_t s = t.index(uint32_t(sx), uint32_t(sy));
                        if (t.region[s] != t.region[c]) continue;
                        const glm::vec3 d = t.position[s] - t.position[c];
                        const float wp = std::exp(-glm::dot(d, d) * inv2Sigma2);
                        const float wn = std::pow(std::max(glm::dot(t.normal[s], t.normal[c]), 0.0f), o.normalPower);
                        const float w = kKernel[i + 2] * kKernel[j + 2] * wp * wn;
                        sum += w * t.irradiance[s];
                        weight += w;
                    }
                next[c] = sum / weight; // the centre's own weight is > 0, so weight > 0
            }
        t.irradiance.swap(next);
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

uint32_t packRgb9e5(glm::vec3 rgb) {
    constexpr int kN = 9, kB = 15;
    constexpr float kMax = 511.0f / 512.0f * 65536.0f; // (2^N - 1) / 2^N * 2^(Emax - B)
    auto clampChannel = [&](float v) { return std::isnan(v) ? 0.0f : std::clamp(v, 0.0f, kMax); };
    const float r = clampChannel(rgb.r), g = clampChannel(rgb.g), b = clampChannel(rgb.b);
    const float maxC = std::max(r, std::max(g, b));
    int expPrime = (maxC > 0.0f ? std::max(-kB - 1, int(std::floor(std::log2(maxC)))) : -kB - 1) + 1 + kB;
    const float maxS = std::floor(maxC / std::ldexp(1.0f, expPrime - kB - kN) + 0.5f);
    const int expShared = maxS < float(1 << kN) ? expPrime : expPrime + 1;
    const float scale = std::ldexp(1.0f, expShared - kB - kN);
    auto mantissa = [&](float v) { return uint32_t(std::floor(v / scale + 0.5f)) & 0x1ffu; };
    return mantissa(r) | (mantissa(g) << 9) | (mantissa(b) << 18) | (uint32_t(expShared) << 27);
}

glm::vec3 unpackRgb9e5(uint32_t p) {
    const float scale = std::ldexp(1.0f, int(p >> 27) - 15 - 9);
    return glm::vec3(float(p & 0x1ffu), float((p >> 9) & 0x1ffu), float((p >> 18) & 0x1ffu)) * scale;
}

} // namespace vitrine::bake
