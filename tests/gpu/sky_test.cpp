// sky.procedural against the CPU Preetham model (core/shading/sky.cpp, written separately from
// the GLSL), its SH against a CPU projection of the read-back cube map, the sun's energy in the
// cube map against its illuminance, and sky.hdri on a synthetic equirect EXR.
#include "tests/gpu/gpu_test.hpp"
#include "tests/gpu/test_nodes.hpp"

#include "core/base/error.hpp"
#include "core/image/io.hpp"
#include "core/shading/cubemap.hpp"
#include "core/shading/sky.hpp"
#include "shaders/sky/sky.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <numbers>

namespace vitrine::test {
namespace {

using nlohmann::json;
constexpr double kPi = std::numbers::pi;

json graph(json nodes, json outputs) {
    return {{"format", "vitrine-graph/1"},
            {"frame", {{"width", 16}, {"height", 16}}},
            {"nodes", nodes},
            {"outputs", outputs}};
}

json skyNode(double turbidity, double elevation, double azimuth, int size, bool sun) {
    return {{"type", "sky.procedural"},
            {"params",
             {{"turbidity", turbidity},
              {"sun_elevation", elevation},
              {"sun_azimuth", azimuth},
              {"ground_albedo", 0.2},
              {"size", size},
              {"sun_in_cubemap", sun}}}};
}

glm::dvec3 texel(const Image& img, int x) {
    return {img.at(x, 0)[0], img.at(x, 0)[1], img.at(x, 0)[2]};
}

shading::Sh9 readSh(const Image& sh) {
    shading::Sh9 s;
    for (int i = 0; i < 9; ++i)
        s.c[i] = texel(sh, i);
    return s;
}

double relDiff(glm::dvec3 a, glm::dvec3 b) {
    return glm::length(a - b) / std::max(glm::length(b), 1e-30);
}

class Sky : public GpuTest {};

TEST_F(Sky, ProceduralMatchesCpuPreethamAndItsShTheCubeMap) {
    const int size = 16;
    const double T = 3.0, elevation = 35.0, azimuth = 40.0;
    auto out = runGraph(graph({{"sky", skyNode(T, elevation, azimuth, size, false)},
                               {"unfold", {{"type", "test.cube_unfold"}, {"in", {{"cube", "sky.cubemap"}}}}}},
                              {{"faces", "unfold.faces"}, {"sh", "sky.sh"}}));
    const Image& faces = out.at("faces");
    const Image& sh = out.at("sh");
    ASSERT_EQ(faces.width, 6 * size);
    shading::PreethamSky cpu(T, shading::sunDirection(elevation, azimuth), 0.2);
    double worstSky = 0.0, worstGround = 0.0;
    for (int f = 0; f < 6; ++f)
        for (int y = 0; y < size; ++y)
            for (int x = 0; x < size; ++x) {
                glm::dvec3 d = shading::cubeTexelDirection(f, x, y, size);
                double e = relDiff(cubeTexel(faces, f, x, y), cpu.radiance(d));
                (d.y >= 0.0 ? worstSky : worstGround) = std::max(d.y >= 0.0 ? worstSky : worstGround, e);
            }
    std::printf("sky.procedural vs CPU Preetham: max relative error sky %.2g, ground %.2g\n", worstSky, worstGround);
    EXPECT_LT(worstSky, 2e-3);    // fp32 vs fp64 of the same formulas
    EXPECT_LT(worstGround, 1e-2); // the GPU integrates the sky's irradiance on a 32 x 64 grid

    shading::Sh9 gpuSh = readSh(sh);
    shading::Sh9 cpuSh = shading::projectCube(size, [&](int f, int x, int y) { return cubeTexel(faces, f, x, y); });
    for (int i = 0; i < 9; ++i)
        EXPECT_LT(glm::length(gpuSh.c[i] - cpuSh.c[i]), 1e-4 * glm::length(cpuSh.c[0])) << i;

    glm::dvec3 sunE = texel(sh, SKY_TEXEL_SUN_ILLUMINANCE);
    EXPECT_LT(relDiff(sunE, cpu.sunIlluminance()), 2e-3);
    EXPECT_LT(glm::length(texel(sh, SKY_TEXEL_SUN_DIRECTION) - shading::sunDirection(elevation, azimuth)), 1e-5);
    glm::dvec3 info = texel(sh, SKY_TEXEL_SUN_INFO);
    EXPECT_NEAR(info.x, shading::luminance709(cpu.sunRadiance()), 2e-3 * info.x);
    EXPECT_NEAR(info.y, 0.2665 * kPi / 180.0, 1e-7);
    EXPECT_NEAR(info.z, T, 1e-6);
    // The SH holds the sky only: what it gives a surface facing the sun is far below the sun.
    double skyOnSunFacing =
        shading::luminance709(shading::shIrradiance(gpuSh, shading::sunDirection(elevation, azimuth)));
    std::printf("sun %.0f lux, sky on a sun-facing surface (SH) %.0f lux\n", shading::luminance709(sunE),
                skyOnSunFacing);
    EXPECT_GT(skyOnSunFacing, 0.0);
    EXPECT_LT(skyOnSunFacing, 0.5 * shading::luminance709(sunE));
}

TEST_F(Sky, SunDiskInTheCubeMapCarriesTheSunsIlluminance) {
    const int size = 32;
    auto out = runGraph(graph({{"on", skyNode(2.5, 52.0, -130.0, size, true)},
                               {"off", skyNode(2.5, 52.0, -130.0, size, false)},
                               {"u_on", {{"type", "test.cube_unfold"}, {"in", {{"cube", "on.cubemap"}}}}},
                               {"u_off", {{"type", "test.cube_unfold"}, {"in", {{"cube", "off.cubemap"}}}}}},
                              {{"on", "u_on.faces"}, {"off", "u_off.faces"}, {"sh", "on.sh"}}));
    glm::dvec3 energy(0.0);
    int texels = 0;
    const glm::dvec3 toSun = shading::sunDirection(52.0, -130.0);
    for (int f = 0; f < 6; ++f)
        for (int y = 0; y < size; ++y)
            for (int x = 0; x < size; ++x) {
                glm::dvec3 diff = cubeTexel(out["on"], f, x, y) - cubeTexel(out["off"], f, x, y);
                if (glm::length(diff) == 0.0) continue;
                ++texels;
                energy += diff * shading::cubeTexelSolidAngle(x, y, size);
                EXPECT_GT(glm::dot(shading::cubeTexelDirection(f, x, y, size), toSun), std::cos(4.0 / size));
            }
    glm::dvec3 sunE = texel(out["sh"], SKY_TEXEL_SUN_ILLUMINANCE);
    std::printf("sun disk: %d texels, energy %.0f lux vs illuminance %.0f lux\n", texels, shading::luminance709(energy),
                shading::luminance709(sunE));
    EXPECT_GE(texels, 1);
    EXPECT_LT(relDiff(energy, sunE), 1e-3);
}

// `intensity` scales every radiance the node outputs: the cube map (sun disk included), the SH coefficients, the
// sun's illuminance and its disk radiance, by exactly that factor (a brighter day, the light camera.physical meters).
TEST_F(Sky, IntensityScalesSkySunAndGroundAlike) {
    const int size = 16;
    json bright = skyNode(2.5, 40.0, 30.0, size, true);
    bright["params"]["intensity"] = 8.0;
    auto out = runGraph(graph({{"one", skyNode(2.5, 40.0, 30.0, size, true)},
                               {"eight", bright},
                               {"u_one", {{"type", "test.cube_unfold"}, {"in", {{"cube", "one.cubemap"}}}}},
                               {"u_eight", {{"type", "test.cube_unfold"}, {"in", {{"cube", "eight.cubemap"}}}}}},
                              {{"one", "u_one.faces"}, {"eight", "u_eight.faces"}, {"sh_one", "one.sh"}, {"sh_eight", "eight.sh"}}));
    double worst = 0.0;
    for (int f = 0; f < 6; ++f)
        for (int y = 0; y < size; ++y)
            for (int x = 0; x < size; ++x)
                worst = std::max(worst, relDiff(cubeTexel(out["eight"], f, x, y), 8.0 * cubeTexel(out["one"], f, x, y)));
    for (int i : {0, 1, 2, 3, 4, 5, 6, 7, 8, SKY_TEXEL_SUN_ILLUMINANCE})
        worst = std::max(worst, relDiff(texel(out["sh_eight"], i), 8.0 * texel(out["sh_one"], i)));
    worst = std::max(worst, std::abs(out["sh_eight"].at(SKY_TEXEL_SUN_INFO, 0)[0] / (8.0 * out["sh_one"].at(SKY_TEXEL_SUN_INFO, 0)[0]) - 1.0));
    // The direction and the rest of the sun's info do not change.
    EXPECT_EQ(texel(out["sh_eight"], SKY_TEXEL_SUN_DIRECTION), texel(out["sh_one"], SKY_TEXEL_SUN_DIRECTION));
    EXPECT_EQ(out["sh_eight"].at(SKY_TEXEL_SUN_INFO, 0)[1], out["sh_one"].at(SKY_TEXEL_SUN_INFO, 0)[1]);
    std::printf("sky intensity 8: largest relative difference from 8x intensity 1: %.2g\n", worst);
    EXPECT_LT(worst, 1e-5);
}

TEST_F(Sky, SunIlluminanceFallsWithElevation) {
    const double elevations[] = {85.0, 60.0, 40.0, 20.0, 8.0, 2.0};
    json nodes, outputs;
    for (int i = 0; i < 6; ++i) {
        nodes["s" + std::to_string(i)] = skyNode(2.5, elevations[i], 0.0, 8, false);
        outputs["sh" + std::to_string(i)] = "s" + std::to_string(i) + ".sh";
    }
    auto out = runGraph(graph(nodes, outputs));
    double previous = 1e12;
    for (int i = 0; i < 6; ++i) {
        double lux = shading::luminance709(texel(out["sh" + std::to_string(i)], SKY_TEXEL_SUN_ILLUMINANCE));
        std::printf("turbidity 2.5, elevation %4.1f: sun %.0f lux\n", elevations[i], lux);
        EXPECT_LT(lux, previous);
        previous = lux;
        if (elevations[i] >= 60.0) {
            EXPECT_GT(lux, 80000.0);
            EXPECT_LT(lux, 120000.0);
        }
    }
}

TEST_F(Sky, CubeMapFacesMatchTheHardwareSamplersConvention) {
    const int size = 16;
    auto out = runGraph(graph({{"sky", skyNode(4.0, 20.0, 75.0, size, false)},
                               {"unfold", {{"type", "test.cube_unfold"}, {"in", {{"cube", "sky.cubemap"}}}}},
                               {"sample", {{"type", "test.cube_sample"}, {"in", {{"cube", "sky.cubemap"}}}}}},
                              {{"loaded", "unfold.faces"}, {"sampled", "sample.faces"}}));
    double worst = 0.0;
    for (int f = 0; f < 6; ++f)
        for (int y = 0; y < size; ++y)
            for (int x = 0; x < size; ++x)
                worst = std::max(worst, relDiff(cubeTexel(out["sampled"], f, x, y), cubeTexel(out["loaded"], f, x, y)));
    EXPECT_LT(worst, 1e-3); // a texel-centre lookup returns that texel
}

// Equirect written independently of core/shading/environment.cpp: column u looks toward
// azimuth 2 pi u - pi (from -Z toward +X), row v toward elevation pi/2 - pi v.
Image syntheticEquirect(int w, int h, glm::dvec3 sky, glm::dvec3 disk, double elevation, double azimuth,
                        double radius) {
    Image img(w, h);
    auto dir = [](double az, double el) {
        return glm::dvec3(std::cos(el) * std::sin(az), std::sin(el), -std::cos(el) * std::cos(az));
    };
    glm::dvec3 center = dir(azimuth, elevation);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            int inside = 0;
            for (int sy = 0; sy < 8; ++sy)
                for (int sx = 0; sx < 8; ++sx) {
                    double u = (x + (sx + 0.5) / 8) / w, v = (y + (sy + 0.5) / 8) / h;
                    inside += glm::dot(dir(2 * kPi * u - kPi, kPi / 2 - kPi * v), center) > std::cos(radius);
                }
            glm::dvec3 c = sky + (disk - sky) * (inside / 64.0);
            float* p = img.at(x, y);
            p[0] = static_cast<float>(c.x);
            p[1] = static_cast<float>(c.y);
            p[2] = static_cast<float>(c.z);
            p[3] = 1.0f;
        }
    return img;
}

TEST_F(Sky, HdriFindsTheSunAndKeepsItOutOfTheSh) {
    const glm::dvec3 sky(0.3, 0.5, 0.9), disk(3e4, 2.8e4, 2.5e4);
    const double elevation = 40.0, azimuth = 150.0, radius = 2.0 * kPi / 180.0, intensity = 1.5;
    auto path = std::filesystem::temp_directory_path() / "vitrine_gpu_sky_hdri_test.exr";
    writeExr(path, syntheticEquirect(256, 128, sky, disk, elevation * kPi / 180.0, azimuth * kPi / 180.0, radius),
             ExrPixelType::Float);
    auto out = runGraph(graph(
        {{"sky", {{"type", "sky.hdri"}, {"params", {{"path", path.string()}, {"intensity", intensity}, {"size", 16}}}}},
         {"unfold", {{"type", "test.cube_unfold"}, {"in", {{"cube", "sky.cubemap"}}}}}},
        {{"faces", "unfold.faces"}, {"sh", "sky.sh"}}));
    std::filesystem::remove(path);
    const Image& sh = out.at("sh");
    glm::dvec3 toSun = shading::sunDirection(elevation, azimuth);
    double angle =
        std::acos(std::clamp(glm::dot(glm::normalize(texel(sh, SKY_TEXEL_SUN_DIRECTION)), toSun), -1.0, 1.0));
    glm::dvec3 expected = intensity * (disk - sky) * (kPi * std::sin(radius) * std::sin(radius));
    glm::dvec3 sunE = texel(sh, SKY_TEXEL_SUN_ILLUMINANCE);
    std::printf("sky.hdri: sun direction off by %.3f deg, illuminance %.1f vs %.1f (lux if the file is in cd/m^2)\n",
                angle * 180.0 / kPi, shading::luminance709(sunE), shading::luminance709(expected));
    EXPECT_LT(angle, kPi / 180.0);
    EXPECT_LT(relDiff(sunE, expected), 0.03);
    shading::Sh9 s = readSh(sh);
    for (glm::dvec3 n : {glm::dvec3(0, 1, 0), glm::dvec3(0, -1, 0), toSun, glm::dvec3(1, 0, 0)})
        EXPECT_LT(relDiff(shading::shIrradiance(s, n), intensity * kPi * sky), 0.01);
    // Away from the sun the cube map is the sky, times the intensity.
    const Image& faces = out.at("faces");
    EXPECT_LT(relDiff(cubeTexel(faces, 3, 8, 8), intensity * sky), 1e-5);
}

TEST_F(Sky, HdriMissingFileIsAUserErrorNamingIt) {
    json g = graph({{"sky", {{"type", "sky.hdri"}, {"params", {{"path", "/nonexistent/dir/sky_missing.exr"}}}}}},
                   {{"sh", "sky.sh"}});
    try {
        runGraph(g);
        FAIL() << "expected a UserError";
    } catch (const UserError& e) {
        std::string m = e.what();
        EXPECT_NE(m.find("sky_missing.exr"), std::string::npos) << m;
        EXPECT_NE(m.find("/nodes/sky/params/path"), std::string::npos) << m;
    }
}

} // namespace
} // namespace vitrine::test
