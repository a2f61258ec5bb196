#include "core/image/io.hpp"

#include "support.hpp"

#include <algorithm>

namespace vitrine::test {
namespace {

using PngTest = ImageTest;

TEST_F(PngTest, WriteThenLoadRoundTripsWithinOneStepAfterSrgb) {
    // Every 8-bit code, values between codes, out-of-range values (clamped) and an alpha ramp.
    Image image(256, 3);
    for (int x = 0; x < 256; ++x) {
        image.at(x, 0)[0] = static_cast<float>(srgbDecode(x / 255.0));
        image.at(x, 0)[1] = static_cast<float>(srgbDecode((x + 0.4) / 255.0));
        image.at(x, 0)[2] = static_cast<float>(x) / 255.0f;
        image.at(x, 1)[0] = static_cast<float>(x) / 64.0f - 1.0f;
        image.at(x, 1)[1] = 1.0f - static_cast<float>(x) / 200.0f;
        image.at(x, 1)[2] = static_cast<float>(x * x) / 30000.0f;
        for (int y = 0; y < 3; ++y)
            image.at(x, y)[3] = static_cast<float>(x) / 255.0f * 1.2f - 0.1f;
    }
    writePng(file("round.png"), image);
    const Image loaded = loadImage(file("round.png"));
    ASSERT_EQ(loaded.width, image.width);
    ASSERT_EQ(loaded.height, image.height);

    for (size_t i = 0; i < image.pixels.size(); ++i) {
        const double original = std::clamp(static_cast<double>(image.pixels[i]), 0.0, 1.0);
        if (i % 4 == 3) {
            EXPECT_NEAR(loaded.pixels[i], original, 0.5 / 255 + 1e-6) << "alpha of pixel " << i / 4;
        } else {
            // Rounding to the nearest code is within half a step; OCIO's curve adds ~1e-5.
            EXPECT_NEAR(srgbEncode(std::max(0.0f, loaded.pixels[i])), srgbEncode(original), 0.5 / 255 + 1e-4)
                << "sample " << i;
        }
    }
}

TEST_F(PngTest, EncodeGivesTheBytesWriteStores) {
    const Image image = patternImage(7, 5, 1.5f, 0.0f);
    const std::vector<unsigned char> png = encodePng(image);
    ASSERT_GT(png.size(), 8u);
    const std::vector<unsigned char> signature = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
    EXPECT_EQ(std::vector<unsigned char>(png.begin(), png.begin() + 8), signature);
    writePng(file("same.png"), image);
    EXPECT_EQ(readBytes(file("same.png")), png);
}

TEST_F(PngTest, RawViewWritesValuesWithoutTheCurve) {
    Image image(1, 1);
    std::fill_n(image.at(0, 0), 4, 0.2f);
    writePng(file("raw.png"), image, ColorConfig::builtin(), "sRGB", "Raw");
    const Image loaded = loadImage(file("raw.png"), "Raw");
    EXPECT_FLOAT_EQ(loaded.at(0, 0)[0], 51.0f / 255.0f);
}

TEST_F(PngTest, NanAndInfinityAreClamped) {
    Image image(2, 1);
    std::fill_n(image.at(0, 0), 4, std::numeric_limits<float>::quiet_NaN());
    std::fill_n(image.at(1, 0), 4, std::numeric_limits<float>::infinity());
    writePng(file("nan.png"), image);
    const Image loaded = loadImage(file("nan.png"), "Raw");
    EXPECT_EQ(loaded.pixels, (std::vector<float>{0, 0, 0, 0, 1, 1, 1, 1}));
}

TEST_F(PngTest, UnwritablePathsAreUserErrors) {
    const Image image(2, 2);
    expectUserError([&] { writePng(file("missing/dir/out.png"), image); }, {"out.png", "does not exist"});
    std::filesystem::create_directory(file("taken.png"));
    expectUserError([&] { writePng(file("taken.png"), image); }, {"taken.png"});
}

} // namespace
} // namespace vitrine::test
