#include "core/image/color.hpp"

#include "support.hpp"

#include <glslang/Public/ResourceLimits.h>
#include <glslang/Public/ShaderLang.h>
#include <glslang/SPIRV/GlslangToSpv.h>

#include <fstream>

namespace vitrine::test {
namespace {

using GlslTest = ImageTest;

// Compiles a compute shader for Vulkan the way the renderer will; returns glslang's log, empty on success.
std::string compileCompute(const std::string& source) {
    static const bool kInitialised = glslang::InitializeProcess();
    EXPECT_TRUE(kInitialised);
    glslang::TShader shader(EShLangCompute);
    const char* text = source.c_str();
    shader.setStrings(&text, 1);
    shader.setEnvInput(glslang::EShSourceGlsl, EShLangCompute, glslang::EShClientVulkan, 100);
    shader.setEnvClient(glslang::EShClientVulkan, glslang::EShTargetVulkan_1_3);
    shader.setEnvTarget(glslang::EShTargetSpv, glslang::EShTargetSpv_1_6);
    const auto messages = static_cast<EShMessages>(EShMsgSpvRules | EShMsgVulkanRules);
    if (!shader.parse(GetDefaultResources(), 460, false, messages)) return shader.getInfoLog();
    glslang::TProgram program;
    program.addShader(&shader);
    if (!program.link(messages)) return program.getInfoLog();
    std::vector<uint32_t> spirv;
    glslang::GlslangToSpv(*program.getIntermediate(EShLangCompute), spirv);
    return spirv.empty() ? "no SPIR-V produced" : "";
}

// The GLSL pasted after the version line, as the display pass will do.
std::string computeShaderAround(const std::string& functions, const std::string& call) {
    return "#version 460\n"
           "layout(local_size_x = 8, local_size_y = 8) in;\n"
           "layout(set = 0, binding = 0, rgba32f) uniform image2D uImage;\n" +
           functions +
           "\nvoid main() {\n"
           "    ivec2 p = ivec2(gl_GlobalInvocationID.xy);\n"
           "    imageStore(uImage, p, " +
           call +
           "(imageLoad(uImage, p)));\n"
           "}\n";
}

TEST_F(GlslTest, HarnessRejectsBrokenGlsl) {
    EXPECT_NE(compileCompute(computeShaderAround("vec4 broken(vec4 c) { return c.rgbq; }", "broken")), "");
}

TEST_F(GlslTest, DisplayShaderCompilesAsVulkanGlsl460) {
    const ColorConfig& config = ColorConfig::builtin();
    const std::string standard = config.displayShaderGlsl("scene_linear", "sRGB", "Standard", "vitrineDisplay");
    EXPECT_NE(standard.find("vec4 vitrineDisplay(vec4 inPixel)"), std::string::npos) << standard;
    EXPECT_NE(standard.find("pow("), std::string::npos) << "expected the sRGB curve:\n" << standard;
    EXPECT_EQ(compileCompute(computeShaderAround(standard, "vitrineDisplay")), "") << standard;

    // Two transforms in one shader must not collide.
    const std::string acescg = config.displayShaderGlsl("ACEScg", "sRGB", "Standard", "fromAcescg");
    const std::string raw = config.displayShaderGlsl("scene_linear", "sRGB", "Raw", "rawDisplay");
    EXPECT_EQ(compileCompute(computeShaderAround(standard + acescg + raw, "fromAcescg")), "") << acescg;
}

TEST_F(GlslTest, BadFunctionNameIsAnInternalError) {
    EXPECT_THROW(ColorConfig::builtin().displayShaderGlsl("scene_linear", "sRGB", "Standard", "1st"), InternalError);
    EXPECT_THROW(ColorConfig::builtin().displayShaderGlsl("scene_linear", "sRGB", "Standard", "gl_x"), InternalError);
}

// A view through a 1D LUT file needs a texture, which the GPU display pass cannot bind.
TEST_F(GlslTest, TransformsNeedingLutTexturesAreRefused) {
    std::ofstream(file("curve.spi1d")) << "Version 1\nFrom 0.0 1.0\nLength 3\nComponents 1\n{\n0.0\n0.1\n1.0\n}\n";
    std::ofstream(file("lut.ocio")) << R"(ocio_profile_version: 2.1
search_path: "."
roles:
  default: linear
  scene_linear: linear
file_rules:
  - !<Rule> {name: Default, colorspace: default}
displays:
  screen:
    - !<View> {name: Curve, colorspace: curve}
colorspaces:
  - !<ColorSpace>
    name: linear
  - !<ColorSpace>
    name: curve
    from_scene_reference: !<FileTransform> {src: curve.spi1d, interpolation: linear}
)";
    const ColorConfig config(file("lut.ocio"));
    const Image image = patternImage(3, 2, 1.0f, 0.0f);
    EXPECT_NE(config.toDisplay(image, "scene_linear", "screen", "Curve").pixels, image.pixels); // the CPU path works
    EXPECT_THROW(config.displayShaderGlsl("scene_linear", "screen", "Curve", "curve"), InternalError);
}

} // namespace
} // namespace vitrine::test
