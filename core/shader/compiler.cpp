#include "core/shader/compiler.hpp"

#include "core/base/error.hpp"
#include "core/base/paths.hpp"
#include "core/shader/reflection.hpp"

#include <glslang/Public/ResourceLimits.h>
#include <glslang/Public/ShaderLang.h>
#include <glslang/SPIRV/GlslangToSpv.h>
#include <glslang/build_info.h>

#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <mutex>
#include <regex>
#include <sstream>

namespace vitrine {

namespace fs = std::filesystem;

fs::path defaultShaderDir() { return shaderDir(); }

fs::path defaultCacheDir() { return cacheDir(); }

VkShaderStageFlagBits stageFromPath(const std::string& path) {
    std::string ext = fs::path(path).extension().string();
    if (ext == ".comp") return VK_SHADER_STAGE_COMPUTE_BIT;
    if (ext == ".vert") return VK_SHADER_STAGE_VERTEX_BIT;
    if (ext == ".frag") return VK_SHADER_STAGE_FRAGMENT_BIT;
    throw UserError(path + ": unknown shader stage; expected a .comp, .vert or .frag file");
}

namespace {

EShLanguage toGlslang(VkShaderStageFlagBits stage) {
    switch (stage) {
    case VK_SHADER_STAGE_VERTEX_BIT: return EShLangVertex;
    case VK_SHADER_STAGE_FRAGMENT_BIT: return EShLangFragment;
    default: return EShLangCompute;
    }
}

std::string readText(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw UserError(path.string() + ": cannot read shader file");
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

uint64_t fnv1a(const std::string& data, uint64_t hash = 1469598103934665603ull) {
    for (unsigned char c : data) hash = (hash ^ c) * 1099511628211ull;
    return hash;
}

// Resolves #include against the including file's directory, then the shader root. Header
// names are reported relative to the root so error messages stay short.
class Includer : public glslang::TShader::Includer {
public:
    explicit Includer(fs::path root) : mRoot(std::move(root)) {}

    IncludeResult* includeLocal(const char* header, const char* includer, size_t depth) override {
        fs::path base = fs::path(includer).parent_path();
        for (const fs::path& candidate : {mRoot / base / header, mRoot / header}) {
            std::error_code ec;
            if (fs::is_regular_file(candidate, ec)) return load(candidate);
        }
        return nullptr;
    }
    IncludeResult* includeSystem(const char* header, const char* includer, size_t depth) override {
        return includeLocal(header, includer, depth);
    }
    void releaseInclude(IncludeResult* result) override {
        if (!result) return;
        delete static_cast<std::string*>(result->userData);
        delete result;
    }

private:
    IncludeResult* load(const fs::path& path) {
        auto* text = new std::string(readText(path));
        std::string name = fs::relative(path, mRoot).generic_string();
        return new IncludeResult(name, text->data(), text->size(), text);
    }
    fs::path mRoot;
};

// glslang logs "ERROR: name:line: message"; rewrite each as "name:line: error: message".
std::string formatLog(const std::string& log) {
    static const std::regex kLine(R"(^(ERROR|WARNING): ([^:\n]+):(\d+): (.*)$)");
    std::stringstream in(log), out;
    std::string line;
    while (std::getline(in, line)) {
        std::smatch m;
        if (std::regex_match(line, m, kLine)) {
            std::string kind = m[1] == "ERROR" ? "error" : "warning";
            out << m[2] << ":" << m[3] << ": " << kind << ": " << m[4] << "\n";
        } else if (!line.empty() && line.find("compilation errors") == std::string::npos) {
            out << line << "\n";
        }
    }
    return out.str();
}

void initGlslang() {
    static std::once_flag once;
    std::call_once(once, [] {
        glslang::InitializeProcess();
        std::atexit([] { glslang::FinalizeProcess(); });
    });
}

} // namespace

ShaderCompiler::ShaderCompiler(fs::path shaderRoot, fs::path cacheDir, bool useCache)
    : mRoot(std::move(shaderRoot)), mCacheDir(std::move(cacheDir) / "spirv"), mUseCache(useCache) {}

CompiledShader ShaderCompiler::compile(const std::string& path, const ShaderDefines& defines) {
    fs::path file = mRoot / path;
    std::error_code ec;
    if (!fs::is_regular_file(file, ec))
        throw UserError(path + ": shader not found under " + mRoot.string());
    return compileSource(path, readText(file), stageFromPath(path), defines);
}

CompiledShader ShaderCompiler::compileSource(const std::string& name, const std::string& source,
                                             VkShaderStageFlagBits stage, const ShaderDefines& defines) {
    initGlslang();
    const EShLanguage lang = toGlslang(stage);
    const auto messages = static_cast<EShMessages>(EShMsgSpvRules | EShMsgVulkanRules);
    std::string preamble;
    for (const auto& [key, value] : defines) preamble += "#define " + key + " " + value + "\n";

    // glslang keeps the pointers to these arrays until parse(): they must outlive makeShader (as locals of the
    // lambda they dangled, which only an unoptimised build showed).
    const char* text = source.c_str();
    const int length = static_cast<int>(source.size());
    const char* names = name.c_str();
    auto makeShader = [&](glslang::TShader& shader) {
        shader.setStringsWithLengthsAndNames(&text, &length, &names, 1);
        shader.setPreamble(preamble.c_str());
        shader.setEnvInput(glslang::EShSourceGlsl, lang, glslang::EShClientVulkan, 460);
        shader.setEnvClient(glslang::EShClientVulkan, glslang::EShTargetVulkan_1_3);
        shader.setEnvTarget(glslang::EShTargetSpv, glslang::EShTargetSpv_1_5);
    };

    // Preprocess first: the expanded text (all includes and defines applied) is the cache key.
    Includer includer(mRoot);
    std::string expanded;
    {
        glslang::TShader pre(lang);
        makeShader(pre);
        if (!pre.preprocess(GetDefaultResources(), 460, ECoreProfile, false, false, messages, &expanded, includer))
            throw UserError("shader " + name + " failed to preprocess:\n" + formatLog(pre.getInfoLog()));
    }
    std::stringstream keyText;
    keyText << "spv1.5|" << GLSLANG_VERSION_MAJOR << "." << GLSLANG_VERSION_MINOR << "|" << lang << "|" << expanded;
    char hex[17];
    std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(fnv1a(keyText.str())));
    const fs::path spvPath = mCacheDir / (std::string(hex) + ".spv");
    const fs::path reflPath = mCacheDir / (std::string(hex) + ".json");

    CompiledShader result;
    result.name = name;
    std::error_code existsError;
    if (mUseCache && fs::exists(spvPath, existsError) && fs::exists(reflPath, existsError)) {
        std::ifstream in(spvPath, std::ios::binary | std::ios::ate);
        size_t bytes = static_cast<size_t>(in.tellg());
        if (bytes % 4 == 0 && bytes > 0) {
            result.spirv.resize(bytes / 4);
            in.seekg(0);
            in.read(reinterpret_cast<char*>(result.spirv.data()), static_cast<std::streamsize>(bytes));
            if (in && reflectionFromJson(readText(reflPath), result.reflection)) {
                result.fromCache = true;
                ++mHits;
                return result;
            }
        }
    }
    ++mMisses;

    glslang::TShader shader(lang);
    makeShader(shader);
    if (!shader.parse(GetDefaultResources(), 460, false, messages, includer))
        throw UserError("shader " + name + " failed to compile:\n" + formatLog(shader.getInfoLog()));
    glslang::TProgram program;
    program.addShader(&shader);
    if (!program.link(messages))
        throw UserError("shader " + name + " failed to link:\n" + formatLog(program.getInfoLog()));
    if (!program.buildReflection(EShReflectionSeparateBuffers))
        throw InternalError("shader " + name + ": glslang reflection failed");
    result.reflection = reflect(program, stage);

    glslang::SpvOptions options;
    options.generateDebugInfo = false;
    options.validate = false;
    spv::SpvBuildLogger logger;
    glslang::GlslangToSpv(*program.getIntermediate(lang), result.spirv, &logger, &options);
    if (!logger.getAllMessages().empty() && result.spirv.empty())
        throw InternalError("shader " + name + ": SPIR-V generation failed: " + logger.getAllMessages());

    if (mUseCache) {
        std::error_code ec;
        fs::create_directories(mCacheDir, ec);
        // Write to temporaries and rename so a concurrent reader never sees a partial file.
        fs::path tmpSpv = spvPath.string() + ".tmp" + std::to_string(::getpid());
        fs::path tmpRefl = reflPath.string() + ".tmp" + std::to_string(::getpid());
        std::ofstream(tmpSpv, std::ios::binary)
            .write(reinterpret_cast<const char*>(result.spirv.data()),
                   static_cast<std::streamsize>(result.spirv.size() * 4));
        std::ofstream(tmpRefl) << reflectionToJson(result.reflection);
        fs::rename(tmpRefl, reflPath, ec);
        fs::rename(tmpSpv, spvPath, ec);
    }
    return result;
}

uint64_t ShaderCompiler::treeHash() const {
    if (mTreeHash) return *mTreeHash;
    std::vector<std::string> files;
    std::error_code ec;
    for (fs::recursive_directory_iterator it(mRoot, ec), end; !ec && it != end; it.increment(ec))
        if (it->is_regular_file()) files.push_back(fs::relative(it->path(), mRoot).generic_string());
    std::sort(files.begin(), files.end()); // directory order is the file system's
    uint64_t h = fnv1a(std::to_string(files.size()));
    for (const std::string& f : files) {
        std::ifstream in(mRoot / f, std::ios::binary);
        std::ostringstream bytes;
        bytes << in.rdbuf();
        h = fnv1a(f + '\0' + std::to_string(bytes.str().size()) + '\0', h);
        h = fnv1a(bytes.str(), h);
    }
    mTreeHash = h;
    return h;
}

} // namespace vitrine
