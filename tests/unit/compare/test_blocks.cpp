// The block luminance ratio (core/compare/blocks.hpp) against a CPU computation written here from its definition: mean
// Rec. 709 luminance per 16 px block, ratio = max(test, floor) / max(reference, floor) with floor = 1 % of the
// reference's mean, and the heat map's colours from their sRGB definition.
#include "core/base/error.hpp"
#include "core/compare/blocks.hpp"
#include "core/compare/metrics.hpp"
#include "test_images.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace vitrine::compare {
namespace {

double lum(const float* p) {
    auto c = [](float v) { return v > 0.0f ? double(v) : 0.0; };
    return 0.2126 * c(p[0]) + 0.7152 * c(p[1]) + 0.0722 * c(p[2]);
}

// The measure computed the plain way: pixel by pixel, block by block.
struct Expected {
    std::vector<double> log2Ratio; // NaN: dark
    int lit = 0, dark = 0;
    double within = 0.0, meanAbsLog2 = 0.0, meanAbsRelative = 0.0, floor = 0.0;
};

Expected cpuBlocks(const Image& test, const Image& reference, int size) {
    double meanReference = 0.0;
    for (int y = 0; y < reference.height; ++y)
        for (int x = 0; x < reference.width; ++x)
            meanReference += lum(reference.at(x, y));
    meanReference /= double(reference.width) * reference.height;
    Expected e;
    e.floor = 0.01 * meanReference;
    int within = 0;
    for (int by = 0; by * size < test.height; ++by)
        for (int bx = 0; bx * size < test.width; ++bx) {
            double lt = 0.0, lr = 0.0;
            int n = 0;
            for (int y = by * size; y < std::min((by + 1) * size, test.height); ++y)
                for (int x = bx * size; x < std::min((bx + 1) * size, test.width); ++x, ++n) {
                    lt += lum(test.at(x, y));
                    lr += lum(reference.at(x, y));
                }
            lt /= n;
            lr /= n;
            if (lt <= e.floor && lr <= e.floor) {
                e.log2Ratio.push_back(std::nan(""));
                ++e.dark;
                continue;
            }
            const double ratio = std::max(lt, e.floor) / std::max(lr, e.floor);
            e.log2Ratio.push_back(std::log2(ratio));
            ++e.lit;
            e.meanAbsLog2 += std::fabs(std::log2(ratio));
            e.meanAbsRelative += std::fabs(ratio - 1.0);
            within += std::fabs(ratio - 1.0) <= 0.15;
        }
    e.within = double(within) / e.lit;
    e.meanAbsLog2 /= e.lit;
    e.meanAbsRelative /= e.lit;
    return e;
}

double srgbDecode(double c) {
    return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
}

void scaleRect(Image& image, int x0, int y0, int x1, int y1, float factor) {
    for (int y = y0; y < y1; ++y)
        for (int x = x0; x < x1; ++x)
            for (int c = 0; c < 3; ++c)
                image.at(x, y)[c] *= factor;
}

// A region exactly two blocks large made 2× brighter: 2 of 12 blocks are off by +1 stop, saturated red.
TEST(BlockRatio, TwiceBrighterBlocksAreOneStopAndSaturatedRed) {
    const Image reference = testing::constantImage(64, 48, 0.2f, 0.3f, 0.1f);
    Image test = reference;
    scaleRect(test, 16, 16, 48, 32, 2.0f);
    const BlockRatioResult r = blockLuminanceRatio(test, reference);
    EXPECT_EQ(r.blocksX, 4);
    EXPECT_EQ(r.blocksY, 3);
    EXPECT_EQ(r.litBlocks, 12);
    EXPECT_EQ(r.darkBlocks, 0);
    EXPECT_DOUBLE_EQ(r.withinShare, 10.0 / 12.0);
    EXPECT_NEAR(r.meanAbsLog2, 2.0 / 12.0, 1e-6);
    EXPECT_NEAR(r.meanAbsRelative, 2.0 / 12.0, 1e-6);
    EXPECT_NEAR(r.log2Ratio[1 * 4 + 1], 1.0, 1e-6);
    EXPECT_NEAR(r.log2Ratio[0], 0.0, 1e-12);

    const Image map = blockRatioHeatMap(r, 64, 48);
    ASSERT_EQ(map.width, 64);
    const float* red = map.at(20, 20);
    EXPECT_NEAR(red[0], 1.0f, 1e-6);
    EXPECT_NEAR(red[1], 0.0f, 1e-6);
    EXPECT_NEAR(red[2], 0.0f, 1e-6);
    const float* white = map.at(5, 5);
    EXPECT_NEAR(white[0], 1.0f, 1e-5);
    EXPECT_NEAR(white[1], 1.0f, 1e-5);
    EXPECT_NEAR(white[2], 1.0f, 1e-5);

    // The other way round the same blocks are 1 stop darker: saturated blue.
    const BlockRatioResult darker = blockLuminanceRatio(reference, test);
    const float* blue = blockRatioHeatMap(darker, 64, 48).at(40, 30);
    EXPECT_NEAR(blue[0], 0.0f, 1e-6);
    EXPECT_NEAR(blue[1], 0.0f, 1e-6);
    EXPECT_NEAR(blue[2], 1.0f, 1e-6);
}

// Half a stop: halfway from white to red in sRGB, (1, 0.5, 0.5), stored as linear values; 4 stops saturate.
TEST(BlockRatio, HeatMapColoursFollowTheSrgbRamp) {
    const Image reference = testing::constantImage(32, 16, 0.25f, 0.25f, 0.25f);
    Image test = reference;
    scaleRect(test, 0, 0, 16, 16, std::sqrt(2.0f));
    scaleRect(test, 16, 0, 32, 16, 1.0f / 16.0f);
    const BlockRatioResult r = blockLuminanceRatio(test, reference);
    const Image map = blockRatioHeatMap(r, 32, 16);
    EXPECT_NEAR(map.at(3, 3)[0], 1.0, 1e-5);
    EXPECT_NEAR(map.at(3, 3)[1], srgbDecode(0.5), 1e-5);
    EXPECT_NEAR(map.at(3, 3)[2], srgbDecode(0.5), 1e-5);
    EXPECT_NEAR(r.log2Ratio[1], -4.0, 1e-6);
    EXPECT_NEAR(map.at(20, 3)[0], 0.0, 1e-6);
    EXPECT_NEAR(map.at(20, 3)[2], 1.0, 1e-6);
    EXPECT_EQ(r.withinShare, 0.0);
}

// A noisy image with a brighter rectangle that cuts blocks, partial edge blocks (70×37) and a black corner, against
// the plain computation above.
TEST(BlockRatio, MatchesThePlainComputationWithEdgesAndDarkBlocks) {
    Image reference = testing::addNoise(testing::colourfulImage(70, 37), 0.1f, 3);
    scaleRect(reference, 48, 0, 70, 16, 0.0f); // black in both: dark blocks
    Image test = testing::addNoise(reference, 0.05f, 11);
    scaleRect(test, 48, 0, 70, 16, 0.0f);
    scaleRect(test, 5, 9, 29, 30, 1.3f);
    scaleRect(test, 0, 32, 16, 37, 0.0f); // black in the test only: a lit block at the floor
    const BlockRatioResult r = blockLuminanceRatio(test, reference);
    const Expected e = cpuBlocks(test, reference, 16);
    EXPECT_EQ(r.blocksX, 5);
    EXPECT_EQ(r.blocksY, 3);
    EXPECT_EQ(r.litBlocks, e.lit);
    EXPECT_EQ(r.darkBlocks, e.dark);
    EXPECT_EQ(e.dark, 2); // (3, 0) and (4, 0)
    EXPECT_NEAR(r.floor, e.floor, 1e-12);
    EXPECT_NEAR(r.withinShare, e.within, 1e-12);
    EXPECT_NEAR(r.meanAbsLog2, e.meanAbsLog2, 1e-9);
    EXPECT_NEAR(r.meanAbsRelative, e.meanAbsRelative, 1e-9);
    ASSERT_EQ(r.log2Ratio.size(), e.log2Ratio.size());
    for (size_t i = 0; i < e.log2Ratio.size(); ++i) {
        if (std::isnan(e.log2Ratio[i]))
            EXPECT_TRUE(std::isnan(r.log2Ratio[i])) << i;
        else
            EXPECT_NEAR(r.log2Ratio[i], e.log2Ratio[i], 1e-9) << i;
    }
    // The test-only black block sits at the floor: a large, finite darkening.
    EXPECT_LT(r.log2Ratio[2 * 5 + 0], -3.0);
    // Dark blocks are neutral grey (sRGB 0.5).
    const Image map = blockRatioHeatMap(r, 70, 37);
    for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(map.at(60, 4)[c], srgbDecode(0.5), 1e-5);
}

// Zero-mean per-pixel noise (two independent "halves" of the same image) moves FLIP a lot and the blocks hardly.
TEST(BlockRatio, IndependentNoiseMovesFlipButNotTheBlocks) {
    const Image base = testing::colourfulImage(160, 96);
    const Image a = testing::addNoise(base, 0.12f, 1);
    const Image b = testing::addNoise(base, 0.12f, 2);
    const BlockRatioResult r = blockLuminanceRatio(a, b);
    const double flip = ldrFlip(b, a).mean;
    std::printf("noise halves: FLIP mean %.4f, blocks mean |ratio - 1| %.4f, within %.3f\n", flip, r.meanAbsRelative,
                r.withinShare);
    EXPECT_LT(r.meanAbsRelative, 0.02);
    EXPECT_EQ(r.withinShare, 1.0);
    EXPECT_GT(flip, 0.05);
}

TEST(BlockRatio, BadInputIsAUserError) {
    const Image a = testing::constantImage(16, 16, 1, 1, 1);
    const Image b = testing::constantImage(8, 16, 1, 1, 1);
    EXPECT_THROW(blockLuminanceRatio(a, b), UserError);
    EXPECT_THROW(blockLuminanceRatio(a, Image()), UserError);
    EXPECT_THROW(blockLuminanceRatio(a, a, 0), UserError);
    EXPECT_THROW(blockRatioHeatMap(blockLuminanceRatio(a, a), 32, 16), UserError);
}

} // namespace
} // namespace vitrine::compare
