// Every input in tests/fuzz/regressions/ (inputs that once crashed a fuzzer, kept after the fix) and in the seed
// corpus tests/fuzz/corpus/ goes through the same loader calls as the fuzzers (fuzz_inputs.hpp), in the normal
// build: each must load or be rejected with a UserError. Another exception fails the test; a crash fails ctest.
#include "core/base/error.hpp"
#include "tests/fuzz/fuzz_inputs.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <string>
#include <vector>

namespace vitrine::fuzz {
namespace {

namespace fs = std::filesystem;

const fs::path kFuzzDir = fs::path(VITRINE_SOURCE_DIR) / "tests" / "fuzz";

using Loader = std::function<void(const uint8_t*, size_t, const fs::path&)>;

// Feeds every file of `dir` to `load`; returns how many there were.
size_t replay(const fs::path& dir, const Loader& load, const fs::path& scratch) {
    std::vector<fs::path> files;
    if (!fs::is_directory(dir)) return 0;
    for (const auto& e : fs::directory_iterator(dir))
        if (e.is_regular_file() && e.path().filename() != "README.md") files.push_back(e.path());
    std::sort(files.begin(), files.end());
    for (const fs::path& file : files) {
        std::ifstream in(file, std::ios::binary);
        std::vector<uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
        try {
            load(bytes.data(), bytes.size(), scratch);
        } catch (const UserError&) {
        } catch (const std::exception& e) {
            ADD_FAILURE() << file << ": not a UserError: " << e.what();
        } catch (...) {
            ADD_FAILURE() << file << ": threw something that is not a std::exception";
        }
    }
    return files.size();
}

TEST(Regressions, GraphInputs) {
    const fs::path scratch = scratchDirectory("vitrine-fuzz-regressions-graph");
    replay(kFuzzDir / "regressions" / "graph", loadGraphInput, scratch);
    EXPECT_GE(replay(kFuzzDir / "corpus" / "graph", loadGraphInput, scratch), 5u);
    fs::remove_all(scratch);
}

TEST(Regressions, GltfInputs) {
    const fs::path scratch = scratchDirectory("vitrine-fuzz-regressions-gltf");
    replay(kFuzzDir / "regressions" / "gltf", loadGltfInput, scratch);
    EXPECT_GE(replay(kFuzzDir / "corpus" / "gltf", loadGltfInput, scratch), 3u);
    fs::remove_all(scratch);
}

// The seed graphs are valid: they must load, or the fuzzer starts from rejected input only.
TEST(Regressions, SeedGraphsLoad) {
    const fs::path scratch = scratchDirectory("vitrine-fuzz-seeds-graph");
    for (const auto& e : fs::directory_iterator(kFuzzDir / "corpus" / "graph")) {
        if (e.path().filename().string().rfind("bad_", 0) == 0) continue;
        std::ifstream in(e.path(), std::ios::binary);
        std::vector<uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
        EXPECT_NO_THROW(loadGraphInput(bytes.data(), bytes.size(), scratch)) << e.path();
    }
    fs::remove_all(scratch);
}

} // namespace
} // namespace vitrine::fuzz
