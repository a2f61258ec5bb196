#include "core/image/io.hpp"

#include "support.hpp"

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>
#include <half.h>

#include <cstring>
#include <limits>
#include <map>
#include <random>

namespace vitrine::test {
namespace {

using ExrTest = ImageTest;

// Values over the whole float range, signs, zero, denormals and infinity, not just [0, 1].
Image randomImage(int width, int height, unsigned seed, float minMagnitude, float maxMagnitude) {
    std::mt19937 random(seed);
    std::uniform_real_distribution<float> exponent(std::log2(minMagnitude), std::log2(maxMagnitude));
    std::bernoulli_distribution negative(0.3);
    Image image(width, height);
    for (float& value : image.pixels)
        value = (negative(random) ? -1.0f : 1.0f) * std::exp2(exponent(random));
    return image;
}

std::map<std::string, Imf::PixelType> channelTypes(const std::filesystem::path& path) {
    Imf::InputFile file(path.string().c_str());
    std::map<std::string, Imf::PixelType> types;
    for (auto it = file.header().channels().begin(); it != file.header().channels().end(); ++it)
        types[it.name()] = it.channel().type;
    return types;
}

TEST_F(ExrTest, FloatRoundTripIsBitExact) {
    Image image = randomImage(37, 23, 1, 1e-30f, 1e30f); // odd sizes: partial ZIP blocks and rows
    image.pixels[0] = 0.0f;
    image.pixels[1] = -0.0f;
    image.pixels[2] = std::numeric_limits<float>::denorm_min() * 3;
    image.pixels[3] = std::numeric_limits<float>::infinity();
    writeExr(file("float.exr"), image, ExrPixelType::Float);

    EXPECT_EQ(channelTypes(file("float.exr")).at("R"), Imf::FLOAT);
    for (const Image& loaded : {loadImage(file("float.exr")), loadExrLayer(file("float.exr"), "")}) {
        ASSERT_EQ(loaded.width, image.width);
        ASSERT_EQ(loaded.height, image.height);
        EXPECT_EQ(std::memcmp(loaded.pixels.data(), image.pixels.data(), image.pixels.size() * sizeof(float)), 0);
    }
}

TEST_F(ExrTest, HalfRoundTripIsWithinHalfPrecision) {
    const Image image = randomImage(19, 31, 2, 1e-3f, 6e4f);
    writeExr(file("half.exr"), image, ExrPixelType::Half);

    EXPECT_EQ(channelTypes(file("half.exr")).at("A"), Imf::HALF);
    const Image loaded = loadImage(file("half.exr"));
    ASSERT_EQ(loaded.pixels.size(), image.pixels.size());
    for (size_t i = 0; i < image.pixels.size(); ++i)
        ASSERT_NEAR(loaded.pixels[i], image.pixels[i], 1e-3 * std::abs(image.pixels[i])) << "sample " << i;
}

TEST_F(ExrTest, MultiLayerRoundTripKeepsNamesAndValues) {
    const Image beauty = patternImage(8, 6, 4.0f, 0.0f);
    const Image diffuse = patternImage(8, 6, 1.0f, 0.25f);
    const Image normal = patternImage(8, 6, -2.0f, 1.0f);
    writeExr(file("layers.exr"), {{"", &beauty}, {"diffuse", &diffuse}, {"normal.world", &normal}},
             ExrPixelType::Float);

    const auto types = channelTypes(file("layers.exr"));
    for (const char* channel : {"R", "A", "diffuse.R", "diffuse.A", "normal.world.B"})
        EXPECT_TRUE(types.count(channel)) << "no channel " << channel; // the Nuke/Blender naming

    const auto layers = readExrLayers(file("layers.exr"));
    ASSERT_EQ(layers.size(), 3u);
    const std::map<std::string, const Image*> expected = {
        {"", &beauty}, {"diffuse", &diffuse}, {"normal.world", &normal}};
    EXPECT_EQ(layers[0].first, ""); // the unnamed layer comes first
    for (const auto& [name, image] : layers) {
        ASSERT_TRUE(expected.count(name)) << "unexpected layer '" << name << "'";
        EXPECT_EQ(image.pixels, expected.at(name)->pixels) << "layer '" << name << "'";
    }
    EXPECT_EQ(loadExrLayer(file("layers.exr"), "diffuse").pixels, diffuse.pixels);
    EXPECT_EQ(loadImage(file("layers.exr")).pixels, beauty.pixels);
}

// Writes float planes as channels of the given type (FLOAT or HALF), as other tools would.
void writePlanes(const std::filesystem::path& path, const Imath::Box2i& dataWindow,
                 const std::map<std::string, std::vector<float>>& planes, Imf::PixelType type) {
    Imf::Header header(Imath::Box2i({0, 0}, dataWindow.max), dataWindow);
    Imf::FrameBuffer buffer;
    std::vector<std::vector<half>> halfPlanes;
    for (const auto& [name, plane] : planes) {
        header.channels().insert(name, Imf::Channel(type));
        const void* data = plane.data();
        if (type == Imf::HALF) data = halfPlanes.emplace_back(plane.begin(), plane.end()).data();
        buffer.insert(name, Imf::Slice::Make(type, data, dataWindow));
    }
    Imf::OutputFile out(path.string().c_str(), header);
    out.setFrameBuffer(buffer);
    out.writePixels(dataWindow.max.y - dataWindow.min.y + 1);
}

TEST_F(ExrTest, LoadImagePicksTheFirstColourLayerWhenThereIsNoUnnamedOne) {
    const std::map<std::string, std::vector<float>> planes = {
        {"a_mask.Z", {0.5f, 0.25f}}, {"beauty.R", {1, 2}}, {"beauty.G", {3, 4}}, {"beauty.B", {5, 6}}};
    writePlanes(file("named.exr"), Imath::Box2i({0, 0}, {1, 0}), planes, Imf::FLOAT);
    // "a_mask" sorts first but is no colour layer.
    EXPECT_EQ(loadImage(file("named.exr")).pixels, (std::vector<float>{1, 3, 5, 1, 2, 4, 6, 1}));
    // A lone channel reads as grey.
    EXPECT_EQ(loadExrLayer(file("named.exr"), "a_mask").pixels,
              (std::vector<float>{0.5f, 0.5f, 0.5f, 1, 0.25f, 0.25f, 0.25f, 1}));
}

// Files vitrine's writer never produces but other tools do: a luminance-only half file with a
// data window that does not start at the origin, and 32-bit uint RGB.
TEST_F(ExrTest, ReadsLuminanceAndUintChannels) {
    const int width = 3;
    const int height = 2;
    const std::vector<float> luminance = {0.5f, 1.0f, 2.0f, 4.0f, 8.0f, 0.125f};
    const std::map<std::string, std::vector<float>> planes = {{"Y", luminance}};
    writePlanes(file("y.exr"), Imath::Box2i({4, 5}, {4 + width - 1, 5 + height - 1}), planes, Imf::HALF);
    const Image grey = loadImage(file("y.exr"));
    ASSERT_EQ(grey.width, width);
    ASSERT_EQ(grey.height, height);
    for (int i = 0; i < width * height; ++i) {
        for (int c = 0; c < 3; ++c)
            EXPECT_EQ(grey.pixels[i * 4 + c], luminance[i]) << "pixel " << i;
        EXPECT_EQ(grey.pixels[i * 4 + 3], 1.0f);
    }

    Imf::Header uintHeader(2, 1);
    std::vector<uint32_t> samples = {1, 2, 3, 70000, 0, 9};
    Imf::FrameBuffer uintBuffer;
    for (int c = 0; c < 3; ++c) {
        const std::string name(1, "RGB"[c]);
        uintHeader.channels().insert(name, Imf::Channel(Imf::UINT));
        uintBuffer.insert(name, Imf::Slice(Imf::UINT, reinterpret_cast<char*>(samples.data() + c), 12, 24));
    }
    {
        Imf::OutputFile out(file("uint.exr").string().c_str(), uintHeader);
        out.setFrameBuffer(uintBuffer);
        out.writePixels(1);
    }
    const Image ids = loadImage(file("uint.exr"));
    EXPECT_EQ(ids.pixels, (std::vector<float>{1, 2, 3, 1, 70000, 0, 9, 1}));
}

TEST_F(ExrTest, LayersOfDifferentSizesOrNamesAreUserErrors) {
    const Image a(4, 4);
    const Image b(4, 5);
    expectUserError(
        [&] {
            writeExr(file("sizes.exr"), {{"", &a}, {"b", &b}}, ExrPixelType::Half);
        },
        {"sizes.exr", "4x5", "same size"});
    expectUserError(
        [&] {
            writeExr(file("names.exr"), {{"x", &a}, {"x", &a}}, ExrPixelType::Half);
        },
        {"names.exr", "'x'"});
    EXPECT_FALSE(std::filesystem::exists(file("sizes.exr")));
}

TEST_F(ExrTest, UnknownLayerIsAUserErrorListingTheLayers) {
    const Image image(2, 2);
    writeExr(file("one.exr"), {{"diffuse", &image}}, ExrPixelType::Half);
    expectUserError([&] { loadExrLayer(file("one.exr"), "specular"); }, {"one.exr", "'specular'", "'diffuse'"});
}

TEST_F(ExrTest, TruncatedOrGarbageFilesAreUserErrors) {
    writeExr(file("whole.exr"), randomImage(64, 64, 3, 1e-3f, 1e3f), ExrPixelType::Float); // noise: no tiny file
    const std::vector<unsigned char> bytes = readBytes(file("whole.exr"));
    for (double kept : {0.95, 0.1}) { // cut in the pixel data, cut in the header or offsets
        writeBytes(file("truncated.exr"),
                   std::vector<unsigned char>(bytes.begin(), bytes.begin() + kept * bytes.size()));
        expectUserError([&] { loadImage(file("truncated.exr")); }, {"truncated.exr"});
        expectUserError([&] { readExrLayers(file("truncated.exr")); }, {"truncated.exr"});
    }

    writeBytes(file("garbage.exr"), std::vector<unsigned char>(100, 'x'));
    expectUserError([&] { loadImage(file("garbage.exr")); }, {"garbage.exr"});
}

TEST_F(ExrTest, WritingIntoAMissingDirectoryIsAUserError) {
    const Image image(2, 2);
    expectUserError([&] { writeExr(file("nowhere/out.exr"), image, ExrPixelType::Half); }, {"out.exr", "nowhere"});
}

} // namespace
} // namespace vitrine::test
