#include "core/compare/metrics.hpp"

#include "core/base/error.hpp"
#include "test_images.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

namespace vitrine::compare {
namespace {

using testing::addNoise;
using testing::colourfulImage;
using testing::constantImage;
using testing::generate;
using testing::hashNoise;

constexpr double kC1 = 0.01 * 0.01; // (K1·L)² with L = 1
constexpr double kC2 = 0.03 * 0.03; // (K2·L)²

// SSIM of two constant signals: σx = σy = σxy = 0, so the structure term is C2/C2 = 1.
double constantPairSsim(double mx, double my) {
    return (2.0 * mx * my + kC1) / (mx * mx + my * my + kC1);
}

TEST(Psnr, ConstantOffsetMatchesClosedForm) {
    // MSE = d² for a constant offset d, so PSNR = 20·log10(1/d). 0.5 − 0.25 is exact in binary.
    const Image a = constantImage(64, 64, 0.5f, 0.5f, 0.5f, 1.0f);
    const Image b = constantImage(64, 64, 0.25f, 0.25f, 0.25f, 0.0f); // alpha differs and must be ignored
    EXPECT_NEAR(psnr(a, b), 20.0 * std::log10(1.0 / 0.25), 1e-9);
    EXPECT_NEAR(psnr(a, b, 2.0), 20.0 * std::log10(2.0 / 0.25), 1e-9);
}

TEST(Psnr, OffsetOnTexturedImage) {
    const Image a = colourfulImage(64, 64);
    Image b = a;
    for (size_t i = 0; i < b.pixels.size(); ++i)
        if (i % 4 != 3) b.pixels[i] += 0.1f;
    // Float rounding of x + 0.1 perturbs d by ~1e-8, i.e. ~1e-6 dB.
    EXPECT_NEAR(psnr(a, b), 20.0, 1e-4);
}

TEST(Psnr, IdenticalIsInfinite) {
    const Image a = colourfulImage(64, 64);
    EXPECT_EQ(psnr(a, a), std::numeric_limits<double>::infinity());
}

TEST(Ssim, IdenticalIsExactlyOne) {
    const Image a = addNoise(colourfulImage(64, 64), 0.1f, 7);
    const SsimResult r = ssim(a, a);
    EXPECT_EQ(r.mean, 1.0);
    for (int y = 0; y < a.height; ++y)
        for (int x = 0; x < a.width; ++x)
            ASSERT_EQ(r.map.at(x, y)[0], 1.0f) << "at " << x << "," << y;
}

TEST(Ssim, ConstantPairMatchesFormula) {
    const Image a = constantImage(64, 64, 0.6f, 0.6f, 0.6f);
    const Image b = constantImage(64, 64, 0.4f, 0.4f, 0.4f);
    EXPECT_NEAR(ssim(a, b).mean, constantPairSsim(0.6, 0.4), 1e-6);
}

TEST(Ssim, UsesRec709LuminanceOfClampedValues) {
    // Pure red against pure green: Y = 0.2126 against 0.7152.
    const Image red = constantImage(32, 32, 1.0f, 0.0f, 0.0f);
    const Image green = constantImage(32, 32, 0.0f, 1.0f, 0.0f);
    EXPECT_NEAR(ssim(red, green).mean, constantPairSsim(0.2126, 0.7152), 1e-6);
    // 3.0 clamps to 1.0 (and -1 to 0) before luminance, so these are the same image to SSIM.
    const Image over = constantImage(32, 32, 3.0f, 3.0f, -1.0f);
    const Image at = constantImage(32, 32, 1.0f, 1.0f, 0.0f);
    EXPECT_NEAR(ssim(over, at).mean, 1.0, 1e-12);
}

TEST(Ssim, ConstantRegionOfContrastScaledOffsetCopy) {
    // x: noise on the left half, 0.6 on the right. y = 0.5·x + 0.1, so y's right half is 0.4. Away from the
    // boundary by more than the window radius (5 px), each window sees two constants: SSIM = (2μxμy+C1)/(μx²+μy²+C1).
    const Image x = generate(64, 64, [](int px, int py, float* p) {
        const float v = px < 32 ? 0.5f + 0.4f * hashNoise(px, py, 3) : 0.6f;
        p[0] = p[1] = p[2] = v;
    });
    Image y = x;
    for (size_t i = 0; i < y.pixels.size(); ++i)
        if (i % 4 != 3) y.pixels[i] = 0.5f * x.pixels[i] + 0.1f;
    const SsimResult r = ssim(x, y);
    const double expected = constantPairSsim(0.6, 0.5 * 0.6 + 0.1);
    for (int py = 0; py < 64; ++py)
        for (int px = 38; px < 64; ++px)
            ASSERT_NEAR(r.map.at(px, py)[0], expected, 1e-5) << "at " << px << "," << py;
    // In the textured half, halving the contrast also costs structure: lower than the constant region.
    EXPECT_LT(r.map.at(10, 32)[0], expected);
}

TEST(Ssim, WindowIsElevenTapGaussianWithSigmaOnePointFive) {
    // x is a vertical step (0 left of column 32, 1 from it on), y a constant c. Near the step, a window's weight on
    // the bright side is F = Σ w(k) over the taps k in [-5, 5] with x0 + k ≥ 32, w the normalised Gaussian of σ = 1.5
    // (rows do not matter: the image is constant along y). Then μx = F, σx² = F − F², μy = c, σy = σxy = 0.
    const float c = 0.3f;
    const Image x = generate(64, 64, [](int px, int, float* p) { p[0] = p[1] = p[2] = px >= 32 ? 1.0f : 0.0f; });
    const Image y = constantImage(64, 64, c, c, c);
    const SsimResult r = ssim(x, y);
    double weights[11], total = 0.0;
    for (int k = -5; k <= 5; ++k)
        total += weights[k + 5] = std::exp(-k * k / (2.0 * 1.5 * 1.5));
    for (int x0 = 26; x0 <= 37; ++x0) {
        double f = 0.0;
        for (int k = -5; k <= 5; ++k)
            if (x0 + k >= 32) f += weights[k + 5] / total;
        const double expected = (2.0 * f * c + kC1) / (f * f + c * c + kC1) * kC2 / (f - f * f + kC2);
        EXPECT_NEAR(r.map.at(x0, 20)[0], expected, 1e-6) << "column " << x0;
    }
}

TEST(Ssim, DecreasesWithNoise) {
    const Image a = colourfulImage(64, 64);
    double previous = 1.0;
    for (float amplitude : {0.01f, 0.03f, 0.1f, 0.3f}) {
        const double s = ssim(a, addNoise(a, amplitude, 11)).mean;
        EXPECT_LT(s, previous) << "amplitude " << amplitude;
        previous = s;
    }
}

TEST(SizeMismatch, NamesBothSizes) {
    const Image a(4, 4), b(4, 5);
    auto expectNamed = [&](auto&& call) {
        try {
            call();
            FAIL() << "expected UserError";
        } catch (const UserError& e) {
            const std::string message = e.what();
            EXPECT_NE(message.find("4x4"), std::string::npos) << message;
            EXPECT_NE(message.find("4x5"), std::string::npos) << message;
        }
    };
    expectNamed([&] { psnr(a, b); });
    expectNamed([&] { ssim(a, b); });
    expectNamed([&] { ldrFlip(a, b); });
    expectNamed([&] { hdrFlip(a, b); });
    expectNamed([&] { absoluteDifference(a, b); });
    EXPECT_THROW(psnr(Image(), Image()), UserError);
}

TEST(AbsoluteDifference, PerChannelWithOpaqueAlpha) {
    const Image a = constantImage(2, 2, 0.5f, 0.25f, 1.0f, 0.3f);
    const Image b = constantImage(2, 2, 0.75f, 0.25f, 0.0f, 0.9f);
    const Image d = absoluteDifference(a, b);
    EXPECT_FLOAT_EQ(d.at(1, 1)[0], 0.25f);
    EXPECT_FLOAT_EQ(d.at(1, 1)[1], 0.0f);
    EXPECT_FLOAT_EQ(d.at(1, 1)[2], 1.0f);
    EXPECT_FLOAT_EQ(d.at(1, 1)[3], 1.0f);
}

float srgbToLinear(float v) {
    return v <= 0.04045f ? v / 12.92f : std::pow((v + 0.055f) / 1.055f, 2.4f);
}

TEST(FlipColorMap, EndpointsAreMagmasAndLinear) {
    // Magma's published end colours are #000004 (0.001462, 0.000466, 0.013866) and #fcfdbf
    // (0.987053, 0.991438, 0.749504); the map stores them decoded to linear.
    Image e(2, 1);
    e.at(0, 0)[0] = 0.0f;
    e.at(1, 0)[0] = 1.0f;
    const Image c = flipColorMap(e);
    EXPECT_NEAR(c.at(0, 0)[0], srgbToLinear(0.001462f), 1e-6);
    EXPECT_NEAR(c.at(0, 0)[2], srgbToLinear(0.013866f), 1e-6);
    EXPECT_NEAR(c.at(1, 0)[0], srgbToLinear(0.987053f), 1e-5);
    EXPECT_NEAR(c.at(1, 0)[1], srgbToLinear(0.991438f), 1e-5);
    EXPECT_NEAR(c.at(1, 0)[2], srgbToLinear(0.749504f), 1e-5);
    EXPECT_EQ(c.at(1, 0)[3], 1.0f);
}

TEST(FlipColorMap, LuminanceRisesMonotonically) {
    // Magma is designed with monotonically increasing lightness; a mistyped table entry would break that.
    Image e(256, 1);
    for (int i = 0; i < 256; ++i)
        e.at(i, 0)[0] = i / 255.0f;
    const Image c = flipColorMap(e);
    double previous = -1.0;
    for (int i = 0; i < 256; ++i) {
        const float* p = c.at(i, 0);
        const double y = 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
        EXPECT_GT(y, previous) << "entry " << i;
        previous = y;
    }
}

TEST(FalseColor, ScalesLargestChannelThroughMagma) {
    Image e(1, 1);
    e.at(0, 0)[0] = 1.0f;
    const Image top = flipColorMap(e);
    // max(0.05, 0.25, 0.1) · 4 = 1 → top of the map.
    const Image scaled = falseColor(constantImage(1, 1, 0.05f, 0.25f, 0.1f), 4.0);
    for (int c = 0; c < 3; ++c)
        EXPECT_FLOAT_EQ(scaled.at(0, 0)[c], top.at(0, 0)[c]);
    const Image broken = falseColor(constantImage(1, 1, std::nanf(""), 0.0f, 0.0f), 1.0);
    EXPECT_FLOAT_EQ(broken.at(0, 0)[0], top.at(0, 0)[0]);
}

} // namespace
} // namespace vitrine::compare
