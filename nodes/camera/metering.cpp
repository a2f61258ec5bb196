#include "nodes/camera/metering.hpp"

#include <algorithm>
#include <limits>

namespace vitrine::camera {

float histogramMeanLog2(std::span<const glm::vec2> bins, float low, float high) {
    double total = 0.0;
    for (const glm::vec2& b : bins) total += b.x;
    if (!(total > 0.0)) return std::numeric_limits<float>::quiet_NaN();
    const double lo = low * total, hi = high * total;
    double below = 0.0, weight = 0.0, sum = 0.0;
    for (const glm::vec2& b : bins) {
        if (b.x <= 0.0f) continue;
        const double from = std::max(below, lo), to = std::min(below + b.x, hi);
        if (to > from) {
            const double part = (to - from) / b.x;
            weight += part * b.x;
            sum += part * b.y;
        }
        below += b.x;
    }
    return weight > 0.0 ? static_cast<float>(sum / weight) : std::numeric_limits<float>::quiet_NaN();
}

} // namespace vitrine::camera
