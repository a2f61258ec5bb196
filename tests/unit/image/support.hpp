#pragma once

#include "core/base/error.hpp"
#include "core/image/image.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace vitrine::test {

// A fresh directory per test (ctest runs tests as parallel processes), removed afterwards.
class ImageTest : public ::testing::Test {
protected:
    void SetUp() override;
    void TearDown() override;
    std::filesystem::path file(const std::string& name) const { return mDir / name; }

    std::filesystem::path mDir;
};

// The sRGB OETF and its inverse from IEC 61966-2-1, written out independently of OCIO.
inline double srgbEncode(double linear) {
    return linear <= 0.0031308 ? 12.92 * linear : 1.055 * std::pow(linear, 1.0 / 2.4) - 0.055;
}
inline double srgbDecode(double encoded) {
    return encoded <= 0.04045 ? encoded / 12.92 : std::pow((encoded + 0.055) / 1.055, 2.4);
}

// A deterministic image whose channels all differ, so that swapped or dropped channels show up.
Image patternImage(int width, int height, float scale, float offset);

// Writes a 16-bit RGBA PNG with stored (uncompressed) deflate blocks; stb_image_write has no 16-bit output.
void writePng16(const std::filesystem::path& path, int width, int height, const std::vector<uint16_t>& rgba);

void writeBytes(const std::filesystem::path& path, const std::vector<unsigned char>& bytes);
std::vector<unsigned char> readBytes(const std::filesystem::path& path);

// Runs call and expects a UserError whose message contains every one of needles.
template <typename Call> void expectUserError(Call&& call, const std::vector<std::string>& needles) {
    try {
        call();
        ADD_FAILURE() << "expected a UserError, nothing was thrown";
    } catch (const UserError& e) {
        const std::string message = e.what();
        for (const std::string& needle : needles)
            EXPECT_NE(message.find(needle), std::string::npos)
                << "message '" << message << "' lacks '" << needle << "'";
    }
}

} // namespace vitrine::test
