#include "core/compare/metrics.hpp"

#include "core/base/error.hpp"
#include "test_images.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <set>

namespace vitrine::compare {
namespace {

using testing::addNoise;
using testing::colourfulImage;
using testing::constantImage;
using testing::generate;

TEST(LdrFlip, IdenticalIsZeroEverywhere) {
    const Image a = addNoise(colourfulImage(64, 64), 0.1f, 5);
    const FlipResult r = ldrFlip(a, a);
    for (size_t i = 0; i < r.errorMap.pixels.size(); i += 4)
        ASSERT_EQ(r.errorMap.pixels[i], 0.0f);
    EXPECT_EQ(r.mean, 0.0);
    EXPECT_EQ(r.maximum, 0.0);
    EXPECT_EQ(r.weightedMedian, 0.0);
}

TEST(LdrFlip, GrowsWithNoiseAmplitude) {
    const Image reference = colourfulImage(64, 64);
    double previous = 0.0;
    for (float amplitude : {0.01f, 0.03f, 0.07f, 0.15f}) {
        const double mean = ldrFlip(reference, addNoise(reference, amplitude, 21)).mean;
        EXPECT_GT(mean, previous) << "amplitude " << amplitude;
        previous = mean;
    }
}

TEST(LdrFlip, GrowsWithColourShift) {
    const Image reference = colourfulImage(64, 64);
    double previous = 0.0;
    for (float shift : {0.02f, 0.05f, 0.1f, 0.2f, 0.4f}) {
        Image test = reference;
        for (size_t i = 0; i < test.pixels.size(); i += 4)
            test.pixels[i] += shift; // red only: a hue shift, clamped to 1 where it overflows
        const double mean = ldrFlip(reference, test).mean;
        EXPECT_GT(mean, previous) << "shift " << shift;
        previous = mean;
    }
}

// Mean error away from the border: clamp-to-edge padding (the paper's BORDER_REPLICATE) breaks a checker's zero
// mean within a filter radius of the border, and that radius grows with ppd, so border pixels would mix a second
// effect into the comparison. 24 px exceeds the widest radius used here (21 px for the CSF at 150 ppd).
double interiorMean(const Image& errorMap, int margin) {
    double sum = 0.0;
    int count = 0;
    for (int y = margin; y < errorMap.height - margin; ++y) {
        for (int x = margin; x < errorMap.width - margin; ++x) {
            sum += errorMap.at(x, y)[0];
            ++count;
        }
    }
    return sum / count;
}

TEST(LdrFlip, PixelCheckerIsLessVisibleAtHigherPixelsPerDegree) {
    // More pixels per degree (a denser display or a viewer farther away) makes a 1-pixel pattern finer than the
    // eye resolves, so the CSF filters and feature detectors, which widen in pixels with ppd, average it away.
    const Image grey = constantImage(96, 96, 0.5f, 0.5f, 0.5f);
    const Image checker =
        generate(96, 96, [](int x, int y, float* p) { p[0] = p[1] = p[2] = (x + y) % 2 ? 0.6f : 0.4f; });
    const double coarse = interiorMean(ldrFlip(grey, checker, 10.0).errorMap, 24);
    const double paper = interiorMean(ldrFlip(grey, checker, kDefaultPixelsPerDegree).errorMap, 24);
    const double fine = interiorMean(ldrFlip(grey, checker, 150.0).errorMap, 24);
    EXPECT_GT(coarse, paper);
    EXPECT_GT(paper, fine);
    EXPECT_GT(coarse, 0.1); // at 10 ppd a pixel spans 0.1°: clearly visible
}

// The colour pipeline on uniform images, worked by hand from the paper's formulas: uniform images stay uniform
// through the CSF filters and have no features (ΔE_f = 0), so FLIP = ΔE_c. The maximum difference c_max is that of
// green and blue, from the published CIELAB (D65) values of the sRGB primaries after the Hunt adjustment
// (a, b scaled by 0.01·L).
double expectedColourError(double hyabDistance) {
    const double greenL = 87.737, greenA = -86.185 * 0.01 * greenL, greenB = 83.181 * 0.01 * greenL;
    const double blueL = 32.303, blueA = 79.197 * 0.01 * blueL, blueB = -107.864 * 0.01 * blueL;
    const double cmax = std::pow(std::abs(greenL - blueL) + std::hypot(greenA - blueA, greenB - blueB), 0.7);
    const double e = std::pow(hyabDistance, 0.7);
    const double pccmax = 0.4 * cmax;
    return e < pccmax ? 0.95 / pccmax * e : 0.95 + (e - pccmax) / (cmax - pccmax) * 0.05;
}

// CIE L* of a relative luminance.
double lightness(double y) {
    return y > 216.0 / 24389.0 ? 116.0 * std::cbrt(y) - 16.0 : 24389.0 / 27.0 * y;
}

TEST(LdrFlip, BlackAgainstWhiteMatchesPaperFormula) {
    // L* 0 against 100, a = b = 0: HyAB = 100, beyond p_c·c_max, so ΔE_c lands in the compressed (0.95, 1] part.
    const FlipResult r = ldrFlip(constantImage(32, 32, 0, 0, 0), constantImage(32, 32, 1, 1, 1));
    EXPECT_NEAR(r.mean, expectedColourError(100.0), 1e-3);
    EXPECT_GT(r.mean, 0.95);
    EXPECT_LE(r.maximum, 1.0);
    EXPECT_NEAR(r.minimum, r.maximum, 1e-6); // uniform images: the same error everywhere
}

TEST(LdrFlip, UniformGreyPairMatchesPaperFormula) {
    // Greys have a = b = 0, so HyAB = |ΔL*|.
    for (const auto& [a, b] : {std::pair{0.5f, 0.25f}, std::pair{0.2f, 0.18f}, std::pair{0.9f, 0.05f}}) {
        const FlipResult r = ldrFlip(constantImage(32, 32, a, a, a), constantImage(32, 32, b, b, b));
        EXPECT_NEAR(r.mean, expectedColourError(std::abs(lightness(a) - lightness(b))), 1e-3) << a << " vs " << b;
    }
}

TEST(LdrFlip, FeatureTermRaisesErrorNearAnEdgeAsThePaperSays) {
    // Reference: grey 0.3 everywhere. Test: 0.9 left of column 32, 0.25 from column 32 on. At column 38 the
    // achromatic CSF (σ ≈ 1 px at 67 ppd) no longer sees the step, so the colour error is that of 0.25 against 0.3,
    // but the edge and point detectors (σ = 0.5·0.082·ppd ≈ 2.75 px, radius 9) still reach the 0.9 side 7 px away.
    // Along x their response is (0.9 − 0.25)·Σ_{i ≤ −7} w(i) over the paper's normalised kernels; along y the image
    // is constant and the responses vanish. The reference has no features, so FLIP = ΔE_c^(1 − ΔE_f) with
    // ΔE_f = (max(|edge|, |point|) / √2)^0.5. Beyond the detectors' radius (column 45) FLIP = ΔE_c.
    const double ppd = kDefaultPixelsPerDegree;
    const double sd = 0.5 * 0.082 * ppd;
    const int radius = static_cast<int>(std::ceil(3.0 * sd));
    auto farSideShare = [&](auto shape) {
        double positive = 0.0, negative = 0.0, share = 0.0;
        for (int i = -radius; i <= radius; ++i)
            (shape(i) > 0 ? positive : negative) += shape(i);
        for (int i = -radius; i <= -7; ++i)
            share += shape(i) > 0 ? shape(i) / positive : -shape(i) / negative;
        return share;
    };
    const double edge = farSideShare([&](int i) { return -i * std::exp(-i * i / (2.0 * sd * sd)); });
    const double point =
        farSideShare([&](int i) { return (i * i / (sd * sd) - 1.0) * std::exp(-i * i / (2.0 * sd * sd)); });
    const double deltaF = std::sqrt(0.65 * std::max(std::abs(edge), std::abs(point)) / std::sqrt(2.0));
    const double deltaC = expectedColourError(std::abs(lightness(0.25) - lightness(0.3)));

    const Image reference = constantImage(64, 64, 0.3f, 0.3f, 0.3f);
    const Image test = generate(64, 64, [](int x, int, float* p) { p[0] = p[1] = p[2] = x < 32 ? 0.9f : 0.25f; });
    const FlipResult r = ldrFlip(reference, test, ppd);
    EXPECT_NEAR(r.errorMap.at(38, 30)[0], std::pow(deltaC, 1.0 - deltaF), 1e-3);
    EXPECT_NEAR(r.errorMap.at(45, 30)[0], deltaC, 1e-3);
    EXPECT_GT(std::pow(deltaC, 1.0 - deltaF), deltaC + 0.03); // the check above can tell the two apart
}

TEST(LdrFlip, IsSymmetric) {
    const Image a = colourfulImage(48, 40);
    const Image b = addNoise(a, 0.05f, 9);
    EXPECT_NEAR(ldrFlip(a, b).mean, ldrFlip(b, a).mean, 1e-9);
}

TEST(LdrFlip, ErrorStaysWithinTheFiltersSupport) {
    // At the paper's 67 ppd the widest CSF term (b = 0.04) gives a radius of ceil(3·sqrt(0.04/(2π²))·67.02) = 10
    // pixels and the feature filters ceil(3·0.5·0.082·67.02) = 9, so changing column 32 cannot affect pixels more
    // than 10 columns away.
    const Image reference = colourfulImage(64, 64);
    Image test = reference;
    for (int y = 0; y < 64; ++y)
        test.at(32, y)[1] = 1.0f;
    const FlipResult r = ldrFlip(reference, test);
    for (int y = 0; y < 64; ++y) {
        for (int x = 0; x < 64; ++x) {
            const float e = r.errorMap.at(x, y)[0];
            if (std::abs(x - 32) > 10) {
                ASSERT_EQ(e, 0.0f) << "at " << x << "," << y;
            }
            if (std::abs(x - 32) <= 2) {
                ASSERT_GT(e, 0.05f) << "at " << x << "," << y;
            }
        }
    }
}

TEST(LdrFlip, RejectsNonPositivePixelsPerDegree) {
    const Image a = constantImage(8, 8, 0.5f, 0.5f, 0.5f);
    EXPECT_THROW(ldrFlip(a, a, 0.0), UserError);
    EXPECT_THROW(ldrFlip(a, a, -3.0), UserError);
}

TEST(FlipStatistics, WeightedQuantilesOfHandBuiltMap) {
    // 16 errors: 8×0.05, 4×0.1, 2×0.2, 0.4, 0.9. Sum 2.5. Running sums over the sorted errors: 0.05…0.4, then
    // 0.5 0.6 0.7 0.8, then 1.0 1.2, then 1.6, then 2.5. The weighted p-quantile is the first error whose running sum
    // exceeds p·2.5: Q1 (0.625) → 0.1, median (1.25) → 0.4, Q3 (1.875) → 0.9. The unweighted median would be 0.075.
    const float values[16] = {0.9f,  0.05f, 0.1f,  0.05f, 0.2f,  0.05f, 0.05f, 0.1f,
                              0.05f, 0.4f,  0.05f, 0.1f,  0.05f, 0.2f,  0.1f,  0.05f};
    Image map(4, 4);
    for (int i = 0; i < 16; ++i) {
        float* p = map.at(i % 4, i / 4);
        p[0] = p[1] = p[2] = values[i];
        p[3] = 1.0f;
    }
    const FlipResult r = summarizeFlip(map);
    EXPECT_NEAR(r.mean, 2.5 / 16.0, 1e-7);
    EXPECT_FLOAT_EQ(r.minimum, 0.05f);
    EXPECT_FLOAT_EQ(r.maximum, 0.9f);
    EXPECT_FLOAT_EQ(r.q1, 0.1f);
    EXPECT_FLOAT_EQ(r.weightedMedian, 0.4f);
    EXPECT_FLOAT_EQ(r.q3, 0.9f);
    EXPECT_EQ(r.errorMap.pixels, map.pixels);
}

TEST(FlipStatistics, AllZeroMap) {
    const FlipResult r = summarizeFlip(Image(3, 3));
    EXPECT_EQ(r.weightedMedian, 0.0);
    EXPECT_EQ(r.q1, 0.0);
    EXPECT_EQ(r.q3, 0.0);
    EXPECT_EQ(r.mean, 0.0);
}

// Narkowicz's ACES fit as the HDR-FLIP paper uses it, with the 0.6 pre-exposure, written out independently.
double aces(double x) {
    const double v = 0.6 * x;
    return std::clamp(v * (2.51 * v + 0.03) / (v * (2.43 * v + 0.59) + 0.14), 0.0, 1.0);
}

Image hdrScene(int w, int h) {
    // A quarter at 0.25, half at 1.0 and a quarter at 8.0 (luminance, grey), lightly textured.
    return generate(w, h, [&](int x, int y, float* p) {
        const float level = y < h / 4 ? 0.25f : (y < 3 * h / 4 ? 1.0f : 8.0f);
        const float texture = 1.0f + 0.2f * std::sin(0.7f * x) * std::cos(0.5f * y);
        p[0] = p[1] = p[2] = level * texture;
    });
}

TEST(HdrFlip, IdenticalIsZero) {
    const Image a = hdrScene(64, 64);
    const HdrFlipResult r = hdrFlip(a, a);
    EXPECT_EQ(r.maximum, 0.0);
    EXPECT_EQ(r.mean, 0.0);
    EXPECT_GE(r.exposureCount, 2);
}

TEST(HdrFlip, GrowsWithNoiseAmplitude) {
    const Image reference = hdrScene(64, 64);
    double previous = 0.0;
    for (float amplitude : {0.02f, 0.05f, 0.1f, 0.2f}) {
        Image test = reference;
        for (int y = 0; y < 64; ++y)
            for (int x = 0; x < 64; ++x)
                for (int c = 0; c < 3; ++c)
                    test.at(x, y)[c] *= 1.0f + amplitude * testing::hashNoise(x, y, 40 + c);
        const double mean = hdrFlip(reference, test).mean;
        EXPECT_GT(mean, previous) << "amplitude " << amplitude;
        previous = mean;
    }
}

TEST(HdrFlip, AutomaticExposuresMapMaximumAndMedianToPointEightFive) {
    // Flat levels: luminance max 8, median 1 (the two middle pixels are both 1).
    const Image reference =
        generate(64, 64, [](int, int y, float* p) { p[0] = p[1] = p[2] = y < 16 ? 0.25f : (y < 48 ? 1.0f : 8.0f); });
    const HdrFlipResult r = hdrFlip(reference, reference);
    EXPECT_NEAR(aces(std::exp2(r.startExposure) * 8.0), 0.85, 1e-9);
    EXPECT_NEAR(aces(std::exp2(r.stopExposure) * 1.0), 0.85, 1e-9);
    EXPECT_NEAR(r.stopExposure - r.startExposure, 3.0, 1e-9); // log2(8 / 1)
    EXPECT_EQ(r.exposureCount, 3);                            // max(2, ceil(3))
    std::set<float> seen;
    for (size_t i = 0; i < r.exposureMap.pixels.size(); i += 4)
        seen.insert(r.exposureMap.pixels[i]);
    for (float v : seen)
        EXPECT_TRUE(v == 0.0f || v == 0.5f || v == 1.0f) << v;
}

TEST(HdrFlip, SingleExposureIsLdrFlipOfToneMappedPair) {
    const Image reference = hdrScene(48, 48);
    Image test = reference;
    for (size_t i = 0; i < test.pixels.size(); i += 4)
        test.pixels[i] *= 1.3f;
    HdrFlipOptions options;
    options.automaticExposures = false;
    options.startExposure = options.stopExposure = 1.0;
    options.exposureCount = 1;
    auto toneMapped = [](const Image& image) {
        Image out = image;
        for (size_t i = 0; i < out.pixels.size(); ++i)
            out.pixels[i] = i % 4 == 3 ? 1.0f : static_cast<float>(aces(2.0 * image.pixels[i]));
        return out;
    };
    const double expected = ldrFlip(toneMapped(reference), toneMapped(test)).mean;
    EXPECT_NEAR(hdrFlip(reference, test, options).mean, expected, 1e-5);
    EXPECT_GT(expected, 0.01);
}

} // namespace
} // namespace vitrine::compare
