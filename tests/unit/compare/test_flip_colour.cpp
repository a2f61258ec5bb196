#include "core/compare/metrics.hpp"

#include "flip_reference.hpp"
#include "test_images.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

// LDR-FLIP on coloured inputs against exact values from flip_reference.hpp, a float64 model of the paper's colour
// pipeline. The grey tests in test_flip.cpp cannot see the chroma path (a = b = 0 there): these can.
namespace vitrine::compare {
namespace {

using testing::colourPairs;
using testing::constantImage;
using testing::Rgb;

// What the Image holds, so that the model sees exactly the values ldrFlip() compares.
Rgb asFloat(const Rgb& c) {
    return {static_cast<float>(c[0]), static_cast<float>(c[1]), static_cast<float>(c[2])};
}

Image uniform(const Rgb& c, int size) {
    return constantImage(size, size, float(c[0]), float(c[1]), float(c[2]));
}

TEST(LdrFlipColour, ReferencePairsAreWhatTheyClaim) {
    // The model itself: equal-luminance pairs differ in chroma only, and the pairs cover both parts of the error
    // redistribution (below p_t = 0.95: the linear part; above: the compressed part).
    int compressed = 0;
    for (const auto& [name, reference, test] : colourPairs()) {
        const testing::Lab r = testing::huntLab(reference), t = testing::huntLab(test);
        if (std::string(name).find("equal_luminance") != std::string::npos) {
            EXPECT_NEAR(r.l, t.l, 1e-9) << name;
            EXPECT_GT(std::hypot(r.a - t.a, r.b - t.b), 10.0) << name;
        }
        compressed += testing::uniformPairFlip(reference, test) > 0.95;
    }
    EXPECT_GE(compressed, 2);
    EXPECT_LE(compressed, 4);
}

TEST(LdrFlipColour, UniformColourPairsMatchThePaperPipeline) {
    // 24 x 24 is wider than the CSF filters (radius 10 at 67 ppd), so (12, 12) sees no border; on uniform images the
    // clamp-to-edge border changes nothing anyway, so every pixel must have the same value.
    constexpr int kSize = 24;
    for (const auto& [name, referenceColour, testColour] : colourPairs()) {
        const Rgb reference = asFloat(referenceColour), test = asFloat(testColour);
        const double expected = testing::uniformPairFlip(reference, test);
        const FlipResult r = ldrFlip(uniform(reference, kSize), uniform(test, kSize));
        const double measured = r.errorMap.at(kSize / 2, kSize / 2)[0];
        std::printf("%-32s expected %.6f  ldrFlip %.6f  (%+.1e)\n", name, expected, measured, measured - expected);
        EXPECT_NEAR(measured, expected, 1e-6) << name;
        EXPECT_NEAR(r.minimum, r.maximum, 1e-6) << name;
        EXPECT_NEAR(r.mean, expected, 1e-6) << name;
    }
}

} // namespace
} // namespace vitrine::compare
