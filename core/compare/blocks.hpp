#pragma once

#include "core/image/image.hpp"

#include <vector>

// The block luminance ratio: a comparison measure that Monte Carlo noise barely moves. Per-pixel metrics (FLIP, PSNR)
// against a path-traced reference mostly measure the reference's noise; the mean luminance of a 16×16 block averages
// 256 pixels, so zero-mean noise shrinks by about 16× there while a shading difference, which moves whole regions, does
// not. Computed on the CPU on the linear float images compare has (what a.exr holds), not on the PNGs.
namespace vitrine::compare {

inline constexpr int kBlockSize = 16;               // pixels, at every resolution
inline constexpr double kBlockTolerance = 0.15;     // a block is "within" when |ratio − 1| <= this
inline constexpr double kBlockFloorFraction = 0.01; // the luminance floor, as a fraction of the reference's mean

struct BlockRatioStatistics {
    int blockSize = kBlockSize;
    int blocksX = 0;
    int blocksY = 0;
    int litBlocks = 0;  // blocks where the test or the reference is above the floor: the statistics are over these
    int darkBlocks = 0; // blocks where both are at or below the floor (both black): left out, grey in the heat map
    double floor = 0.0; // the absolute luminance floor used (kBlockFloorFraction × the reference's mean luminance)
    double withinShare = 1.0;     // share of lit blocks with |ratio − 1| <= kBlockTolerance (1 when none is lit)
    double meanAbsLog2 = 0.0;     // mean |log2 ratio| over lit blocks, in stops
    double meanAbsRelative = 0.0; // mean |ratio − 1| over lit blocks
};

struct BlockRatioResult : BlockRatioStatistics {
    // log2(ratio) per block, row-major, blocksX × blocksY, top row first; NaN for dark blocks.
    std::vector<double> log2Ratio;
};

// Per block of blockSize × blockSize pixels (the last column and row of blocks may be narrower), the mean Rec. 709
// luminance of each image (negative and non-finite channel values count as 0), and
//     ratio = max(L_test, floor) / max(L_reference, floor),  floor = kBlockFloorFraction × mean luminance of reference
// (of the test when the reference is all black). ratio > 1: the test is brighter. Throws UserError when the sizes
// differ, an image is empty or blockSize < 1.
BlockRatioResult blockLuminanceRatio(const Image& test, const Image& reference, int blockSize = kBlockSize);

// The heat map of blocks.log2Ratio at width × height pixels (each pixel shows its block): white at 0, towards red
// where the test is brighter and towards blue where it is darker, saturated at ±1 stop; in sRGB terms
// (1, 1 − t, 1 − t) for t = min(log2 ratio, 1) > 0 and (1 − t, 1 − t, 1) for t = min(−log2 ratio, 1) > 0; dark blocks
// neutral grey (sRGB 0.5). The Image holds the linear values of those sRGB colours (PNG encoders apply the transfer).
Image blockRatioHeatMap(const BlockRatioResult& blocks, int width, int height);

// The sRGB colour (components in [0,1]) blockRatioHeatMap() gives a block: for the report's colour bar and tests.
struct SrgbColor {
    double r = 0.0, g = 0.0, b = 0.0;
};
SrgbColor blockRatioColor(double log2Ratio);

} // namespace vitrine::compare
