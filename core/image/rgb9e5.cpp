#include "core/image/rgb9e5.hpp"

#include <algorithm>
#include <cmath>

namespace vitrine {

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

} // namespace vitrine
