#pragma once
// The CPU half of camera.physical's metering: the GPU histogram (shaders/camera/meter.h) -> one mean log2
// luminance, ignoring the darkest and brightest parts of the (weighted) histogram.

#include <glm/glm.hpp>

#include <span>

namespace vitrine::camera {

// bins[i] = (Σw, Σw·log2 Y) of the pixels in bin i. The mean of log2 Y over the weight between the fractions
// `low` and `high` of the total weight, bins ordered from dark to bright; a bin that straddles a bound counts in
// proportion. NaN when the histogram is empty.
float histogramMeanLog2(std::span<const glm::vec2> bins, float low, float high);

} // namespace vitrine::camera
