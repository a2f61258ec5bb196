#pragma once

// Helpers shared by the scene tests: data paths, scratch directories, file I/O, GLB assembly.

#include "core/base/error.hpp"

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <unistd.h>

namespace vitrine::scene::test {

using Json = nlohmann::json;

inline std::filesystem::path dataDir() {
    return std::filesystem::path(VITRINE_TEST_DATA_DIR) / "gltf";
}

inline std::filesystem::path scratchRoot() {
    return std::filesystem::temp_directory_path() / ("vitrine_scene_test_" + std::to_string(::getpid()));
}

// Removes this process's scratch directories when the test program ends.
class ScratchCleanup : public ::testing::Environment {
public:
    void TearDown() override { std::filesystem::remove_all(scratchRoot()); }
};
inline ::testing::Environment* const kScratchCleanup = ::testing::AddGlobalTestEnvironment(new ScratchCleanup);

// A fresh directory per test.
inline std::filesystem::path scratchDir() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    auto dir = scratchRoot() / (std::string(info->test_suite_name()) + "_" + info->name());
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    return dir;
}

inline std::vector<uint8_t> readBytes(const std::filesystem::path& p) {
    std::ifstream in(p, std::ios::binary);
    return std::vector<uint8_t>(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

inline void writeBytes(const std::filesystem::path& p, const std::vector<uint8_t>& bytes) {
    std::ofstream out(p, std::ios::binary);
    out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
}

inline void writeText(const std::filesystem::path& p, const std::string& text) {
    std::ofstream out(p, std::ios::binary);
    out << text;
}

inline Json readJson(const std::filesystem::path& p) {
    std::ifstream in(p);
    return Json::parse(in);
}

inline std::vector<uint8_t> base64Decode(const std::string& s) {
    auto value = [](char c) -> int {
        if (c >= 'A' && c <= 'Z') return c - 'A';
        if (c >= 'a' && c <= 'z') return c - 'a' + 26;
        if (c >= '0' && c <= '9') return c - '0' + 52;
        return c == '+' ? 62 : c == '/' ? 63 : -1;
    };
    std::vector<uint8_t> out;
    uint32_t acc = 0;
    int bits = 0;
    for (char c : s) {
        int v = value(c);
        if (v < 0) continue;
        acc = acc << 6 | uint32_t(v);
        bits += 6;
        if (bits >= 8) {
            bits -= 8;
            out.push_back(static_cast<uint8_t>(acc >> bits));
        }
    }
    return out;
}

// The payload of a data: URI.
inline std::vector<uint8_t> dataUriBytes(const std::string& uri) {
    return base64Decode(uri.substr(uri.find(',') + 1));
}

// A GLB container from JSON text and a binary chunk, laid out by hand (independent of exportGlb()).
inline std::vector<uint8_t> makeGlb(std::string json, std::vector<uint8_t> bin) {
    while (json.size() % 4)
        json.push_back(' ');
    while (bin.size() % 4)
        bin.push_back(0);
    std::vector<uint8_t> out;
    auto u32 = [&](uint32_t v) {
        for (int i = 0; i < 4; ++i)
            out.push_back(static_cast<uint8_t>(v >> (8 * i)));
    };
    u32(0x46546C67u);
    u32(2);
    u32(static_cast<uint32_t>(12 + 8 + json.size() + 8 + bin.size()));
    u32(static_cast<uint32_t>(json.size()));
    u32(0x4E4F534Au);
    out.insert(out.end(), json.begin(), json.end());
    u32(static_cast<uint32_t>(bin.size()));
    u32(0x004E4942u);
    out.insert(out.end(), bin.begin(), bin.end());
    return out;
}

// Expects f() to throw UserError whose message contains every one of parts.
inline void expectUserError(const std::function<void()>& f, const std::vector<std::string>& parts) {
    try {
        f();
        ADD_FAILURE() << "expected a UserError";
    } catch (const UserError& e) {
        std::string message = e.what();
        for (const std::string& part : parts) {
            EXPECT_NE(message.find(part), std::string::npos) << "message lacks '" << part << "': " << message;
        }
    } catch (const std::exception& e) {
        ADD_FAILURE() << "expected a UserError, got: " << e.what();
    }
}

} // namespace vitrine::scene::test
