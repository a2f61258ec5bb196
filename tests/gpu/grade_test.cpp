// color.grade on the GPU (OCIO's generated GLSL, its 3D LUT uploaded as a texture) against OCIO's CPU processor on
// the same pixels (core/image/grade.cpp's apply(), OCIO's own CPU code path): exposure/contrast, ASC CDL and the
// shipped .cube LUT (data/luts/warm_film.cube, made by tools/make_lut.py) with tetrahedral and trilinear
// interpolation, within 1e-4; a missing or broken LUT file is a user error naming the param and the file.
#include "tests/gpu/gpu_test.hpp"

#include "core/base/error.hpp"
#include "core/graph/compiler.hpp"
#include "core/graph/loader.hpp"
#include "core/graph/registry.hpp"
#include "core/image/color.hpp"
#include "core/image/grade.hpp"
#include "core/image/io.hpp"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <unistd.h>

namespace vitrine::test {
namespace {

using nlohmann::json;
namespace fs = std::filesystem;

class Grade : public GpuTest {};

const fs::path kLut = fs::path(VITRINE_SOURCE_DIR) / "data/luts/warm_film.cube";

fs::path scratch() {
    fs::path dir = fs::path(VITRINE_TEST_OUT) / ("grade-" + std::to_string(::getpid()));
    fs::create_directories(dir);
    return dir;
}

// Display-linear colours over the cube (a 12x8 grid of hues and levels, greys, a few values above 1 and 0).
Image testColors() {
    Image img(48, 32);
    for (int y = 0; y < img.height; ++y)
        for (int x = 0; x < img.width; ++x) {
            float* p = img.at(x, y);
            const double u = (x + 0.5) / img.width, v = (y + 0.5) / img.height;
            p[0] = float(std::pow(u, 2.2));
            p[1] = float(std::pow(v, 2.2));
            p[2] = float(std::pow(0.5 + 0.5 * std::sin(13.0 * u + 7.0 * v), 2.2));
            if (y == 0) p[0] = p[1] = p[2] = float(x) / (img.width - 1); // greys
            if (y == 1) p[0] = p[1] = p[2] = 1.0f + 0.01f * x;         // above white
            p[3] = 1.0f;
        }
    return img;
}

json gradeGraph(const fs::path& image, const json& params) {
    return {{"format", "vitrine-graph/1"},
            {"frame", {{"width", 48}, {"height", 32}}},
            {"nodes",
             {{"load", {{"type", "image.load"}, {"params", {{"path", image.string()}}}}},
              {"grade", {{"type", "color.grade"}, {"params", params}, {"in", {{"color", "load.color"}}}}}}},
            {"outputs", {{"final", "grade.color"}}}};
}

struct Case {
    const char* name;
    json params;
    GradeSettings settings;
};

TEST_F(Grade, GpuEqualsOcioCpuProcessor) {
    const Image input = testColors();
    const fs::path file = scratch() / "colors.exr";
    writeExr(file, input, ExrPixelType::Float);

    GradeSettings cdl;
    cdl.slope = {1.1f, 1.0f, 0.9f};
    cdl.offset = {0.02f, 0.0f, -0.01f};
    cdl.power = {0.9f, 1.0f, 1.2f};
    cdl.saturation = 1.3f;
    GradeSettings ec;
    ec.exposure = 0.5f;
    ec.contrast = 1.3f;
    GradeSettings lut = cdl;
    lut.lut = kLut;
    GradeSettings trilinear = lut;
    trilinear.lutTetrahedral = false;
    trilinear.exposure = -0.3f;
    const Case cases[] = {
        {"cdl",
         {{"slope", {1.1, 1.0, 0.9}}, {"offset", {0.02, 0.0, -0.01}}, {"power", {0.9, 1.0, 1.2}}, {"saturation", 1.3}},
         cdl},
        {"exposure/contrast", {{"exposure", 0.5}, {"contrast", 1.3}}, ec},
        {"cdl + .cube tetrahedral",
         {{"slope", {1.1, 1.0, 0.9}}, {"offset", {0.02, 0.0, -0.01}}, {"power", {0.9, 1.0, 1.2}}, {"saturation", 1.3},
          {"lut", kLut.string()}},
         lut},
        {"cdl + .cube trilinear + exposure",
         {{"slope", {1.1, 1.0, 0.9}}, {"offset", {0.02, 0.0, -0.01}}, {"power", {0.9, 1.0, 1.2}}, {"saturation", 1.3},
          {"lut", kLut.string()}, {"lut_interpolation", "linear"}, {"exposure", -0.3}},
         trilinear},
    };
    for (const Case& c : cases) {
        Image cpu = input;
        vitrine::Grade(ColorConfig::builtin(), c.settings).apply(cpu);
        const Image gpuOut = runGraph(gradeGraph(file, c.params)).at("final");
        const double diff = maxAbsDiff(gpuOut, cpu);
        EXPECT_LT(diff, 1e-4) << c.name;
        EXPECT_GT(maxAbsDiff(cpu, input), 0.02) << c.name << ": the grade changes nothing, the test would be vacuous";
        std::printf("%s: GPU vs OCIO CPU max |diff| %.3g\n", c.name, diff);
    }
}

void expectRefused(const json& doc, const std::string& pointer, const std::string& words) {
    try {
        compileGraph(validateGraph(doc, "grade-test.json", NodeRegistry::global()));
        ADD_FAILURE() << "accepted " << doc["nodes"]["grade"].dump();
    } catch (const UserError& e) {
        EXPECT_NE(std::string(e.what()).find(pointer), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
    }
}

TEST(GradeParams, BadLutAndColourSpaceAreUserErrors) {
    const fs::path file = scratch() / "small.exr";
    writeExr(file, testColors(), ExrPixelType::Float);
    const fs::path missing = scratch() / "no_such.cube";
    expectRefused(gradeGraph(file, {{"lut", missing.string()}}), "/nodes/grade/params/lut", missing.string());
    const fs::path broken = scratch() / "broken.cube";
    std::ofstream(broken) << "LUT_3D_SIZE 17\n0.1 0.2\nnot numbers\n";
    expectRefused(gradeGraph(file, {{"lut", broken.string()}}), "/nodes/grade/params/lut", broken.string());
    expectRefused(gradeGraph(file, {{"working", "Kodachrome"}}), "/nodes/grade/params/working", "Kodachrome");
}

} // namespace
} // namespace vitrine::test
