#include "core/compare/metrics.hpp"

#include "core/base/error.hpp"
#include "test_images.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace vitrine::compare {
namespace {

using testing::colourfulImage;
using testing::constantImage;
using testing::generate;

TEST(Flicker, StaticSequenceIsZero) {
    const Image a = colourfulImage(32, 32);
    EXPECT_EQ(flicker({a, a, a, a}), 0.0);
}

TEST(Flicker, AlternatingFramesGiveTheirDifference) {
    // Alpha changes too and must not count.
    const Image dark = constantImage(32, 32, 0.2f, 0.2f, 0.2f, 1.0f);
    const Image light = constantImage(32, 32, 0.7f, 0.7f, 0.7f, 0.0f);
    EXPECT_NEAR(flicker({dark, light, dark, light, dark}), 0.5, 1e-6);
    // Pairs are averaged: |0.7 − 0.2| then 0.
    EXPECT_NEAR(flicker({dark, light, light}), 0.25, 1e-6);
    // Only the red channel changes: a third of the RGB difference.
    const Image red = constantImage(32, 32, 0.8f, 0.2f, 0.2f);
    EXPECT_NEAR(flicker({dark, red}), 0.6 / 3.0, 1e-6);
}

TEST(Flicker, NeedsTwoFramesOfOneSize) {
    const Image a(8, 8);
    EXPECT_THROW(flicker({a}), UserError);
    EXPECT_THROW(flicker({a, Image(8, 9)}), UserError);
}

// A pattern defined everywhere on the plane, moved by (dx, dy) per frame: frame i shows pattern(x − i·dx, y − i·dy).
float pattern(double x, double y) {
    return static_cast<float>(0.5 + 0.2 * std::sin(0.9 * x) * std::cos(0.6 * y) + 0.1 * std::sin(0.37 * (x + 2 * y)));
}

std::vector<Image> translatingSequence(int frames, double dx, double dy) {
    std::vector<Image> out;
    for (int i = 0; i < frames; ++i)
        out.push_back(
            generate(48, 40, [&](int x, int y, float* p) { p[0] = p[1] = p[2] = pattern(x - i * dx, y - i * dy); }));
    return out;
}

std::vector<Image> uniformVelocities(int frames, float vx, float vy) {
    return std::vector<Image>(frames, constantImage(48, 40, vx, vy, 0.0f, 0.0f));
}

TEST(FlickerMotionCompensated, TranslationWithCorrectVelocitiesIsZero) {
    const std::vector<Image> frames = translatingSequence(4, 2.0, 1.0);
    EXPECT_GT(flicker(frames), 0.05);
    // Integer motion: the bilinear fetch lands on pixel centres, so the compensated frames match exactly.
    EXPECT_LT(flickerMotionCompensated(frames, uniformVelocities(4, 2.0f, 1.0f)), 1e-7);
    // The opposite sign (previous minus current) fetches the wrong place.
    EXPECT_GT(flickerMotionCompensated(frames, uniformVelocities(4, -2.0f, -1.0f)), 0.05);
}

TEST(FlickerMotionCompensated, SubpixelMotionOfARampIsExactUnderBilinearFetch) {
    // value = 0.2 + 0.01·(x − 0.5·i): linear, so bilinear interpolation reproduces it; plain flicker is the
    // per-frame change 0.01 · 0.5.
    std::vector<Image> frames;
    for (int i = 0; i < 3; ++i)
        frames.push_back(
            generate(48, 40, [&](int x, int, float* p) { p[0] = p[1] = p[2] = 0.2f + 0.01f * (x - 0.5f * i); }));
    EXPECT_NEAR(flicker(frames), 0.005, 1e-6);
    EXPECT_LT(flickerMotionCompensated(frames, uniformVelocities(3, 0.5f, 0.0f)), 1e-6);
}

TEST(FlickerMotionCompensated, SkipsPixelsThatLandOffScreen) {
    // Content moves 5 px right per frame; the 5 left columns were off-screen in the previous frame. If they were
    // clamped instead of skipped they would add error.
    const std::vector<Image> frames = translatingSequence(3, 5.0, 0.0);
    EXPECT_LT(flickerMotionCompensated(frames, uniformVelocities(3, 5.0f, 0.0f)), 1e-7);
    EXPECT_THROW(flickerMotionCompensated(frames, uniformVelocities(2, 5.0f, 0.0f)), UserError);
}

TEST(ErrorPerFrame, PsnrAgainstOneReference) {
    const Image reference = constantImage(32, 32, 0.5f, 0.5f, 0.5f);
    std::vector<Image> frames;
    for (float d : {0.5f, 0.25f, 0.125f})
        frames.push_back(constantImage(32, 32, 0.5f - d, 0.5f - d, 0.5f - d));
    const std::vector<double> psnrs = errorPerFrame(frames, reference, FrameMetric::Psnr);
    ASSERT_EQ(psnrs.size(), 3u);
    EXPECT_NEAR(psnrs[0], 20.0 * std::log10(1.0 / 0.5), 1e-9);
    EXPECT_NEAR(psnrs[1], 20.0 * std::log10(1.0 / 0.25), 1e-9);
    EXPECT_NEAR(psnrs[2], 20.0 * std::log10(1.0 / 0.125), 1e-9);
}

TEST(ErrorPerFrame, FlipMeanIsZeroForTheMatchingFrameAndGrows) {
    const Image reference = colourfulImage(32, 32);
    const std::vector<Image> frames = {reference, testing::addNoise(reference, 0.05f, 1),
                                       testing::addNoise(reference, 0.15f, 1)};
    const std::vector<double> errors = errorPerFrame(frames, reference, FrameMetric::FlipMean);
    EXPECT_EQ(errors[0], 0.0);
    EXPECT_GT(errors[1], 0.0);
    EXPECT_GT(errors[2], errors[1]);
    EXPECT_THROW(errorPerFrame(frames, std::vector<Image>{reference}, FrameMetric::Psnr), UserError);
    const std::vector<double> own = errorPerFrame(frames, frames, FrameMetric::FlipMean);
    for (double e : own)
        EXPECT_EQ(e, 0.0);
}

} // namespace
} // namespace vitrine::compare
