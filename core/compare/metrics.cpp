#include "core/compare/metrics.hpp"

#include "core/compare/magma.hpp"
#include "core/compare/plane.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace vitrine::compare {

using detail::Kernel;
using detail::Plane;
using detail::PlaneD;

double psnr(const Image& a, const Image& b, double peak) {
    detail::requireSameSize(a, b, "psnr");
    double sumSquares = 0.0;
    for (size_t i = 0; i < a.pixels.size(); i += 4) {
        for (size_t c = 0; c < 3; ++c) {
            const double d = static_cast<double>(a.pixels[i + c]) - b.pixels[i + c];
            sumSquares += d * d;
        }
    }
    const double mse = sumSquares / (static_cast<double>(a.width) * a.height * 3.0);
    if (mse == 0.0) return std::numeric_limits<double>::infinity();
    return 10.0 * std::log10(peak * peak / mse);
}

namespace {

PlaneD clampedLuminance(const Image& image) {
    PlaneD y(image.width, image.height);
    for (int py = 0; py < image.height; ++py) {
        for (int px = 0; px < image.width; ++px) {
            const float* p = image.at(px, py);
            auto c = [](float v) { return std::isnan(v) ? 0.0 : std::clamp(static_cast<double>(v), 0.0, 1.0); };
            y(px, py) = 0.2126 * c(p[0]) + 0.7152 * c(p[1]) + 0.0722 * c(p[2]);
        }
    }
    return y;
}

Kernel ssimWindow() {
    constexpr int kRadius = 5; // 11 taps
    constexpr double kSigma = 1.5;
    Kernel w(2 * kRadius + 1);
    double sum = 0.0;
    for (int i = -kRadius; i <= kRadius; ++i)
        sum += std::exp(-(i * i) / (2.0 * kSigma * kSigma));
    for (int i = -kRadius; i <= kRadius; ++i)
        w[i + kRadius] = std::exp(-(i * i) / (2.0 * kSigma * kSigma)) / sum;
    return w;
}

PlaneD product(const PlaneD& a, const PlaneD& b) {
    PlaneD out(a.width, a.height);
    for (size_t i = 0; i < a.values.size(); ++i)
        out.values[i] = a.values[i] * b.values[i];
    return out;
}

} // namespace

SsimResult ssim(const Image& a, const Image& b) {
    detail::requireSameSize(a, b, "ssim");
    constexpr double kC1 = (0.01 * 1.0) * (0.01 * 1.0);
    constexpr double kC2 = (0.03 * 1.0) * (0.03 * 1.0);
    const Kernel window = ssimWindow();
    const PlaneD x = clampedLuminance(a);
    const PlaneD y = clampedLuminance(b);
    const PlaneD muX = detail::filterSeparable(x, window, window);
    const PlaneD muY = detail::filterSeparable(y, window, window);
    const PlaneD xx = detail::filterSeparable(product(x, x), window, window);
    const PlaneD yy = detail::filterSeparable(product(y, y), window, window);
    const PlaneD xy = detail::filterSeparable(product(x, y), window, window);

    Plane map(a.width, a.height);
    double sum = 0.0;
    for (size_t i = 0; i < map.values.size(); ++i) {
        const double mx = muX.values[i];
        const double my = muY.values[i];
        // Written so that x == y gives bit-identical numerator and denominator: SSIM(x, x) is exactly 1.
        const double sx = xx.values[i] - mx * mx;
        const double sy = yy.values[i] - my * my;
        const double sxy = xy.values[i] - mx * my;
        const double value =
            ((2.0 * mx * my + kC1) * (2.0 * sxy + kC2)) / ((mx * mx + my * my + kC1) * (sx + sy + kC2));
        map.values[i] = static_cast<float>(value);
        sum += value;
    }
    return SsimResult{sum / static_cast<double>(map.values.size()), detail::toScalarImage(map)};
}

Image flipColorMap(const Image& errorMap) {
    detail::requireNonEmpty(errorMap, "flipColorMap");
    Image out(errorMap.width, errorMap.height);
    for (int y = 0; y < errorMap.height; ++y) {
        for (int x = 0; x < errorMap.width; ++x) {
            const float e = errorMap.at(x, y)[0];
            const int index = std::isnan(e) ? 255 : static_cast<int>(std::lround(std::clamp(e, 0.0f, 1.0f) * 255.0f));
            const auto& linear = detail::magmaLinear(index);
            float* p = out.at(x, y);
            p[0] = linear[0];
            p[1] = linear[1];
            p[2] = linear[2];
            p[3] = 1.0f;
        }
    }
    return out;
}

Image absoluteDifference(const Image& a, const Image& b) {
    detail::requireSameSize(a, b, "absoluteDifference");
    Image out(a.width, a.height);
    for (size_t i = 0; i < a.pixels.size(); i += 4) {
        for (size_t c = 0; c < 3; ++c)
            out.pixels[i + c] = std::fabs(a.pixels[i + c] - b.pixels[i + c]);
        out.pixels[i + 3] = 1.0f;
    }
    return out;
}

Image falseColor(const Image& scalar, double scale) {
    detail::requireNonEmpty(scalar, "falseColor");
    Image values(scalar.width, scalar.height);
    for (size_t i = 0; i < scalar.pixels.size(); i += 4) {
        const float* p = &scalar.pixels[i];
        const bool broken = std::isnan(p[0]) || std::isnan(p[1]) || std::isnan(p[2]);
        const double v = broken ? 1.0 : std::max({p[0], p[1], p[2]}) * scale;
        values.pixels[i] = static_cast<float>(std::isnan(v) ? 1.0 : std::clamp(v, 0.0, 1.0));
    }
    return flipColorMap(values);
}

} // namespace vitrine::compare
