#include "core/image/color.hpp"

#include "support.hpp"

#include <algorithm>
#include <array>
#include <cstdlib>
#include <fstream>
#include <unistd.h>

namespace vitrine::test {
namespace {

using ColorTest = ImageTest;

bool contains(const std::vector<std::string>& names, const std::string& name) {
    return std::find(names.begin(), names.end(), name) != names.end();
}

TEST_F(ColorTest, BuiltinConfigHasTheAgreedSpacesDisplaysAndViews) {
    const ColorConfig& config = ColorConfig::builtin();
    for (const char* name : {"Linear Rec.709 (sRGB)", "ACEScg", "ACES2065-1", "sRGB - Texture", "Raw"})
        EXPECT_TRUE(contains(config.colorSpaces(), name)) << name;
    EXPECT_TRUE(config.hasColorSpace("scene_linear"));
    EXPECT_FALSE(config.hasColorSpace("Linear Rec.2020"));
    EXPECT_TRUE(contains(config.displays(), "sRGB"));
    EXPECT_TRUE(contains(config.views("sRGB"), "Standard"));
    EXPECT_TRUE(contains(config.views("sRGB"), "Raw"));
}

TEST_F(ColorTest, StandardViewIsThePlainSrgbEncoding) {
    const std::array<float, 12> values = {0.0f,  0.0005f, 0.002f, 0.003f, 0.0031308f, 0.0035f,
                                          0.01f, 0.0452f, 0.18f,  0.5f,   0.9f,       1.0f};
    Image linear(static_cast<int>(values.size()), 1);
    for (size_t i = 0; i < values.size(); ++i) {
        // Each channel gets a different value so that a channel mix-up (a matrix) would show.
        float* pixel = linear.at(static_cast<int>(i), 0);
        pixel[0] = values[i];
        pixel[1] = values[(i + 4) % values.size()];
        pixel[2] = values[(i + 8) % values.size()];
        pixel[3] = 0.25f;
    }
    const Image display = ColorConfig::builtin().toDisplay(linear);
    ASSERT_EQ(display.width, linear.width);
    for (size_t i = 0; i < linear.pixels.size(); ++i) {
        const double expected = i % 4 == 3 ? 0.25 : srgbEncode(linear.pixels[i]);
        // OCIO makes the curve continuous (break 0.00304, slope 12.923): within 4e-6 of the standard.
        EXPECT_NEAR(display.pixels[i], expected, 1e-5) << "sample " << i << ", linear " << linear.pixels[i];
    }
}

TEST_F(ColorTest, RawViewLeavesValuesAlone) {
    const Image linear = patternImage(5, 3, 2.0f, -0.5f);
    const Image display = ColorConfig::builtin().toDisplay(linear, "scene_linear", "sRGB", "Raw");
    EXPECT_EQ(display.pixels, linear.pixels);
}

// Columns of the AP1 → linear Rec.709 matrix (Bradford D60 → D65), as published with ACES and
// reproduced by colour-science's RGB_to_RGB(ACEScg, sRGB, 'Bradford').
constexpr double kAp1ToRec709[3][3] = {
    {1.70505, -0.62179, -0.08326}, {-0.13026, 1.14080, -0.01055}, {-0.02400, -0.12897, 1.15297}};

// AP0 → AP1 from aces-dev's ACESlib.Transform_Common.ctl (AP0_2_AP1_MAT).
constexpr double kAp0ToAp1[3][3] = {{1.4514393161, -0.2365107469, -0.2149285693},
                                    {-0.0765537734, 1.1762296998, -0.0996759264},
                                    {0.0083161484, -0.0060324498, 0.9977163014}};

void expectMatrix(const std::string& src, const std::string& dst, const double (&matrix)[3][3], double tolerance) {
    Image primaries(3, 1);
    for (int i = 0; i < 3; ++i) {
        primaries.at(i, 0)[i] = 1.0f;
        primaries.at(i, 0)[3] = 0.5f;
    }
    const Image converted = ColorConfig::builtin().convert(primaries, src, dst);
    for (int column = 0; column < 3; ++column) {
        for (int row = 0; row < 3; ++row)
            EXPECT_NEAR(converted.at(column, 0)[row], matrix[row][column], tolerance)
                << src << " primary " << column << " → " << dst << " channel " << row;
        EXPECT_EQ(converted.at(column, 0)[3], 0.5f);
    }
}

TEST_F(ColorTest, AcescgPrimariesMapThroughThePublishedMatrix) {
    expectMatrix("ACEScg", "Linear Rec.709 (sRGB)", kAp1ToRec709, 1e-4);
}

TEST_F(ColorTest, Aces2065PrimariesMapThroughThePublishedMatrix) {
    expectMatrix("ACES2065-1", "ACEScg", kAp0ToAp1, 1e-5);
}

TEST_F(ColorTest, TextureDecodingIsTheInverseSrgbCurve) {
    Image encoded(4, 1);
    const float samples[] = {0.0f, 0.02f, 0.5f, 1.0f};
    for (int i = 0; i < 4; ++i)
        std::fill_n(encoded.at(i, 0), 4, samples[i]);
    const Image linear = ColorConfig::builtin().convert(encoded, "sRGB - Texture", "scene_linear");
    for (int i = 0; i < 4; ++i) {
        for (int c = 0; c < 3; ++c)
            EXPECT_NEAR(linear.at(i, 0)[c], srgbDecode(samples[i]), 1e-5) << i;
        EXPECT_EQ(linear.at(i, 0)[3], samples[i]);
    }
}

TEST_F(ColorTest, UnknownNamesAreUserErrors) {
    const ColorConfig& config = ColorConfig::builtin();
    const Image image(2, 2);
    expectUserError([&] { config.convert(image, "ACEScc", "scene_linear"); }, {"ACEScc", "config.ocio"});
    expectUserError([&] { config.toDisplay(image, "scene_linear", "P3", "Standard"); }, {"'P3'", "'sRGB'"});
    expectUserError([&] { config.toDisplay(image, "scene_linear", "sRGB", "Filmic"); }, {"'Filmic'", "'Standard'"});
}

TEST_F(ColorTest, MissingOrBrokenConfigFileIsAUserError) {
    expectUserError([&] { ColorConfig config(file("absent.ocio")); }, {"absent.ocio", "not found"});
    std::ofstream(file("broken.ocio")) << "ocio_profile_version: 2\ncolorspaces: [\n";
    expectUserError([&] { ColorConfig config(file("broken.ocio")); }, {"broken.ocio"});
}

// builtin() is loaded once per process, so the override is checked in a fresh one.
TEST(ColorEnvTest, VitrineOcioOverridesTheShippedConfig) {
    GTEST_FLAG_SET(death_test_style, "threadsafe"); // re-executes the binary: builtin() not loaded yet
    EXPECT_EXIT(
        {
            const std::filesystem::path copy =
                std::filesystem::temp_directory_path() / ("vitrine-image-env-" + std::to_string(getpid()) + ".ocio");
            std::filesystem::copy_file(std::filesystem::path(VITRINE_DATA_DIR) / "ocio" / "config.ocio", copy);
            setenv("VITRINE_OCIO", copy.c_str(), 1);
            const bool used = ColorConfig::builtin().file() == copy;
            std::filesystem::remove(copy);
            std::exit(used ? 0 : 1);
        },
        ::testing::ExitedWithCode(0), "");
}

} // namespace
} // namespace vitrine::test
