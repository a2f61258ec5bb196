// glTF material extensions drawn (issue #29 item 4): the corpus files of tests/data/gltf/corpus/ (validated by ctest
// gltf.validator) through scene.gltf into gbuffer.layered, whose base colour, metallic, shininess and emissive pixels
// are checked against the values worked out by hand in make_corpus.py (asset.extras.expect). Every file is seen by an
// orthographic camera (xmag = ymag = 2 at z = 5): in a W x W frame, world (x, y) is pixel ((x + 2) / 4 W, (2 − y) / 4
// W).
#include "tests/gpu/gpu_test.hpp"

#include <cmath>
#include <cstdio>
#include <fstream>

namespace vitrine::test {
namespace {

using nlohmann::json;

constexpr int kSize = 128;

std::filesystem::path corpus(const std::string& name) {
    return std::filesystem::path(VITRINE_SOURCE_DIR) / "tests" / "data" / "gltf" / "corpus" / name;
}

json expected(const std::string& file) {
    std::ifstream in(corpus(file));
    return json::parse(in)["asset"]["extras"]["expect"];
}

std::map<std::string, Image> gbuffer(const std::string& file, const std::string& variant = "") {
    json params = {{"path", corpus(file).string()}, {"jitter", "off"}};
    if (!variant.empty()) params["material_variant"] = variant;
    json graph = {
        {"format", "vitrine-graph/1"},
        {"frame", {{"width", kSize}, {"height", kSize}}},
        {"nodes",
         {{"scene", {{"type", "scene.gltf"}, {"params", params}}},
          {"gbuffer",
           {{"type", "gbuffer.layered"}, {"in", {{"scene", "scene.scene"}}}, {"params", {{"toksvig", false}}}}}}},
        {"outputs",
         {{"base_color", "gbuffer.base_color"},
          {"normal", "gbuffer.normal"},
          {"emissive", "gbuffer.emissive"},
          {"material", "gbuffer.material"},
          {"sheen", "gbuffer.sheen"}}}};
    return runGraph(graph);
}

glm::ivec2 pixelAt(double x, double y) {
    return {static_cast<int>((x + 2.0) / 4.0 * kSize), static_cast<int>((2.0 - y) / 4.0 * kSize)};
}

glm::vec4 texel(const Image& image, glm::ivec2 p) {
    const float* v = image.at(p.x, p.y);
    return {v[0], v[1], v[2], v[3]};
}

class GltfMaterials : public GpuTest {};

// Quadrant centres: the grey dielectric (top left), gold (top right), the grey half-metal (bottom left); the textured
// material (bottom right) has its 2x2 texels at (1 ± 0.5, −1 ± 0.5). base_color is RGBA8 UNORM (linear base colour,
// metallic in alpha): half a step is 0.002; normal.w is shininess = 1 − roughness (Toksvig off), half floats.
TEST_F(GltfMaterials, SpecularGlossinessConvertedMaterialsReachTheGbuffer) {
    json want = expected("spec_gloss.gltf");
    auto out = gbuffer("spec_gloss.gltf");
    const Image& base = out.at("base_color");
    const Image& normal = out.at("normal");
    const glm::dvec2 factorCentres[] = {{-1, 1}, {1, 1}, {-1, -1}};
    for (int i = 0; i < 3; ++i) {
        glm::ivec2 p = pixelAt(factorCentres[i].x, factorCentres[i].y);
        glm::vec4 got = texel(base, p);
        std::printf("spec-gloss %s: base (%.4f %.4f %.4f) metallic %.4f shininess %.4f\n",
                    want["quadrants"][i].get<std::string>().c_str(), got.r, got.g, got.b, got.a, texel(normal, p).w);
        for (int c = 0; c < 3; ++c)
            EXPECT_NEAR(got[c], want["base_color"][i][c].get<float>(), 0.5f / 255 + 1e-4f) << i << " channel " << c;
        EXPECT_NEAR(got.a, want["metallic"][i].get<float>(), 0.5f / 255 + 1e-4f) << i;
        EXPECT_NEAR(texel(normal, p).w, 1.0f - want["roughness"][i].get<float>(), 1e-3f) << i;
    }
    for (int t = 0; t < 4; ++t) {
        glm::ivec2 p = pixelAt(0.5 + (t % 2), -0.5 - (t / 2));
        glm::vec4 got = texel(base, p);
        std::printf("spec-gloss texel %d: base (%.4f %.4f %.4f) metallic %.4f shininess %.4f\n", t, got.r, got.g, got.b,
                    got.a, texel(normal, p).w);
        // The converted texture is 8-bit sRGB, then written as 8-bit linear: up to 0.003 + 0.002 apart.
        for (int c = 0; c < 3; ++c)
            EXPECT_NEAR(got[c], want["texels_base_color"][t][c].get<float>(), 0.006f)
                << "texel " << t << " channel " << c;
        EXPECT_NEAR(got.a, want["texels_metallic"][t].get<float>(), 1.0f / 255 + 1e-4f) << "texel " << t;
        EXPECT_NEAR(texel(normal, p).w, 1.0f - want["texels_roughness"][t].get<float>(), 1.0f / 255 + 1e-3f)
            << "texel " << t;
    }
}

TEST_F(GltfMaterials, EmissiveStrengthScalesTheGbufferEmissive) {
    json want = expected("emissive_strength.gltf");
    Image emissive = gbuffer("emissive_strength.gltf").at("emissive");
    glm::vec4 left = texel(emissive, pixelAt(-1, 0)), right = texel(emissive, pixelAt(1, 0));
    std::printf("emissive: strength 4 (%.3f %.3f %.3f), without (%.3f %.3f %.3f)\n", left.r, left.g, left.b, right.r,
                right.g, right.b);
    for (int c = 0; c < 3; ++c) {
        EXPECT_NEAR(left[c], want["left_emissive"][c].get<float>(), 2e-3f) << c;
        EXPECT_NEAR(right[c], want["right_emissive"][c].get<float>(), 1e-3f) << c;
    }
}

// variants.gltf: the left quad is white by default, red or blue in those variants; the right one has no mapping.
TEST_F(GltfMaterials, MaterialVariantChangesTheDrawnBaseColour) {
    const std::pair<std::string, glm::vec3> cases[] = {
        {"", glm::vec3(1, 1, 1)}, {"red", glm::vec3(1, 0, 0)}, {"blue", glm::vec3(0, 0, 1)}};
    for (const auto& [variant, colour] : cases) {
        Image base = gbuffer("variants.gltf", variant).at("base_color");
        glm::vec4 left = texel(base, pixelAt(-1, 0)), right = texel(base, pixelAt(1, 0));
        std::printf("variant '%s': left (%.3f %.3f %.3f), right (%.3f %.3f %.3f)\n", variant.c_str(), left.r, left.g,
                    left.b, right.r, right.g, right.b);
        for (int c = 0; c < 3; ++c) {
            EXPECT_NEAR(left[c], colour[c], 1e-3f) << variant << " " << c;
            EXPECT_NEAR(right[c], 1.0f, 1e-3f) << variant << " " << c;
        }
    }
}

// specular.gltf: KHR_materials_specular's strength k reaches the G-buffer as material.y = 1 - k (UNORM8: the expected
// values are multiples of 1/255 but for the textured ones, 1 - alpha/255 exactly too); a material without the
// extension (variants.gltf) keeps 0 there, the value the channel had before it carried anything.
TEST_F(GltfMaterials, SpecularStrengthReachesTheGbuffer) {
    json want = expected("specular.gltf");
    const Image& material = gbuffer("specular.gltf").at("material");
    const glm::dvec2 centres[] = {{-1, 1}, {1, 1}, {-1, -1}};
    for (int i = 0; i < 3; ++i) {
        float got = texel(material, pixelAt(centres[i].x, centres[i].y)).y;
        std::printf("specular %s: material.y %.4f\n", want["quadrants"][i].get<std::string>().c_str(), got);
        EXPECT_NEAR(got, want["material_y"][i].get<float>(), 0.5f / 255) << i;
    }
    for (int t = 0; t < 4; ++t) {
        float got = texel(material, pixelAt(0.5 + (t % 2), -0.5 - (t / 2))).y;
        std::printf("specular texel %d: material.y %.4f\n", t, got);
        EXPECT_NEAR(got, want["texels_material_y"][t].get<float>(), 0.5f / 255) << "texel " << t;
    }
    const Image& plain = gbuffer("variants.gltf").at("material");
    EXPECT_EQ(texel(plain, pixelAt(-1, 0)).y, 0.0f);
    EXPECT_EQ(texel(plain, pixelAt(1, 0)).y, 0.0f);
}

// clearcoat.gltf: KHR_materials_clearcoat's strength c and roughness r reach the G-buffer packed into the emissive
// alpha (gbuffer/clearcoat_pack.glsl) as 2 (32 q(c) + q(r)), q(x) = floor(31 x + 0.5), worked out here from the values
// the file states; fp16 holds these integers exactly. The textured quadrant's texels multiply the factors by the red
// (strength) and green (roughness) channels. A material without the extension keeps alpha 0 (not lightmapped).
TEST_F(GltfMaterials, ClearcoatReachesTheGbufferEmissiveAlpha) {
    json want = expected("clearcoat.gltf");
    auto pack = [](double c, double r) { return 2.0 * (32.0 * std::floor(31.0 * c + 0.5) + std::floor(31.0 * r + 0.5)); };
    const Image& emissive = gbuffer("clearcoat.gltf").at("emissive");
    const glm::dvec2 centres[] = {{-1, 1}, {1, 1}, {-1, -1}};
    for (int i = 0; i < 3; ++i) {
        glm::vec4 got = texel(emissive, pixelAt(centres[i].x, centres[i].y));
        double c = want["clearcoat"][i].get<double>(), r = want["roughness"][i].get<double>();
        std::printf("clearcoat %s: emissive.a %.1f\n", want["quadrants"][i].get<std::string>().c_str(), got.w);
        EXPECT_EQ(got.w, static_cast<float>(pack(c, r))) << i;
        EXPECT_EQ(glm::vec3(got), glm::vec3(0.0f)) << i;
    }
    for (int t = 0; t < 4; ++t) {
        float got = texel(emissive, pixelAt(0.5 + (t % 2), -0.5 - (t / 2))).w;
        double c = want["texels_clearcoat"][t].get<double>(), r = want["texels_roughness"][t].get<double>();
        std::printf("clearcoat texel %d: emissive.a %.1f\n", t, got);
        EXPECT_EQ(got, static_cast<float>(pack(c, r))) << "texel " << t;
    }
    const Image& plain = gbuffer("variants.gltf").at("emissive");
    EXPECT_EQ(texel(plain, pixelAt(-1, 0)).w, 0.0f);
}

// sheen.gltf: KHR_materials_sheen reaches the G-buffer's sheen target (RGBA8 UNORM: colour, roughness), worked out
// here from the values the file states (the spheres' centres face the camera; the textured quad's texels multiply
// the factors by the sRGB colour and by alpha), to half an 8-bit step. The sheen leaves the other targets as they are
// without it: no coat in emissive.a and the base colour's alpha (1) in material.x. The black sheen is no sheen: 0.
TEST_F(GltfMaterials, SheenReachesItsGbufferTarget) {
    json want = expected("sheen.gltf");
    auto check = [&](glm::ivec2 p, const std::map<std::string, Image>& images, glm::dvec3 c, double r,
                     const std::string& what) {
        glm::vec4 got = texel(images.at("sheen"), p);
        std::printf("sheen %s: (%.4f, %.4f, %.4f), roughness %.4f\n", what.c_str(), got.r, got.g, got.b, got.a);
        glm::dvec4 expected = c == glm::dvec3(0.0) ? glm::dvec4(0.0) : glm::dvec4(c, r);
        for (int k = 0; k < 4; ++k)
            EXPECT_NEAR(got[k], expected[k], 0.5 / 255.0 + 1e-4) << what << " channel " << k;
        EXPECT_EQ(texel(images.at("emissive"), p).w, 0.0f) << what;
        EXPECT_EQ(texel(images.at("material"), p).x, 1.0f) << what;
    };
    auto images = gbuffer("sheen.gltf");
    const glm::dvec2 centres[] = {{-1, 1}, {1, 1}, {-1, -1}};
    for (int i = 0; i < 3; ++i) {
        glm::ivec2 p = pixelAt(centres[i].x, centres[i].y);
        json c = want["sheen_color"][i];
        check(p, images, {c[0].get<double>(), c[1].get<double>(), c[2].get<double>()},
              want["roughness"][i].get<double>(), want["quadrants"][i].get<std::string>());
        EXPECT_EQ(glm::vec3(texel(images.at("emissive"), p)), glm::vec3(0.0f)) << i;
    }
    for (int t = 0; t < 4; ++t) {
        glm::ivec2 p = pixelAt(0.5 + (t % 2), -0.5 - (t / 2));
        json c = want["texels_color"][t];
        glm::dvec3 colour(c[0].get<double>(), c[1].get<double>(), c[2].get<double>());
        check(p, images, colour, want["texels_roughness"][t].get<double>(), "texel " + std::to_string(t));
    }
}

} // namespace
} // namespace vitrine::test
