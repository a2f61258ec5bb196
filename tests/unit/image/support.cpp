#include "support.hpp"

#include <algorithm>
#include <fstream>
#include <iterator>
#include <unistd.h>

namespace vitrine::test {

void ImageTest::SetUp() {
    const ::testing::TestInfo* info = ::testing::UnitTest::GetInstance()->current_test_info();
    mDir = std::filesystem::temp_directory_path() / ("vitrine-image-" + std::string(info->test_suite_name()) + "-" +
                                                     info->name() + "-" + std::to_string(getpid()));
    std::filesystem::remove_all(mDir);
    std::filesystem::create_directories(mDir);
}

void ImageTest::TearDown() {
    std::filesystem::remove_all(mDir);
}

Image patternImage(int width, int height, float scale, float offset) {
    Image image(width, height);
    for (int y = 0; y < height; ++y) {
        for (int x = 0; x < width; ++x) {
            float* pixel = image.at(x, y);
            pixel[0] = offset + scale * static_cast<float>(x + 1) / static_cast<float>(width);
            pixel[1] = offset + scale * static_cast<float>(y + 1) / static_cast<float>(height);
            pixel[2] = offset + scale * 0.5f * static_cast<float>((x * 7 + y * 3) % 11) / 11.0f;
            pixel[3] = static_cast<float>((x + y) % 5) / 4.0f;
        }
    }
    return image;
}

namespace {

uint32_t crc32(const unsigned char* data, size_t size, uint32_t crc = 0) {
    crc = ~crc;
    for (size_t i = 0; i < size; ++i) {
        crc ^= data[i];
        for (int bit = 0; bit < 8; ++bit)
            crc = (crc >> 1) ^ (0xEDB88320u & (0u - (crc & 1u)));
    }
    return ~crc;
}

void putBigEndian32(std::vector<unsigned char>& out, uint32_t value) {
    for (int shift = 24; shift >= 0; shift -= 8)
        out.push_back(static_cast<unsigned char>(value >> shift));
}

void putChunk(std::vector<unsigned char>& out, const char* type, const std::vector<unsigned char>& data) {
    putBigEndian32(out, static_cast<uint32_t>(data.size()));
    std::vector<unsigned char> typed(type, type + 4);
    typed.insert(typed.end(), data.begin(), data.end());
    out.insert(out.end(), typed.begin(), typed.end());
    putBigEndian32(out, crc32(typed.data(), typed.size()));
}

} // namespace

void writePng16(const std::filesystem::path& path, int width, int height, const std::vector<uint16_t>& rgba) {
    std::vector<unsigned char> raw; // filter byte 0 then big-endian samples, per row
    for (int y = 0; y < height; ++y) {
        raw.push_back(0);
        for (int i = 0; i < width * 4; ++i) {
            const uint16_t sample = rgba[static_cast<size_t>(y) * width * 4 + i];
            raw.push_back(static_cast<unsigned char>(sample >> 8));
            raw.push_back(static_cast<unsigned char>(sample & 0xFF));
        }
    }
    std::vector<unsigned char> zlib = {0x78, 0x01};
    for (size_t start = 0; start < raw.size() || start == 0; start += 65535) {
        const size_t length = std::min<size_t>(65535, raw.size() - start);
        zlib.push_back(start + length == raw.size() ? 1 : 0); // BFINAL, BTYPE = stored
        zlib.push_back(static_cast<unsigned char>(length & 0xFF));
        zlib.push_back(static_cast<unsigned char>(length >> 8));
        zlib.push_back(static_cast<unsigned char>(~length & 0xFF));
        zlib.push_back(static_cast<unsigned char>((~length >> 8) & 0xFF));
        zlib.insert(zlib.end(), raw.begin() + static_cast<long>(start),
                    raw.begin() + static_cast<long>(start + length));
    }
    uint32_t a = 1, b = 0; // Adler-32
    for (unsigned char byte : raw) {
        a = (a + byte) % 65521;
        b = (b + a) % 65521;
    }
    putBigEndian32(zlib, (b << 16) | a);

    std::vector<unsigned char> png = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
    std::vector<unsigned char> header;
    putBigEndian32(header, static_cast<uint32_t>(width));
    putBigEndian32(header, static_cast<uint32_t>(height));
    header.insert(header.end(), {16, 6, 0, 0, 0}); // 16 bits, RGBA, deflate, no filter, no interlace
    putChunk(png, "IHDR", header);
    putChunk(png, "IDAT", zlib);
    putChunk(png, "IEND", {});
    writeBytes(path, png);
}

void writeBytes(const std::filesystem::path& path, const std::vector<unsigned char>& bytes) {
    std::ofstream out(path, std::ios::binary);
    out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
    ASSERT_TRUE(out.good()) << path;
}

std::vector<unsigned char> readBytes(const std::filesystem::path& path) {
    std::ifstream in(path, std::ios::binary);
    return std::vector<unsigned char>(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

} // namespace vitrine::test
