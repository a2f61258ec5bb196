#pragma once

#include <vulkan/vulkan.h>

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace vitrine {

// One descriptor binding as glslang's reflection reports it (live variables only).
struct ShaderBinding {
    std::string name;
    uint32_t set = 0;
    uint32_t binding = 0;
    VkDescriptorType type = VK_DESCRIPTOR_TYPE_MAX_ENUM;
    uint32_t count = 1;
    bool operator==(const ShaderBinding&) const = default;
};

struct ShaderReflection {
    VkShaderStageFlagBits stage = VK_SHADER_STAGE_COMPUTE_BIT;
    std::vector<ShaderBinding> bindings;
    uint32_t pushConstantSize = 0;
    uint32_t localSize[3] = {1, 1, 1};
};

struct CompiledShader {
    std::string name; // path relative to the shader root, or the name given to compileSource
    std::vector<uint32_t> spirv;
    ShaderReflection reflection;
    bool fromCache = false;
};

using ShaderDefines = std::vector<std::pair<std::string, std::string>>;

// The directory shaders are found in: $VITRINE_SHADER_DIR, else an installed share/vitrine/shaders next to the
// binary, else the source tree's shaders/ (core/base/paths.hpp).
std::filesystem::path defaultShaderDir();
// $VITRINE_CACHE_DIR, else $XDG_CACHE_HOME/vitrine, else ~/.cache/vitrine.
std::filesystem::path defaultCacheDir();

// GLSL -> SPIR-V through glslang at run time. `#include "x.glsl"` resolves relative to the
// including file, then to the shader root. Defines are injected as a preamble. Results are
// cached on disk keyed by a hash of the preprocessed source (so includes and defines count),
// the stage and the compiler version; the reflection is cached beside the SPIR-V.
// Errors throw UserError with lines of the form `file:line: error: message`.
class ShaderCompiler {
public:
    explicit ShaderCompiler(std::filesystem::path shaderRoot = defaultShaderDir(),
                            std::filesystem::path cacheDir = defaultCacheDir(), bool useCache = true);

    CompiledShader compile(const std::string& path, const ShaderDefines& defines = {});
    CompiledShader compileSource(const std::string& name, const std::string& source, VkShaderStageFlagBits stage,
                                 const ShaderDefines& defines = {});

    const std::filesystem::path& root() const { return mRoot; }
    uint32_t cacheHits() const { return mHits; }
    uint32_t cacheMisses() const { return mMisses; }

    // A hash of every regular file under root() (its path relative to the root and its bytes), read once per
    // compiler. For results cached on disk that come out of whole graphs of shaders, such as ibl.capture's probes
    // (rendered by the G-buffer, lighting and scene shaders): any shader edit gives them another key.
    uint64_t treeHash() const;

private:
    std::filesystem::path mRoot;
    std::filesystem::path mCacheDir;
    bool mUseCache;
    uint32_t mHits = 0;
    uint32_t mMisses = 0;
    mutable std::optional<uint64_t> mTreeHash;
};

VkShaderStageFlagBits stageFromPath(const std::string& path);

} // namespace vitrine
