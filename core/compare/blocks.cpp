#include "core/compare/blocks.hpp"

#include "core/base/error.hpp"
#include "core/compare/plane.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

namespace vitrine::compare {

namespace {

double channel(float v) {
    return std::isfinite(v) && v > 0.0f ? static_cast<double>(v) : 0.0;
}

double luminance(const float* p) {
    return 0.2126 * channel(p[0]) + 0.7152 * channel(p[1]) + 0.0722 * channel(p[2]);
}

// Mean luminance of every block, row-major.
std::vector<double> blockMeans(const Image& image, int blockSize, int blocksX, int blocksY, double& imageMean) {
    std::vector<double> sums(static_cast<size_t>(blocksX) * blocksY, 0.0);
    double total = 0.0;
    for (int y = 0; y < image.height; ++y)
        for (int x = 0; x < image.width; ++x) {
            const double l = luminance(image.at(x, y));
            sums[static_cast<size_t>(y / blockSize) * blocksX + x / blockSize] += l;
            total += l;
        }
    for (int by = 0; by < blocksY; ++by)
        for (int bx = 0; bx < blocksX; ++bx) {
            const int w = std::min(blockSize, image.width - bx * blockSize);
            const int h = std::min(blockSize, image.height - by * blockSize);
            sums[static_cast<size_t>(by) * blocksX + bx] /= static_cast<double>(w) * h;
        }
    imageMean = total / (static_cast<double>(image.width) * image.height);
    return sums;
}

double srgbToLinear(double c) {
    return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
}

} // namespace

BlockRatioResult blockLuminanceRatio(const Image& test, const Image& reference, int blockSize) {
    detail::requireSameSize(test, reference, "block luminance ratio");
    if (blockSize < 1)
        throw UserError("block luminance ratio: block size " + std::to_string(blockSize) +
                        "; expected at least 1 pixel");
    BlockRatioResult r;
    r.blockSize = blockSize;
    r.blocksX = (test.width + blockSize - 1) / blockSize;
    r.blocksY = (test.height + blockSize - 1) / blockSize;
    double meanTest = 0.0, meanReference = 0.0;
    const std::vector<double> lt = blockMeans(test, blockSize, r.blocksX, r.blocksY, meanTest);
    const std::vector<double> lr = blockMeans(reference, blockSize, r.blocksX, r.blocksY, meanReference);
    r.floor = kBlockFloorFraction * (meanReference > 0.0 ? meanReference : meanTest);
    r.log2Ratio.assign(lt.size(), std::numeric_limits<double>::quiet_NaN());
    int within = 0;
    double sumLog = 0.0, sumRelative = 0.0;
    for (size_t i = 0; i < lt.size(); ++i) {
        if (lt[i] <= r.floor && lr[i] <= r.floor) {
            ++r.darkBlocks;
            continue;
        }
        ++r.litBlocks;
        const double ratio = std::max(lt[i], r.floor) / std::max(lr[i], r.floor);
        r.log2Ratio[i] = std::log2(ratio);
        sumLog += std::fabs(r.log2Ratio[i]);
        sumRelative += std::fabs(ratio - 1.0);
        if (std::fabs(ratio - 1.0) <= kBlockTolerance) ++within;
    }
    if (r.litBlocks > 0) {
        r.withinShare = static_cast<double>(within) / r.litBlocks;
        r.meanAbsLog2 = sumLog / r.litBlocks;
        r.meanAbsRelative = sumRelative / r.litBlocks;
    }
    return r;
}

SrgbColor blockRatioColor(double log2Ratio) {
    if (std::isnan(log2Ratio)) return {0.5, 0.5, 0.5};
    const double t = std::min(std::fabs(log2Ratio), 1.0);
    if (log2Ratio > 0.0) return {1.0, 1.0 - t, 1.0 - t};
    return {1.0 - t, 1.0 - t, 1.0};
}

Image blockRatioHeatMap(const BlockRatioResult& blocks, int width, int height) {
    if (width < 1 || height < 1 || blocks.blocksX != (width + blocks.blockSize - 1) / blocks.blockSize ||
        blocks.blocksY != (height + blocks.blockSize - 1) / blocks.blockSize ||
        blocks.log2Ratio.size() != static_cast<size_t>(blocks.blocksX) * blocks.blocksY)
        throw UserError("block ratio heat map: " + std::to_string(width) + "x" + std::to_string(height) +
                        " does not match " + std::to_string(blocks.blocksX) + "x" + std::to_string(blocks.blocksY) +
                        " blocks of " + std::to_string(blocks.blockSize) + " px");
    Image out(width, height);
    for (int y = 0; y < height; ++y)
        for (int x = 0; x < width; ++x) {
            const SrgbColor c = blockRatioColor(
                blocks.log2Ratio[static_cast<size_t>(y / blocks.blockSize) * blocks.blocksX + x / blocks.blockSize]);
            float* p = out.at(x, y);
            p[0] = static_cast<float>(srgbToLinear(c.r));
            p[1] = static_cast<float>(srgbToLinear(c.g));
            p[2] = static_cast<float>(srgbToLinear(c.b));
            p[3] = 1.0f;
        }
    return out;
}

} // namespace vitrine::compare
