// Shader compilation: include resolution, error reporting as file:line, the SPIR-V cache.
#include "core/base/error.hpp"
#include "core/shader/compiler.hpp"
#include "core/shader/reflection.hpp"

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
