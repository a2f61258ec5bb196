#include "core/shader/compiler.hpp"

#include "core/base/error.hpp"
#include "core/base/paths.hpp"
#include "core/shader/reflection.hpp"
#include "core/shader/source_key.hpp"

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
#include <set>
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

// Where `#include "header"` in the file `includer` (a path relative to root) leads: against the including file's
// directory, then the shader root; relative to root, or nullopt when neither holds the file. The one rule of both the
// preprocessor's includer and the source key (shaderSourceKey).
std::optional<fs::path> resolveInclude(const fs::path& root, const std::string& includer, const std::string& header) {
    for (const fs::path& candidate : {fs::path(includer).parent_path() / header, fs::path(header)}) {
        std::error_code ec;
        if (fs::is_regular_file(root / candidate, ec)) return candidate.lexically_normal();
    }
    return std::nullopt;
}

// Resolves #include with resolveInclude(). Header names are reported relative to the root so error messages stay
// short.
class Includer : public glslang::TShader::Includer {
public:
    explicit Includer(fs::path root) : mRoot(std::move(root)) {}

    IncludeResult* includeLocal(const char* header, const char* includer, size_t depth) override {
        std::optional<fs::path> found = resolveInclude(mRoot, includer, header);
        return found ? load(mRoot / *found) : nullptr;
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

// The SPIR-V and reflection cached under `hex` in cacheDir; false when either is missing or unreadable.
bool loadCached(const fs::path& cacheDir, const std::string& hex, CompiledShader& result) {
    const fs::path spvPath = cacheDir / (hex + ".spv");
    const fs::path reflPath = cacheDir / (hex + ".json");
    std::error_code existsError;
    if (!fs::exists(spvPath, existsError) || !fs::exists(reflPath, existsError)) return false;
    std::ifstream in(spvPath, std::ios::binary | std::ios::ate);
    size_t bytes = static_cast<size_t>(in.tellg());
    if (!in || bytes % 4 != 0 || bytes == 0) return false;
    result.spirv.resize(bytes / 4);
    in.seekg(0);
    in.read(reinterpret_cast<char*>(result.spirv.data()), static_cast<std::streamsize>(bytes));
    if (!in || !reflectionFromJson(readText(reflPath), result.reflection)) return false;
    result.fromCache = true;
    return true;
}

// The file names of a text's `#include "x"` / `#include <x>` lines, in order.
std::vector<std::string> includeNames(const std::string& text) {
    std::vector<std::string> names;
    size_t pos = 0;
    while (pos < text.size()) {
        size_t end = text.find('\n', pos);
        if (end == std::string::npos) end = text.size();
        size_t i = text.find_first_not_of(" \t", pos);
        if (i < end && text[i] == '#') {
            i = text.find_first_not_of(" \t", i + 1);
            if (i < end && text.compare(i, 7, "include") == 0) {
                i = text.find_first_not_of(" \t", i + 7);
                if (i < end && (text[i] == '"' || text[i] == '<')) {
                    const char close = text[i] == '"' ? '"' : '>';
                    size_t last = text.find(close, i + 1);
                    if (last < end) names.push_back(text.substr(i + 1, last - i - 1));
                }
            }
        }
        pos = end + 1;
    }
    return names;
}

// Adds the files that the include lines of `text` (the file `name`, relative to root) name to the hash, recursively;
// false when one cannot be read.
bool hashIncludes(const fs::path& root, const std::string& name, const std::string& text, std::set<std::string>& seen,
                  uint64_t& hash) {
    for (const std::string& header : includeNames(text)) {
        const std::optional<fs::path> resolved = resolveInclude(root, name, header);
        // Named but absent: an include the preprocessor skips (`#include <cstdint>` under __cplusplus in the headers
        // shared with C++), or a missing file, which fails preprocessing, so no key ever points to SPIR-V for it.
        // Its line is in the including file's bytes; should a file of that name appear, it is hashed from then on.
        if (!resolved) continue;
        const std::string found = resolved->generic_string();
        if (!seen.insert(found).second) continue; // once each (include guards are not read: files may cycle)
        std::string included;
        try {
            included = readText(root / found);
        } catch (const UserError&) {
            return false;
        }
        hash = fnv1a(found + '\0' + std::to_string(included.size()) + '\0', hash);
        hash = fnv1a(included, hash);
        if (!hashIncludes(root, found, included, seen, hash)) return false;
    }
    return true;
}

void initGlslang() {
    static std::once_flag once;
    std::call_once(once, [] {
        glslang::InitializeProcess();
        std::atexit([] { glslang::FinalizeProcess(); });
    });
}

} // namespace

std::optional<uint64_t> shaderSourceKey(const fs::path& root, const std::string& name, const std::string& source,
                                        const std::string& preamble, int stage) {
    std::stringstream head;
    head << "src1|" << GLSLANG_VERSION_MAJOR << "." << GLSLANG_VERSION_MINOR << "." << GLSLANG_VERSION_PATCH << "|"
         << stage << "|" << name << '\0' << preamble << '\0' << source.size() << '\0';
    uint64_t hash = fnv1a(head.str());
    hash = fnv1a(source, hash);
    std::set<std::string> seen;
    if (!hashIncludes(root, name, source, seen, hash)) return std::nullopt;
    return hash;
}

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

    // The SPIR-V is cached under a hash of the expanded text (all includes and defines applied). Preprocessing every
    // shader to find it was most of a warm start's pipeline time (glslang's preprocessor: about 140 of 190 ms for the
    // Museum's compute shaders on lavapipe's 2-core machine), so a first key read from the sources and the files
    // they include (shaderSourceKey) points to it: `src-KEY.ref` holds the expanded text's hash.
    fs::path refPath;
    if (const std::optional<uint64_t> sourceKey =
            mUseCache ? shaderSourceKey(mRoot, name, source, preamble, static_cast<int>(lang)) : std::nullopt) {
        char key[17];
        std::snprintf(key, sizeof key, "%016llx", static_cast<unsigned long long>(*sourceKey));
        refPath = mCacheDir / ("src-" + std::string(key) + ".ref");
        std::string hex;
        std::ifstream(refPath) >> hex; // empty when there is no ref yet
        CompiledShader cached;
        if (hex.size() == 16 && loadCached(mCacheDir, hex, cached)) {
            cached.name = name;
            ++mHits;
            return cached;
        }
    }

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

    // Where the source key will point from now on (written after the SPIR-V, so it never points to nothing).
    auto writeRef = [&] {
        if (refPath.empty()) return;
        std::error_code ec;
        fs::create_directories(mCacheDir, ec);
        fs::path tmp = refPath.string() + ".tmp" + std::to_string(::getpid());
        std::ofstream(tmp) << hex << "\n";
        fs::rename(tmp, refPath, ec);
    };

    CompiledShader result;
    result.name = name;
    if (mUseCache && loadCached(mCacheDir, hex, result)) {
        result.name = name;
        ++mHits;
        writeRef();
        return result;
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
        writeRef();
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
