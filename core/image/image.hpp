#pragma once

#include <cstddef>
#include <vector>

namespace vitrine {

// A CPU-side image: linear float RGBA, row-major, top row first. The exchange type between
// GPU read-back, file I/O, metrics and reports.
struct Image {
    int width = 0;
    int height = 0;
    std::vector<float> pixels; // width * height * 4

    Image() = default;
    Image(int w, int h) : width(w), height(h), pixels(static_cast<size_t>(w) * h * 4, 0.0f) {}

    float* at(int x, int y) { return &pixels[(static_cast<size_t>(y) * width + x) * 4]; }
    const float* at(int x, int y) const { return &pixels[(static_cast<size_t>(y) * width + x) * 4]; }
    bool empty() const { return width == 0 || height == 0; }
};

} // namespace vitrine
