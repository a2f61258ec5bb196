#include "tests/fuzz/fuzz_inputs.hpp"

#include "core/graph/loader.hpp"
#include "core/graph/order.hpp"
#include "core/scene/gltf.hpp"

#include <unistd.h>

#include <fstream>
#include <string>
#include <vector>

namespace vitrine::fuzz {

namespace fs = std::filesystem;

namespace {

void writeFile(const fs::path& path, const std::string& bytes) {
    std::ofstream out(path, std::ios::binary | std::ios::trunc);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

} // namespace

void loadGraphInput(const uint8_t* data, size_t size, const fs::path& scratch) {
    std::vector<std::string> parts(1);
    for (size_t i = 0; i < size; ++i) {
        if (data[i] == 0 && parts.size() < 3)
            parts.emplace_back();
        else
            parts.back() += static_cast<char>(data[i]);
    }
    writeFile(scratch / "graph.json", parts[0]);
    std::error_code ec;
    if (parts.size() > 1)
        writeFile(scratch / "base.json", parts[1]);
    else
        fs::remove(scratch / "base.json", ec);
    std::vector<std::string> sets;
    if (parts.size() > 2) {
        size_t start = 0;
        for (size_t end; (end = parts[2].find('\n', start)) != std::string::npos; start = end + 1)
            sets.push_back(parts[2].substr(start, end - start));
        if (start < parts[2].size()) sets.push_back(parts[2].substr(start));
    }
    GraphDesc desc = loadGraph(scratch / "graph.json", sets);
    orderGraph(desc);
}

void loadGltfInput(const uint8_t* data, size_t size, const fs::path& scratch) {
    std::vector<std::string> warnings;
    scene::loadGltfFromMemory(std::vector<uint8_t>(data, data + size), scratch / "input", warnings);
}

fs::path scratchDirectory(const char* name) {
    // Memory-backed when possible: ext4 flushes a file rewritten through truncation on close, which made every
    // execution wait for the disk (250 instead of thousands of executions per second).
    const char* tmp = std::getenv("TMPDIR");
    std::error_code ec;
    fs::path root = fs::is_directory("/dev/shm", ec) ? fs::path("/dev/shm") : fs::path(tmp && *tmp ? tmp : "/tmp");
    fs::path dir = root / (std::string(name) + "-" + std::to_string(::getpid()));
    fs::create_directories(dir);
    return dir;
}

} // namespace vitrine::fuzz
