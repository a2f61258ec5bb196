#pragma once

// The shader compiler's first cache key (core/shader/compiler.cpp): what a shader's expanded text is made of, read
// without running the preprocessor, so that a warm start finds its SPIR-V without preprocessing every shader.
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>

namespace vitrine {

// A hash of: the glslang version, the stage, the shader's name and source, the preamble of defines, and every file
// that an `#include` line of the source or of an included file names (its path relative to `root` and its bytes),
// resolved as the compiler's includer resolves them: against the including file's directory, then `root`. Lines
// inside `#if` blocks count too (a superset of what the preprocessor includes: the key may change when a file that
// is not included changes, never stays the same when one that is included does); a name that resolves to no file
// adds nothing until such a file appears. nullopt when a resolved file cannot be read
// (the compiler then keys by the expanded text alone, as before).
std::optional<uint64_t> shaderSourceKey(const std::filesystem::path& root, const std::string& name,
                                        const std::string& source, const std::string& preamble, int stage);

} // namespace vitrine
