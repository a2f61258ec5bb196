#include "core/compare/plane.hpp"

#include "core/base/error.hpp"

#include <algorithm>

namespace vitrine::compare::detail {

template <typename T> BasicPlane<T> filterRows(const BasicPlane<T>& in, const Kernel& kernel) {
    const int radius = static_cast<int>(kernel.size()) / 2;
    BasicPlane<T> out(in.width, in.height);
    // One padded copy of the row keeps the inner loop free of bounds checks, and looping over taps outside pixels
    // lets the compiler vectorise it (a per-pixel sum over taps is a serial dependency chain).
    std::vector<double> padded(static_cast<size_t>(in.width) + 2 * radius);
    std::vector<double> sum(in.width);
    for (int y = 0; y < in.height; ++y) {
        const T* row = &in.values[static_cast<size_t>(y) * in.width];
        for (int i = 0; i < static_cast<int>(padded.size()); ++i)
            padded[i] = row[std::clamp(i - radius, 0, in.width - 1)];
        std::fill(sum.begin(), sum.end(), 0.0);
        for (size_t k = 0; k < kernel.size(); ++k) {
            const double w = kernel[k];
            const double* src = &padded[k];
            for (int x = 0; x < in.width; ++x)
                sum[x] += w * src[x];
        }
        T* dst = &out.values[static_cast<size_t>(y) * in.width];
        for (int x = 0; x < in.width; ++x)
            dst[x] = static_cast<T>(sum[x]);
    }
    return out;
}

template <typename T> BasicPlane<T> filterColumns(const BasicPlane<T>& in, const Kernel& kernel) {
    const int radius = static_cast<int>(kernel.size()) / 2;
    BasicPlane<T> out(in.width, in.height);
    // Accumulating whole rows walks memory in order, which matters far more than the extra double buffer.
    std::vector<double> sum(in.width);
    for (int y = 0; y < in.height; ++y) {
        std::fill(sum.begin(), sum.end(), 0.0);
        for (int k = 0; k < static_cast<int>(kernel.size()); ++k) {
            const int sy = std::clamp(y + k - radius, 0, in.height - 1);
            const T* src = &in.values[static_cast<size_t>(sy) * in.width];
            const double w = kernel[k];
            for (int x = 0; x < in.width; ++x)
                sum[x] += w * src[x];
        }
        T* dst = &out.values[static_cast<size_t>(y) * in.width];
        for (int x = 0; x < in.width; ++x)
            dst[x] = static_cast<T>(sum[x]);
    }
    return out;
}

template Plane filterRows(const Plane&, const Kernel&);
template PlaneD filterRows(const PlaneD&, const Kernel&);
template Plane filterColumns(const Plane&, const Kernel&);
template PlaneD filterColumns(const PlaneD&, const Kernel&);

void requireNonEmpty(const Image& a, const std::string& what) {
    if (a.empty() || a.pixels.size() != static_cast<size_t>(a.width) * a.height * 4)
        throw UserError(what + ": expected a non-empty RGBA image, got " + std::to_string(a.width) + "x" +
                        std::to_string(a.height) + " with " + std::to_string(a.pixels.size()) + " floats");
}

void requireSameSize(const Image& a, const Image& b, const std::string& what) {
    requireNonEmpty(a, what);
    requireNonEmpty(b, what);
    if (a.width != b.width || a.height != b.height)
        throw UserError(what + ": expected images of the same size, got " + std::to_string(a.width) + "x" +
                        std::to_string(a.height) + " and " + std::to_string(b.width) + "x" + std::to_string(b.height));
}

Image toScalarImage(const Plane& plane) {
    Image image(plane.width, plane.height);
    for (int y = 0; y < plane.height; ++y) {
        for (int x = 0; x < plane.width; ++x) {
            float* p = image.at(x, y);
            p[0] = p[1] = p[2] = plane(x, y);
            p[3] = 1.0f;
        }
    }
    return image;
}

} // namespace vitrine::compare::detail
