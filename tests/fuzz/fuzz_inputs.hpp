#pragma once

// What the fuzzers feed to vitrine's loaders, shared by the libFuzzer targets (fuzz_graph.cpp, fuzz_gltf.cpp, built
// with clang by tools/fuzz.sh) and by the regression test that every build runs (regressions_test.cpp), so a crash
// the fuzzer found is replayed through exactly the same calls.
//
// Both throw UserError for input the loaders reject; anything else escaping (another exception, a crash, a
// sanitizer report) is a bug.

#include <cstddef>
#include <cstdint>
#include <filesystem>

namespace vitrine::fuzz {

// A graph: the bytes split at NUL bytes into up to three parts, written as files into `scratch` and loaded like
// `vitrine validate scratch/graph.json --set ...` (phases 1-3: JSON, `extends` merge patch, --set, validation,
// order and cull; node setup is not run):
//   part 0: graph.json;
//   part 1: base.json (absent: no such file), which graph.json may name in "extends";
//   part 2: --set assignments, one per line.
void loadGraphInput(const uint8_t* data, size_t size, const std::filesystem::path& scratch);

// A glTF file: the bytes as a file called scratch/"input" (no extension: JSON or GLB decided by the content), loaded
// by scene::loadGltfFromMemory (external URIs resolve in `scratch`, which holds nothing else).
void loadGltfInput(const uint8_t* data, size_t size, const std::filesystem::path& scratch);

// A directory for one process's scratch files (created; under /dev/shm when there is one, else $TMPDIR or /tmp).
std::filesystem::path scratchDirectory(const char* name);

// scratchDirectory(), removed with its files when the process ends normally (a fuzzer's time is up).
struct Scratch {
    explicit Scratch(const char* name) : dir(scratchDirectory(name)) {}
    ~Scratch() {
        std::error_code ec;
        std::filesystem::remove_all(dir, ec);
    }
    Scratch(const Scratch&) = delete;
    Scratch& operator=(const Scratch&) = delete;
    std::filesystem::path dir;
};

} // namespace vitrine::fuzz
