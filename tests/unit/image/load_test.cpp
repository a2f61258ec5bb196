#include "core/image/io.hpp"

#include "support.hpp"

#include <stb_image_write.h>

namespace vitrine::test {
namespace {

using LoadTest = ImageTest;

TEST_F(LoadTest, SixteenBitPngKeepsItsPrecision) {
    const std::vector<uint16_t> samples = {0, 1, 32768, 65535, 12345, 54321, 65534, 256};
    writePng16(file("deep.png"), 2, 1, samples);

    const Image raw = loadImage(file("deep.png"), "Raw");
    ASSERT_EQ(raw.width, 2);
    ASSERT_EQ(raw.height, 1);
    for (size_t i = 0; i < samples.size(); ++i)
        EXPECT_FLOAT_EQ(raw.pixels[i], samples[i] / 65535.0f) << i;

    const Image decoded = loadImage(file("deep.png"));
    for (size_t i = 0; i < samples.size(); ++i) {
        const double stored = samples[i] / 65535.0;
        EXPECT_NEAR(decoded.pixels[i], i % 4 == 3 ? stored : srgbDecode(stored), 1e-5) << i;
    }
}

TEST_F(LoadTest, EightBitGreyPngIsDecodedFromSrgbUnlessRaw) {
    const unsigned char grey[] = {0, 10, 128, 255};
    ASSERT_TRUE(stbi_write_png(file("grey.png").string().c_str(), 2, 2, 1, grey, 2));

    const Image raw = loadImage(file("grey.png"), "Raw");
    const Image decoded = loadImage(file("grey.png"), "auto");
    const Image named = loadImage(file("grey.png"), "sRGB - Texture");
    for (int i = 0; i < 4; ++i) {
        for (int c = 0; c < 3; ++c) {
            EXPECT_FLOAT_EQ(raw.pixels[i * 4 + c], grey[i] / 255.0f);
            EXPECT_NEAR(decoded.pixels[i * 4 + c], srgbDecode(grey[i] / 255.0), 1e-5);
        }
        EXPECT_EQ(raw.pixels[i * 4 + 3], 1.0f);
        EXPECT_EQ(decoded.pixels[i * 4 + 3], 1.0f);
    }
    EXPECT_EQ(named.pixels, decoded.pixels);
}

TEST_F(LoadTest, JpegIsDecodedFromSrgb) {
    std::vector<unsigned char> rgb(16 * 16 * 3);
    for (size_t i = 0; i < rgb.size(); i += 3)
        rgb[i] = 200, rgb[i + 1] = 100, rgb[i + 2] = 30;
    ASSERT_TRUE(stbi_write_jpg(file("flat.JPG").string().c_str(), 16, 16, 3, rgb.data(), 100));

    const Image image = loadImage(file("flat.JPG"));
    ASSERT_EQ(image.width, 16);
    for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(srgbEncode(image.at(7, 9)[c]), rgb[c] / 255.0, 2.0 / 255) << "channel " << c;
}

TEST_F(LoadTest, RadianceHdrIsAlreadyLinear) {
    const std::vector<float> rgb = {0.001f, 0.002f, 0.003f, 1.0f, 0.5f, 0.25f, 100.0f, 40.0f, 7.0f};
    ASSERT_TRUE(stbi_write_hdr(file("sky.hdr").string().c_str(), 3, 1, 3, rgb.data()));

    const Image image = loadImage(file("sky.hdr"));
    ASSERT_EQ(image.width, 3);
    for (int x = 0; x < 3; ++x) {
        const float largest = std::max({rgb[x * 3], rgb[x * 3 + 1], rgb[x * 3 + 2]});
        for (int c = 0; c < 3; ++c) // RGBE: an 8-bit mantissa shared with the largest channel
            EXPECT_NEAR(image.at(x, 0)[c], rgb[x * 3 + c], largest / 128.0f) << "pixel " << x << " channel " << c;
        EXPECT_EQ(image.at(x, 0)[3], 1.0f);
    }
}

TEST_F(LoadTest, NamedColourSpaceIsConvertedToSceneLinear) {
    Image acescg(1, 1);
    acescg.at(0, 0)[0] = 1.0f; // the AP1 red primary
    writeExr(file("ap1.exr"), acescg, ExrPixelType::Float);
    const Image linear = loadImage(file("ap1.exr"), "ACEScg");
    EXPECT_NEAR(linear.at(0, 0)[0], 1.70505, 1e-4);
    EXPECT_NEAR(linear.at(0, 0)[1], -0.13026, 1e-4);
    EXPECT_NEAR(linear.at(0, 0)[2], -0.02400, 1e-4);
}

TEST_F(LoadTest, MissingFilesAreUserErrors) {
    expectUserError([&] { loadImage(file("absent.png")); }, {"absent.png", "not found"});
    expectUserError([&] { loadImage(file("absent.exr")); }, {"absent.exr", "not found"});
    expectUserError([&] { loadExrLayer(file("absent2.exr"), "x"); }, {"absent2.exr", "not found"});
    expectUserError([&] { loadImage(mDir / "folder.png"); }, {"folder.png"});
}

TEST_F(LoadTest, UnknownExtensionIsAUserError) {
    writeBytes(file("picture.tiff"), {1, 2, 3});
    expectUserError([&] { loadImage(file("picture.tiff")); }, {"picture.tiff", "'.tiff'", ".exr"});
    expectUserError([&] { loadImage(file("noextension")); }, {"noextension", "extension"});
}

TEST_F(LoadTest, UnknownColourSpaceIsAUserErrorNamingTheFile) {
    const unsigned char pixel[] = {1, 2, 3, 4};
    ASSERT_TRUE(stbi_write_png(file("tex.png").string().c_str(), 1, 1, 4, pixel, 4));
    expectUserError([&] { loadImage(file("tex.png"), "Adobe RGB"); }, {"tex.png", "'Adobe RGB'", "'ACEScg'"});
}

TEST_F(LoadTest, DamagedFilesAreUserErrors) {
    const Image image = patternImage(64, 64, 1.0f, 0.0f);
    writePng(file("whole.png"), image);
    std::vector<unsigned char> bytes = readBytes(file("whole.png"));
    bytes.resize(bytes.size() / 2);
    writeBytes(file("truncated.png"), bytes);
    expectUserError([&] { loadImage(file("truncated.png")); }, {"truncated.png", "PNG"});

    writeBytes(file("garbage.png"), std::vector<unsigned char>(200, 0x42));
    expectUserError([&] { loadImage(file("garbage.png")); }, {"garbage.png"});
    writeBytes(file("empty.jpg"), {});
    expectUserError([&] { loadImage(file("empty.jpg")); }, {"empty.jpg"});

    std::filesystem::copy_file(file("whole.png"), file("renamed.hdr"));
    expectUserError([&] { loadImage(file("renamed.hdr")); }, {"renamed.hdr", "Radiance"});
}

} // namespace
} // namespace vitrine::test
