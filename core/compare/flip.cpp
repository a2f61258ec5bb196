#include "core/compare/metrics.hpp"

#include "core/base/error.hpp"
#include "core/compare/flip_kernels.hpp"
#include "core/compare/plane.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <exception>
#include <numbers>
#include <string>
#include <thread>

// LDR-FLIP and HDR-FLIP as published (HPG 2020, EG 2021). Constant names follow the papers' symbols.
namespace vitrine::compare {

using detail::CsfTerm;
using detail::FlipKernels;
using detail::Plane;

namespace {

using Vec3 = std::array<double, 3>;

// Colour pipeline exponents and the error redistribution of the HPG 2020 paper (section 4.1).
constexpr double kQc = 0.7;
constexpr double kPc = 0.4;
constexpr double kPt = 0.95;
// Feature exponent (section 4.2).
constexpr double kQf = 0.5;

// Linear sRGB (Rec.709 primaries, D65) to CIE XYZ, written as the exact fractions of the sRGB definition.
constexpr double kRgbToXyz[3][3] = {
    {10135552.0 / 24577794.0, 8788810.0 / 24577794.0, 4435075.0 / 24577794.0},
    {2613072.0 / 12288897.0, 8788810.0 / 12288897.0, 887015.0 / 12288897.0},
    {1425312.0 / 73733382.0, 8788810.0 / 73733382.0, 70074185.0 / 73733382.0},
};

struct ColorMatrices {
    double xyzToRgb[3][3];
    Vec3 white; // XYZ of linear RGB (1,1,1): the D65 reference illuminant both Y CxCz and L*a*b* normalise by
};

const ColorMatrices& colorMatrices() {
    static const ColorMatrices kMatrices = [] {
        ColorMatrices m{};
        const auto& a = kRgbToXyz;
        const double det = a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) -
                           a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0]) +
                           a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]);
        for (int r = 0; r < 3; ++r) {
            for (int c = 0; c < 3; ++c) {
                // Inverse = transposed cofactors / determinant.
                const int r1 = (c + 1) % 3, r2 = (c + 2) % 3, c1 = (r + 1) % 3, c2 = (r + 2) % 3;
                m.xyzToRgb[r][c] = (a[r1][c1] * a[r2][c2] - a[r1][c2] * a[r2][c1]) / det;
            }
            m.white[r] = a[r][0] + a[r][1] + a[r][2];
        }
        return m;
    }();
    return kMatrices;
}

Vec3 rgbToXyz(const Vec3& rgb) {
    Vec3 xyz{};
    for (int r = 0; r < 3; ++r)
        xyz[r] = kRgbToXyz[r][0] * rgb[0] + kRgbToXyz[r][1] * rgb[1] + kRgbToXyz[r][2] * rgb[2];
    return xyz;
}

Vec3 xyzToYcxcz(const Vec3& xyz) {
    const Vec3& w = colorMatrices().white;
    const double x = xyz[0] / w[0], y = xyz[1] / w[1], z = xyz[2] / w[2];
    return {116.0 * y - 16.0, 500.0 * (x - y), 200.0 * (y - z)};
}

Vec3 ycxczToLinearRgb(const Vec3& ycxcz) {
    const ColorMatrices& m = colorMatrices();
    const double y = (ycxcz[0] + 16.0) / 116.0;
    const Vec3 xyz = {(y + ycxcz[1] / 500.0) * m.white[0], y * m.white[1], (y - ycxcz[2] / 200.0) * m.white[2]};
    Vec3 rgb{};
    for (int r = 0; r < 3; ++r)
        rgb[r] = m.xyzToRgb[r][0] * xyz[0] + m.xyzToRgb[r][1] * xyz[1] + m.xyzToRgb[r][2] * xyz[2];
    return rgb;
}

// CIE L*a*b* followed by the Hunt adjustment (chroma scaled by 0.01·L*), which models that colour differences are
// harder to see in dark regions.
Vec3 linearRgbToHuntLab(const Vec3& rgb) {
    const Vec3 xyz = rgbToXyz(rgb);
    const Vec3& w = colorMatrices().white;
    constexpr double kDelta = 6.0 / 29.0;
    auto f = [&](double t) {
        return t > kDelta * kDelta * kDelta ? std::cbrt(t) : t / (3.0 * kDelta * kDelta) + 4.0 / 29.0;
    };
    const double fx = f(xyz[0] / w[0]), fy = f(xyz[1] / w[1]), fz = f(xyz[2] / w[2]);
    const double l = 116.0 * fy - 16.0;
    return {l, 0.01 * l * 500.0 * (fx - fy), 0.01 * l * 200.0 * (fy - fz)};
}

double hyab(const Vec3& a, const Vec3& b) {
    return std::fabs(a[0] - b[0]) + std::hypot(a[1] - b[1], a[2] - b[2]);
}

// The largest colour difference the paper considers, green against blue, raised to q_c; redistribution maps it to 1.
double maxColorDifference() {
    static const double kCmax =
        std::pow(hyab(linearRgbToHuntLab({0.0, 1.0, 0.0}), linearRgbToHuntLab({0.0, 0.0, 1.0})), kQc);
    return kCmax;
}

Plane csfFilter(const Plane& in, const std::vector<CsfTerm>& terms) {
    Plane out(in.width, in.height);
    for (const CsfTerm& term : terms) {
        const Plane filtered = detail::filterSeparable(in, term.kernel, term.kernel);
        for (size_t i = 0; i < out.values.size(); ++i)
            out.values[i] += static_cast<float>(term.weight * filtered.values[i]);
    }
    return out;
}

Plane magnitude(const Plane& x, const Plane& y) {
    Plane out(x.width, x.height);
    for (size_t i = 0; i < out.values.size(); ++i)
        out.values[i] = std::hypot(x.values[i], y.values[i]);
    return out;
}

// What LDR-FLIP needs of one image: its CSF-filtered Hunt-adjusted L*a*b* and its feature strengths.
struct Preprocessed {
    std::array<Plane, 3> lab;
    Plane edges;
    Plane points;
};

Preprocessed preprocess(const Image& image, const FlipKernels& k) {
    const int w = image.width, h = image.height;
    std::array<Plane, 3> opponent = {Plane(w, h), Plane(w, h), Plane(w, h)};
    Plane luminance(w, h); // Y / Y_white, what the feature detectors see
    for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x) {
            const float* p = image.at(x, y);
            auto c = [](float v) { return std::isnan(v) ? 0.0 : std::clamp(static_cast<double>(v), 0.0, 1.0); };
            const Vec3 ycxcz = xyzToYcxcz(rgbToXyz({c(p[0]), c(p[1]), c(p[2])}));
            for (int ch = 0; ch < 3; ++ch)
                opponent[ch](x, y) = static_cast<float>(ycxcz[ch]);
            luminance(x, y) = static_cast<float>((ycxcz[0] + 16.0) / 116.0);
        }
    }

    Preprocessed out;
    std::array<Plane, 3> filtered;
    for (int ch = 0; ch < 3; ++ch)
        filtered[ch] = csfFilter(opponent[ch], k.csf[ch]);
    out.lab = {Plane(w, h), Plane(w, h), Plane(w, h)};
    for (size_t i = 0; i < filtered[0].values.size(); ++i) {
        Vec3 rgb = ycxczToLinearRgb({filtered[0].values[i], filtered[1].values[i], filtered[2].values[i]});
        // Filtering can leave the RGB cube; the paper clamps back into it before measuring colour.
        for (double& v : rgb)
            v = std::clamp(v, 0.0, 1.0);
        const Vec3 lab = linearRgbToHuntLab(rgb);
        for (int ch = 0; ch < 3; ++ch)
            out.lab[ch].values[i] = static_cast<float>(lab[ch]);
    }

    const Plane rowsGauss = detail::filterRows(luminance, k.featureGauss);
    const Plane rowsEdge = detail::filterRows(luminance, k.edge);
    const Plane rowsPoint = detail::filterRows(luminance, k.point);
    out.edges = magnitude(detail::filterColumns(rowsEdge, k.featureGauss), detail::filterColumns(rowsGauss, k.edge));
    out.points = magnitude(detail::filterColumns(rowsPoint, k.featureGauss), detail::filterColumns(rowsGauss, k.point));
    return out;
}

Plane ldrFlipPlane(const Image& reference, const Image& test, const FlipKernels& k) {
    // The two images are independent until the final per-pixel step, so the reference is prepared on a second thread
    // (most of the time is these filters: about halves LDR-FLIP at 1080p on two cores).
    Preprocessed r;
    std::exception_ptr failure;
    std::thread worker([&] {
        try {
            r = preprocess(reference, k);
        } catch (...) {
            failure = std::current_exception();
        }
    });
    Preprocessed t;
    try {
        t = preprocess(test, k);
    } catch (...) {
        worker.join();
        throw;
    }
    worker.join();
    if (failure) std::rethrow_exception(failure);
    const double cmax = maxColorDifference();
    const double pccmax = kPc * cmax;
    Plane error(reference.width, reference.height);
    for (size_t i = 0; i < error.values.size(); ++i) {
        const double colour = std::pow(hyab({r.lab[0].values[i], r.lab[1].values[i], r.lab[2].values[i]},
                                            {t.lab[0].values[i], t.lab[1].values[i], t.lab[2].values[i]}),
                                       kQc);
        // Differences below p_c·c_max take [0, p_t] of the range, larger ones the compressed rest (p_t, 1].
        const double deltaC =
            colour < pccmax ? kPt / pccmax * colour : kPt + (colour - pccmax) / (cmax - pccmax) * (1.0 - kPt);
        const double feature = std::max(std::fabs(r.edges.values[i] - t.edges.values[i]),
                                        std::fabs(r.points.values[i] - t.points.values[i]));
        const double deltaF = std::pow(feature / std::numbers::sqrt2, kQf);
        // c_max is the largest difference the paper expects inside the RGB cube; the clamp only guards rounding.
        error.values[i] = static_cast<float>(std::clamp(std::pow(deltaC, 1.0 - deltaF), 0.0, 1.0));
    }
    return error;
}

void requirePositivePpd(double ppd, const std::string& what) {
    if (!(ppd > 0.0) || !std::isfinite(ppd))
        throw UserError(what + ": expected pixels per degree > 0, got " + std::to_string(ppd));
}

// The paper's fit of the ACES filmic curve (Narkowicz 2016) with its 0.6 pre-exposure folded into the constants.
constexpr double kAces[6] = {0.6 * 0.6 * 2.51, 0.6 * 0.03, 0.0, 0.6 * 0.6 * 2.43, 0.6 * 0.59, 0.14};

float toneMapAces(float value, double scale) {
    if (std::isnan(value) || value <= 0.0f) return 0.0f;
    const double x = scale * value;
    if (!std::isfinite(x)) return 1.0f;
    const double y = (kAces[0] * x * x + kAces[1] * x + kAces[2]) / (kAces[3] * x * x + kAces[4] * x + kAces[5]);
    return static_cast<float>(std::clamp(std::isfinite(y) ? y : 1.0, 0.0, 1.0));
}

// The input x at which the tone-mapped value is t: the positive root of (k0 − k3·t)x² + (k1 − k4·t)x + (k2 − k5·t).
double acesInverse(double t) {
    const double c0 = (kAces[1] - kAces[4] * t) / (kAces[0] - kAces[3] * t);
    const double c1 = (kAces[2] - kAces[5] * t) / (kAces[0] - kAces[3] * t);
    return -0.5 * c0 + std::sqrt(0.25 * c0 * c0 - c1);
}

double median(std::vector<double> values) {
    const size_t n = values.size();
    std::nth_element(values.begin(), values.begin() + n / 2, values.end());
    const double upper = values[n / 2];
    if (n % 2 == 1) return upper;
    return 0.5 * (upper + *std::max_element(values.begin(), values.begin() + n / 2));
}

// Start exposure: the reference's maximum luminance tone-maps to t_max = 0.85; stop exposure: its median does
// (t_min = 0.85), as in the EG 2021 paper.
std::array<double, 2> automaticExposures(const Image& reference) {
    constexpr double kT = 0.85;
    std::vector<double> luminance;
    luminance.reserve(static_cast<size_t>(reference.width) * reference.height);
    double maxY = 0.0;
    for (size_t i = 0; i < reference.pixels.size(); i += 4) {
        const float* p = &reference.pixels[i];
        auto c = [](float v) { return std::isfinite(v) ? std::max(0.0, static_cast<double>(v)) : 0.0; };
        const double y = 0.2126 * c(p[0]) + 0.7152 * c(p[1]) + 0.0722 * c(p[2]);
        luminance.push_back(y);
        maxY = std::max(maxY, y);
    }
    if (maxY == 0.0) return {0.0, 0.0};
    double medianY = median(luminance);
    if (medianY <= 0.0) {
        // More than half the reference is black, so the paper's log2(x / median) is infinite. We take the median of
        // the lit pixels instead, which keeps the exposure range finite and still covers the dark end.
        std::erase_if(luminance, [](double y) { return y <= 0.0; });
        medianY = median(luminance);
    }
    return {std::log2(acesInverse(kT) / maxY), std::log2(acesInverse(kT) / medianY)};
}

double weightedPercentile(const std::vector<float>& sorted, double sum, double p) {
    if (sum <= 0.0) return 0.0;
    double running = 0.0;
    for (float e : sorted) {
        running += e;
        if (running > p * sum) return e;
    }
    return sorted.back();
}

} // namespace

FlipResult summarizeFlip(Image errorMap) {
    detail::requireNonEmpty(errorMap, "summarizeFlip");
    std::vector<float> values;
    values.reserve(static_cast<size_t>(errorMap.width) * errorMap.height);
    double sum = 0.0;
    for (size_t i = 0; i < errorMap.pixels.size(); i += 4) {
        values.push_back(errorMap.pixels[i]);
        sum += errorMap.pixels[i];
    }
    std::sort(values.begin(), values.end());
    FlipResult result;
    result.mean = sum / static_cast<double>(values.size());
    result.minimum = values.front();
    result.maximum = values.back();
    result.q1 = weightedPercentile(values, sum, 0.25);
    result.weightedMedian = weightedPercentile(values, sum, 0.5);
    result.q3 = weightedPercentile(values, sum, 0.75);
    result.errorMap = std::move(errorMap);
    return result;
}

FlipResult ldrFlip(const Image& reference, const Image& test, double pixelsPerDegree) {
    detail::requireSameSize(reference, test, "ldrFlip");
    requirePositivePpd(pixelsPerDegree, "ldrFlip");
    const FlipKernels kernels = detail::makeKernels(pixelsPerDegree);
    return summarizeFlip(detail::toScalarImage(ldrFlipPlane(reference, test, kernels)));
}

HdrFlipResult hdrFlip(const Image& reference, const Image& test, const HdrFlipOptions& options) {
    detail::requireSameSize(reference, test, "hdrFlip");
    requirePositivePpd(options.pixelsPerDegree, "hdrFlip");
    if (options.exposureCount < 0)
        throw UserError("hdrFlip: expected an exposure count >= 0 (0 = automatic), got " +
                        std::to_string(options.exposureCount));
    double start = options.startExposure, stop = options.stopExposure;
    if (options.automaticExposures) {
        const std::array<double, 2> exposures = automaticExposures(reference);
        start = exposures[0];
        stop = exposures[1];
    } else if (!std::isfinite(start) || !std::isfinite(stop)) {
        throw UserError("hdrFlip: expected finite start and stop exposures, got " + std::to_string(start) + " and " +
                        std::to_string(stop));
    }
    const int count =
        options.exposureCount > 0 ? options.exposureCount : std::max(2, static_cast<int>(std::ceil(stop - start)));
    const double step = (stop - start) / std::max(count - 1, 1);

    const FlipKernels kernels = detail::makeKernels(options.pixelsPerDegree);
    const int w = reference.width, h = reference.height;
    Plane maxError(w, h, -1.0f);
    Plane exposureIndex(w, h);
    Image mappedReference(w, h), mappedTest(w, h);
    for (int i = 0; i < count; ++i) {
        const double scale = std::exp2(start + i * step);
        for (size_t p = 0; p < reference.pixels.size(); ++p) {
            mappedReference.pixels[p] = toneMapAces(reference.pixels[p], scale);
            mappedTest.pixels[p] = toneMapAces(test.pixels[p], scale);
        }
        const Plane error = ldrFlipPlane(mappedReference, mappedTest, kernels);
        for (size_t p = 0; p < error.values.size(); ++p) {
            // Strictly greater: ties keep the shortest exposure, as the paper's exposure map does.
            if (error.values[p] > maxError.values[p]) {
                maxError.values[p] = error.values[p];
                exposureIndex.values[p] = static_cast<float>(count > 1 ? static_cast<double>(i) / (count - 1) : 0.0);
            }
        }
    }

    HdrFlipResult result;
    static_cast<FlipResult&>(result) = summarizeFlip(detail::toScalarImage(maxError));
    result.exposureMap = detail::toScalarImage(exposureIndex);
    result.startExposure = start;
    result.stopExposure = stop;
    result.exposureCount = count;
    return result;
}

} // namespace vitrine::compare
