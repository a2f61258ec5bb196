#include "core/scene/aperture.hpp"

#include "shaders/camera/exposure.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace vitrine::scene {

ApertureShape apertureAt(uint32_t blades, float bladeRoundness, float rotation, float fNumber, float wideOpenFNumber) {
    const float stops = gpu_types::cameraStopsDown(fNumber, wideOpenFNumber);
    return {blades, gpu_types::cameraApertureRoundness(stops, bladeRoundness), rotation};
}

float apertureBoundary(const ApertureShape& shape, float theta) {
    if (shape.blades < 3) return 1.0f;
    const float wedge = 2.0f * std::numbers::pi_v<float> / static_cast<float>(shape.blades);
    float phi = std::fmod(theta - shape.rotation, wedge);
    if (phi < 0.0f) phi += wedge;
    const float polygon = std::cos(0.5f * wedge) / std::cos(phi - 0.5f * wedge);
    return polygon + shape.roundness * (1.0f - polygon);
}

bool insideAperture(const ApertureShape& shape, glm::vec2 p) {
    const float r = glm::length(p);
    return r <= 1.0f && r <= apertureBoundary(shape, std::atan2(p.y, p.x));
}

float apertureArea(const ApertureShape& shape) {
    const int steps = 4096;
    double sum = 0.0;
    for (int i = 0; i < steps; ++i) {
        const double r = apertureBoundary(shape, static_cast<float>(2.0 * std::numbers::pi * (i + 0.5) / steps));
        sum += 0.5 * r * r;
    }
    return static_cast<float>(sum * 2.0 * std::numbers::pi / steps);
}

glm::vec2 apertureSample(const ApertureShape& shape, uint32_t index) {
    // R2 (Roberts 2018): the plastic number's powers as the two irrational steps.
    const double g = 1.32471795724474602596;
    const double a1 = 1.0 / g, a2 = 1.0 / (g * g);
    uint32_t accepted = 0;
    for (uint64_t i = 0;; ++i) {
        const double x = std::fmod(0.5 + a1 * static_cast<double>(i), 1.0) * 2.0 - 1.0;
        const double y = std::fmod(0.5 + a2 * static_cast<double>(i), 1.0) * 2.0 - 1.0;
        const glm::vec2 p(static_cast<float>(x), static_cast<float>(y));
        if (!insideAperture(shape, p)) continue;
        if (accepted++ == index) return p;
    }
}

} // namespace vitrine::scene
