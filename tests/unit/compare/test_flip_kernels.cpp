#include "core/compare/flip_kernels.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

// White-box checks of the FLIP kernels against the HPG 2020 paper's definitions, written out here independently.
namespace vitrine::compare::detail {
namespace {

// The paper's 2D CSF kernel, Σ a·sqrt(π/b)·exp(−π²·(x² + y²)/b) with x, y in degrees, before normalisation.
double paperCsf(int channel, int i, int j, double ppd) {
    static const double kAb[3][2][2] = {
        {{1.0, 0.0047}, {0.0, 1e-5}}, {{1.0, 0.0053}, {0.0, 1e-5}}, {{34.1, 0.04}, {13.5, 0.025}}};
    const double d2 = (i * i + j * j) / (ppd * ppd);
    double value = 0.0;
    for (const auto& [a, b] : kAb[channel])
        value += a * std::sqrt(std::numbers::pi / b) * std::exp(-std::numbers::pi * std::numbers::pi * d2 / b);
    return value;
}

TEST(FlipKernels, SeparableCsfTermsRebuildThePapersNormalisedKernel) {
    for (double ppd : {20.0, 67.02064327658226}) {
        const FlipKernels k = makeKernels(ppd);
        // Radius from the widest term, b = 0.04: ceil(3·sqrt(0.04 / (2π²))·ppd).
        const int radius =
            static_cast<int>(std::ceil(3.0 * std::sqrt(0.04 / (2.0 * std::numbers::pi * std::numbers::pi)) * ppd));
        for (int channel = 0; channel < 3; ++channel) {
            double total = 0.0;
            for (int j = -radius; j <= radius; ++j)
                for (int i = -radius; i <= radius; ++i)
                    total += paperCsf(channel, i, j, ppd);
            for (const CsfTerm& term : k.csf[channel])
                ASSERT_EQ(term.kernel.size(), static_cast<size_t>(2 * radius + 1));
            for (int j = -radius; j <= radius; ++j) {
                for (int i = -radius; i <= radius; ++i) {
                    double ours = 0.0;
                    for (const CsfTerm& term : k.csf[channel])
                        ours += term.weight * term.kernel[i + radius] * term.kernel[j + radius];
                    ASSERT_NEAR(ours, paperCsf(channel, i, j, ppd) / total, 1e-12)
                        << "ppd " << ppd << " channel " << channel << " at " << i << "," << j;
                }
            }
        }
    }
}

TEST(FlipKernels, FeatureDetectorsFollowThePaper) {
    const FlipKernels k = makeKernels(67.02064327658226);
    // σ = 0.5 · 0.082 · ppd ≈ 2.748 px, radius ceil(3σ) = 9.
    ASSERT_EQ(k.edge.size(), 19u);
    ASSERT_EQ(k.point.size(), 19u);
    ASSERT_EQ(k.featureGauss.size(), 19u);
    double positive = 0.0, negative = 0.0, gauss = 0.0;
    for (size_t i = 0; i < k.edge.size(); ++i) {
        (k.edge[i] > 0 ? positive : negative) += k.edge[i];
        EXPECT_NEAR(k.edge[i], -k.edge[k.edge.size() - 1 - i], 1e-15); // odd: a first derivative
        gauss += k.featureGauss[i];
    }
    EXPECT_NEAR(positive, 1.0, 1e-12);
    EXPECT_NEAR(negative, -1.0, 1e-12);
    EXPECT_NEAR(gauss, 1.0, 1e-12);
    positive = negative = 0.0;
    for (double w : k.point)
        (w > 0 ? positive : negative) += w;
    EXPECT_NEAR(positive, 1.0, 1e-12);
    EXPECT_NEAR(negative, -1.0, 1e-12);
    // The second derivative of a Gaussian changes sign at ±σ: taps 0..2 negative, 3.. positive.
    EXPECT_LT(k.point[9 + 2], 0.0);
    EXPECT_GT(k.point[9 + 3], 0.0);
}

} // namespace
} // namespace vitrine::compare::detail
