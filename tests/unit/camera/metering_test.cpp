// The histogram statistic camera.physical reads back (nodes/camera/metering.cpp), on hand-made histograms.
#include "nodes/camera/metering.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace vitrine::camera {
namespace {

TEST(Metering, FlatHistogramGivesItsMean) {
    std::vector<glm::vec2> bins(64, glm::vec2(0.0f));
    bins[30] = {100.0f, 100.0f * 8.3f}; // every pixel at log2 Y = 8.3
    EXPECT_NEAR(histogramMeanLog2(bins, 0.1f, 0.95f), 8.3f, 1e-6f);
    EXPECT_NEAR(histogramMeanLog2(bins, 0.0f, 1.0f), 8.3f, 1e-6f);
}

// Three bins of weight 10 each (means 0, 5, 10): the darkest 10 % (3 of bin 0) and the brightest 5 % (1.5 of
// bin 2) are dropped: (7·0 + 10·5 + 8.5·10) / 25.5.
TEST(Metering, PercentilesTrimBothEnds) {
    std::vector<glm::vec2> bins(64, glm::vec2(0.0f));
    bins[1] = {10.0f, 0.0f};
    bins[20] = {10.0f, 50.0f};
    bins[40] = {10.0f, 100.0f};
    EXPECT_NEAR(histogramMeanLog2(bins, 0.1f, 0.95f), (50.0f + 85.0f) / 25.5f, 1e-5f);
    EXPECT_NEAR(histogramMeanLog2(bins, 0.0f, 1.0f), 5.0f, 1e-5f);
    EXPECT_NEAR(histogramMeanLog2(bins, 0.0f, 1.0f / 3.0f), 0.0f, 1e-5f);
}

TEST(Metering, EmptyHistogramIsNaN) {
    std::vector<glm::vec2> bins(64, glm::vec2(0.0f));
    EXPECT_TRUE(std::isnan(histogramMeanLog2(bins, 0.1f, 0.95f)));
}

} // namespace
} // namespace vitrine::camera
