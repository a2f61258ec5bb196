#pragma once

#include "core/image/image.hpp"

#include <cmath>
#include <cstdint>
#include <functional>

// Small deterministic test images for the compare tests.
namespace vitrine::compare::testing {

inline Image constantImage(int w, int h, float r, float g, float b, float a = 1.0f) {
    Image image(w, h);
    for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x) {
            float* p = image.at(x, y);
            p[0] = r;
            p[1] = g;
            p[2] = b;
            p[3] = a;
        }
    }
    return image;
}

// Hash noise in [-1, 1]: the same value for the same (x, y, seed) on every platform, unlike <random>'s distributions.
inline float hashNoise(int x, int y, uint32_t seed) {
    uint32_t h = static_cast<uint32_t>(x) * 374761393u + static_cast<uint32_t>(y) * 668265263u + seed * 2246822519u;
    h = (h ^ (h >> 13)) * 1274126177u;
    h ^= h >> 16;
    return static_cast<float>(h & 0xffffffu) / static_cast<float>(0xffffff) * 2.0f - 1.0f;
}

inline Image generate(int w, int h, const std::function<void(int, int, float*)>& pixel) {
    Image image(w, h);
    for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x) {
            float* p = image.at(x, y);
            p[3] = 1.0f;
            pixel(x, y, p);
        }
    }
    return image;
}

// A colourful, smoothly varying image with values inside (0.15, 0.85): room to add noise without clamping.
inline Image colourfulImage(int w, int h) {
    return generate(w, h, [](int x, int y, float* p) {
        p[0] = 0.5f + 0.35f * std::sin(0.21f * x + 0.05f * y);
        p[1] = 0.5f + 0.35f * std::cos(0.13f * y - 0.07f * x);
        p[2] = 0.5f + 0.35f * std::sin(0.09f * (x + y) + 1.0f);
    });
}

inline Image addNoise(const Image& base, float amplitude, uint32_t seed) {
    Image out = base;
    for (int y = 0; y < base.height; ++y)
        for (int x = 0; x < base.width; ++x)
            for (int c = 0; c < 3; ++c)
                out.at(x, y)[c] = base.at(x, y)[c] + amplitude * hashNoise(x, y, seed + c);
    return out;
}

} // namespace vitrine::compare::testing
