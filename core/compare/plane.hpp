#pragma once

#include "core/image/image.hpp"

#include <cstddef>
#include <string>
#include <vector>

// Internal to core/compare: single-channel images and the separable filtering that SSIM and FLIP share.
namespace vitrine::compare::detail {

// Row-major, top row first. SSIM keeps its moments in double: σ² = E[x²] − μ² cancels badly in float and the
// constants it is compared with are only ~1e-4.
template <typename T> struct BasicPlane {
    int width = 0;
    int height = 0;
    std::vector<T> values;

    BasicPlane() = default;
    BasicPlane(int w, int h, T fill = T(0)) : width(w), height(h), values(static_cast<size_t>(w) * h, fill) {}

    T& operator()(int x, int y) { return values[static_cast<size_t>(y) * width + x]; }
    T operator()(int x, int y) const { return values[static_cast<size_t>(y) * width + x]; }
};

using Plane = BasicPlane<float>;
using PlaneD = BasicPlane<double>;
using Kernel = std::vector<double>; // odd length, centred

// Correlates every row (resp. column) with `kernel`, reading clamped-to-edge samples outside the image — OpenCV's
// BORDER_REPLICATE, which the FLIP reference code uses. Instantiated for float and double.
template <typename T> BasicPlane<T> filterRows(const BasicPlane<T>& in, const Kernel& kernel);
template <typename T> BasicPlane<T> filterColumns(const BasicPlane<T>& in, const Kernel& kernel);

template <typename T>
BasicPlane<T> filterSeparable(const BasicPlane<T>& in, const Kernel& rowKernel, const Kernel& columnKernel) {
    return filterColumns(filterRows(in, rowKernel), columnKernel);
}

// Throws UserError when the sizes differ or an image is empty; `what` names the operation in the message.
void requireSameSize(const Image& a, const Image& b, const std::string& what);
void requireNonEmpty(const Image& a, const std::string& what);

// An Image whose R, G and B hold `plane` and whose alpha is 1.
Image toScalarImage(const Plane& plane);

} // namespace vitrine::compare::detail
