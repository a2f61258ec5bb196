// Shader compilation: include resolution, error reporting as file:line, the SPIR-V cache.
#include "core/base/error.hpp"
#include "core/shader/compiler.hpp"
#include "core/shader/reflection.hpp"
#include "core/shader/source_key.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

namespace vitrine {
namespace {

namespace fs = std::filesystem;

class ShaderFiles : public ::testing::Test {
protected:
    void SetUp() override {
        mRoot = fs::temp_directory_path() / ("vitrine_shader_test_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) +
                                             ::testing::UnitTest::GetInstance()->current_test_info()->name());
        fs::remove_all(mRoot);
        fs::create_directories(mRoot / "lib");
    }
    void TearDown() override { fs::remove_all(mRoot); }
    void write(const std::string& name, const std::string& text) { std::ofstream(mRoot / name) << text; }
    fs::path mRoot;
};

const char* kHeader = "#version 460\n#extension GL_GOOGLE_include_directive : require\n";

TEST_F(ShaderFiles, ResolvesIncludesAndReflectsBindings) {
    write("lib/util.glsl", "float twice(float x) { return 2.0 * x; }\n");
    write("main.comp", std::string(kHeader) +
                           "#include \"lib/util.glsl\"\n"
                           "layout(local_size_x = 4, local_size_y = 2) in;\n"
                           "layout(binding = 0) uniform sampler2D in_color;\n"
                           "layout(binding = 3) writeonly uniform image2D out_color;\n"
                           "layout(push_constant) uniform P { float a; float b; } pc;\n"
                           "void main() { imageStore(out_color, ivec2(0), vec4(twice(pc.a) + pc.b) + texelFetch(in_color, ivec2(0), 0)); }\n");
    ShaderCompiler compiler(mRoot, mRoot / "cache");
    CompiledShader s = compiler.compile("main.comp");
    EXPECT_FALSE(s.spirv.empty());
    EXPECT_EQ(s.spirv[0], 0x07230203u); // SPIR-V magic
    ASSERT_NE(findBinding(s.reflection, "in_color"), nullptr);
    EXPECT_EQ(findBinding(s.reflection, "in_color")->binding, 0u);
    EXPECT_EQ(findBinding(s.reflection, "in_color")->type, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER);
    ASSERT_NE(findBinding(s.reflection, "out_color"), nullptr);
    EXPECT_EQ(findBinding(s.reflection, "out_color")->binding, 3u);
    EXPECT_EQ(findBinding(s.reflection, "out_color")->type, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE);
    EXPECT_EQ(s.reflection.pushConstantSize, 8u);
    EXPECT_EQ(s.reflection.localSize[0], 4u);
    EXPECT_EQ(s.reflection.localSize[1], 2u);
}

TEST_F(ShaderFiles, CompileErrorNamesFileAndLine) {
    write("broken.comp", std::string(kHeader) + "layout(local_size_x = 1) in;\nvoid main() {\n    float x = undefinedThing;\n}\n");
    ShaderCompiler compiler(mRoot, mRoot / "cache");
    try {
        compiler.compile("broken.comp");
        FAIL() << "expected a compile error";
    } catch (const UserError& e) {
        std::string m = e.what();
        EXPECT_NE(m.find("broken.comp:5: error:"), std::string::npos) << m;
        EXPECT_NE(m.find("undefinedThing"), std::string::npos) << m;
    }
}

TEST_F(ShaderFiles, ErrorInsideIncludeNamesTheIncludedFile) {
    write("lib/bad.glsl", "// line 1\nfloat f() { return nope; }\n");
    write("main.comp", std::string(kHeader) + "#include \"lib/bad.glsl\"\nlayout(local_size_x = 1) in;\nvoid main() {}\n");
    ShaderCompiler compiler(mRoot, mRoot / "cache");
    try {
        compiler.compile("main.comp");
        FAIL() << "expected a compile error";
    } catch (const UserError& e) {
        EXPECT_NE(std::string(e.what()).find("lib/bad.glsl:2: error:"), std::string::npos) << e.what();
    }
}

TEST_F(ShaderFiles, MissingIncludeIsReported) {
    write("main.comp", std::string(kHeader) + "#include \"lib/nothere.glsl\"\nlayout(local_size_x = 1) in;\nvoid main() {}\n");
    ShaderCompiler compiler(mRoot, mRoot / "cache");
    try {
        compiler.compile("main.comp");
        FAIL() << "expected an include error";
    } catch (const UserError& e) {
        EXPECT_NE(std::string(e.what()).find("lib/nothere.glsl"), std::string::npos) << e.what();
    }
}

TEST_F(ShaderFiles, CacheKeyCoversIncludesAndDefines) {
    write("lib/value.glsl", "const float kValue = 1.0;\n");
    write("main.comp", std::string(kHeader) + "#include \"lib/value.glsl\"\nlayout(local_size_x = 1) in;\n"
                                              "layout(binding = 0) writeonly uniform image2D out_x;\n"
                                              "void main() { imageStore(out_x, ivec2(0), vec4(kValue * SCALE)); }\n");
    ShaderCompiler compiler(mRoot, mRoot / "cache");
    EXPECT_FALSE(compiler.compile("main.comp", {{"SCALE", "2.0"}}).fromCache);
    EXPECT_TRUE(compiler.compile("main.comp", {{"SCALE", "2.0"}}).fromCache);
    EXPECT_FALSE(compiler.compile("main.comp", {{"SCALE", "3.0"}}).fromCache); // another define
    write("lib/value.glsl", "const float kValue = 5.0;\n");
    CompiledShader changed = compiler.compile("main.comp", {{"SCALE", "2.0"}}); // an include changed
    EXPECT_FALSE(changed.fromCache);
    ShaderCompiler other(mRoot, mRoot / "cache"); // a new process sees the disk cache
    CompiledShader again = other.compile("main.comp", {{"SCALE", "2.0"}});
    EXPECT_TRUE(again.fromCache);
    EXPECT_EQ(again.spirv, changed.spirv);
    EXPECT_EQ(again.reflection.bindings, changed.reflection.bindings);
}

// The first cache key, read from the sources without preprocessing: it must change whenever the expanded text can.
TEST_F(ShaderFiles, SourceKeyCoversEveryIncludedFileAndTheDefines) {
    fs::create_directories(mRoot / "lib" / "deep");
    write("lib/a.glsl", "#include \"deep/b.glsl\"\nconst float kA = 1.0;\n");
    write("lib/deep/b.glsl", "const float kB = 2.0;\n");
    write("lib/unused.glsl", "const float kUnused = 3.0;\n");
    const std::string source = std::string(kHeader) + "#include \"lib/a.glsl\"\n"
                                                      "#ifdef __cplusplus\n#include <cstdint>\n#endif\n"
                                                      "#if 0\n#include \"lib/later.glsl\"\n#endif\n"
                                                      "void main() {}\n";
    auto key = [&](const std::string& text, const std::string& preamble = "#define X 1\n",
                   const std::string& name = "main.comp") { return shaderSourceKey(mRoot, name, text, preamble, 5); };
    const std::optional<uint64_t> base = key(source);
    ASSERT_TRUE(base.has_value()) << "includes that name no file (skipped by #if) must not stop the key";
    EXPECT_EQ(key(source), base) << "the same inputs";
    write("lib/unused.glsl", "const float kUnused = 4.0;\n");
    EXPECT_EQ(key(source), base) << "a file no include line names";
    EXPECT_NE(key(source, "#define X 2\n"), base) << "the defines";
    EXPECT_NE(key(source, "#define X 1\n", "other.comp"), base) << "the name (#include resolves from its folder)";
    EXPECT_NE(shaderSourceKey(mRoot, "main.comp", source, "#define X 1\n", 4), base) << "the stage";
    std::string edited = source;
    edited.replace(edited.find("void main"), 9, "void mian"); // the same length
    EXPECT_NE(key(edited), base) << "the source";
    write("lib/deep/b.glsl", "const float kB = 2.5;\n");
    const std::optional<uint64_t> nested = key(source);
    EXPECT_NE(nested, base) << "a file included by an included file";
    write("lib/a.glsl", "#include \"deep/b.glsl\"\nconst float kA = 1.5;\n");
    const std::optional<uint64_t> direct = key(source);
    EXPECT_NE(direct, nested) << "an included file";
    write("lib/later.glsl", "const float kLater = 1.0;\n");
    const std::optional<uint64_t> appeared = key(source);
    EXPECT_NE(appeared, direct) << "a file appearing under a name an include line gave";
    // Headers that include each other behind include guards (which the key does not read): each counted once.
    write("lib/c.glsl", "#ifndef C\n#define C\n#include \"d.glsl\"\n#endif\n");
    write("lib/d.glsl", "#ifndef D\n#define D\n#include \"c.glsl\"\nconst float kD = 1.0;\n#endif\n");
    const std::string cyclic = source + "#include \"lib/c.glsl\"\n";
    const std::optional<uint64_t> withCycle = key(cyclic);
    ASSERT_TRUE(withCycle.has_value());
    write("lib/d.glsl", "#ifndef D\n#define D\n#include \"c.glsl\"\nconst float kD = 2.0;\n#endif\n");
    EXPECT_NE(key(cyclic), withCycle) << "a file in an include cycle";
}

// A warm compile reads `spirv/src-KEY.ref` (the source key's pointer to the expanded text's hash) instead of
// preprocessing: pointed at another shader's SPIR-V, it gets that one; a ref to nothing falls back to preprocessing
// and is written again.
TEST_F(ShaderFiles, WarmCompilesFindTheSpirvThroughTheSourceKey) {
    write("lib/value.glsl", "const float kValue = 1.0;\n");
    const std::string body = "layout(local_size_x = 1) in;\nlayout(binding = 0) writeonly uniform image2D out_x;\n";
    write("a.comp", std::string(kHeader) + "#include \"lib/value.glsl\"\n" + body +
                        "void main() { imageStore(out_x, ivec2(0), vec4(kValue)); }\n");
    write("b.comp",
          std::string(kHeader) + body + "void main() { imageStore(out_x, ivec2(0), vec4(7.0, 1.0, 2.0, 3.0)); }\n");
    const fs::path spirvDir = mRoot / "cache" / "spirv";
    CompiledShader a, b;
    {
        ShaderCompiler compiler(mRoot, mRoot / "cache");
        a = compiler.compile("a.comp");
        b = compiler.compile("b.comp");
        ASSERT_FALSE(a.fromCache);
        ASSERT_NE(a.spirv, b.spirv);
    }
    auto refs = [&] {
        std::vector<fs::path> found;
        for (const auto& e : fs::directory_iterator(spirvDir))
            if (e.path().filename().string().rfind("src-", 0) == 0) found.push_back(e.path());
        return found;
    };
    ASSERT_EQ(refs().size(), 2u) << "one ref per compiled source";
    const std::optional<uint64_t> keyA =
        shaderSourceKey(mRoot, "a.comp",
                        std::string(kHeader) + "#include \"lib/value.glsl\"\n" + body +
                            "void main() { imageStore(out_x, ivec2(0), vec4(kValue)); }\n",
                        "", 5 /* EShLangCompute */);
    ASSERT_TRUE(keyA.has_value());
    char name[32];
    std::snprintf(name, sizeof name, "src-%016llx.ref", static_cast<unsigned long long>(*keyA));
    const fs::path refA = spirvDir / name;
    ASSERT_TRUE(fs::exists(refA)) << refA;
    std::string hexB;
    for (const fs::path& r : refs())
        if (r != refA) std::ifstream(r) >> hexB;
    ASSERT_EQ(hexB.size(), 16u);

    std::ofstream(refA) << hexB << "\n";
    {
        ShaderCompiler compiler(mRoot, mRoot / "cache");
        CompiledShader warm = compiler.compile("a.comp");
        EXPECT_TRUE(warm.fromCache);
        EXPECT_EQ(warm.spirv, b.spirv) << "the ref was not what found the SPIR-V";
    }
    std::ofstream(refA) << "0123456789abcdef\n"; // points to nothing
    {
        ShaderCompiler compiler(mRoot, mRoot / "cache");
        CompiledShader warm = compiler.compile("a.comp");
        EXPECT_TRUE(warm.fromCache); // found by the expanded text's hash
        EXPECT_EQ(warm.spirv, a.spirv);
    }
    std::string rewritten;
    std::ifstream(refA) >> rewritten;
    EXPECT_NE(rewritten, "0123456789abcdef");
    EXPECT_NE(rewritten, hexB);
    EXPECT_EQ(rewritten.size(), 16u);
}

TEST(Shaders, EveryShippedShaderCompiles) {
    ShaderCompiler compiler(defaultShaderDir(), defaultCacheDir(), false);
    int count = 0;
    for (const auto& entry : fs::recursive_directory_iterator(defaultShaderDir())) {
        std::string ext = entry.path().extension().string();
        if (ext != ".comp" && ext != ".vert" && ext != ".frag") continue;
        std::string rel = fs::relative(entry.path(), defaultShaderDir()).generic_string();
        EXPECT_NO_THROW(compiler.compile(rel)) << rel;
        ++count;
    }
    EXPECT_GE(count, 5);
}

} // namespace
} // namespace vitrine
