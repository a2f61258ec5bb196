#pragma once

// Small helpers for writing procedural textures: pixel loops, colour encoding, normal maps from heights.

#include "core/scene/material.hpp"
#include "core/scene/museum/noise.hpp"

#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace vitrine::scene::museum {

inline uint8_t toByte(float v) {
    return static_cast<uint8_t>(glm::clamp(v, 0.0f, 1.0f) * 255.0f + 0.5f);
}

// Linear → sRGB-encoded byte through a table: std::pow per channel per texel would dominate the
// generation time.
inline uint8_t toSrgbByte(float linear) {
    static const std::array<uint8_t, 4097> kTable = [] {
        std::array<uint8_t, 4097> t{};
        for (size_t i = 0; i < t.size(); ++i) {
            double c = double(i) / 4096.0;
            double s = c <= 0.0031308 ? 12.92 * c : 1.055 * std::pow(c, 1.0 / 2.4) - 0.055;
            t[i] = static_cast<uint8_t>(s * 255.0 + 0.5);
        }
        return t;
    }();
    return kTable[static_cast<size_t>(glm::clamp(linear, 0.0f, 1.0f) * 4096.0f + 0.5f)];
}

inline TextureImage blankImage(const std::string& name, uint32_t size) {
    TextureImage image;
    image.name = name;
    image.width = image.height = size;
    image.pixels.assign(size_t(size) * size * 4, 255);
    return image;
}

inline void putColor(TextureImage& image, size_t pixel, const glm::vec3& linear, float alpha = 1.0f) {
    uint8_t* p = &image.pixels[pixel * 4];
    p[0] = toSrgbByte(linear.r);
    p[1] = toSrgbByte(linear.g);
    p[2] = toSrgbByte(linear.b);
    p[3] = toByte(alpha);
}

inline void putData(TextureImage& image, size_t pixel, float r, float g, float b, float a = 1.0f) {
    uint8_t* p = &image.pixels[pixel * 4];
    p[0] = toByte(r);
    p[1] = toByte(g);
    p[2] = toByte(b);
    p[3] = toByte(a);
}

// A tangent-space normal map (glTF convention) from a height field in tile units (1 = the texture's
// width), by central differences; wrap for tiling textures, clamp at the border otherwise.
TextureImage normalMapFromHeight(const std::string& name, const std::vector<float>& height, uint32_t size, bool wrap);

// Four procedural paintings in the quadrants of one image (paintings.cpp): a mountain landscape (top
// left), a seascape at sunset (top right), a Mondrian-like composition (bottom left), circles after
// Kandinsky (bottom right).
TextureImage paintingAtlas(uint32_t size, Rng rng);

} // namespace vitrine::scene::museum
