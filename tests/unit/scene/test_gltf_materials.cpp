// glTF material extensions on the corpus tests/data/gltf/corpus/ (written by make_corpus.py, validated by ctest
// gltf.validator; issue #29 item 4): KHR_materials_pbrSpecularGlossiness converted to metallic-roughness against the
// values worked out by hand in the file's asset.extras.expect and against the specular-glossiness model itself,
// KHR_materials_emissive_strength, KHR_materials_variants, KHR_materials_specular, KHR_materials_clearcoat,
// KHR_materials_sheen and KHR_materials_volume (factors, textures, errors, export), and the material extension vitrine
// ignores with a warning.

#include "core/scene/gltf.hpp"

#include "test_util.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

namespace vitrine::scene {
namespace {

std::filesystem::path corpus(const std::string& name) {
    return test::dataDir() / "corpus" / name;
}

test::Json expected(const std::string& file) {
    return test::readJson(corpus(file))["asset"]["extras"]["expect"];
}

const Material& byName(const Scene& s, const std::string& name) {
    auto it = std::find_if(s.materials.begin(), s.materials.end(), [&](const Material& m) { return m.name == name; });
    EXPECT_NE(it, s.materials.end()) << name;
    return *it;
}

double srgbDecode(uint8_t v) {
    double c = v / 255.0;
    return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
}

// Factor-only materials: the converted factors against the hand-computed ones, and the converted material put back
// through both models' definitions (glTF Appendix B and the extension): its diffuse reflectance base × 0.96 × (1 − m)
// must be the file's diffuse × (1 − max(specular)) and its f0 = mix(0.04, base, m) the file's specular (exact for
// grey colours; for gold f0 is the specular colour itself).
TEST(GltfMaterials, SpecularGlossinessFactorsConvertToMetallicRoughness) {
    std::vector<std::string> warnings;
    Scene s = loadGltf(corpus("spec_gloss.gltf"), warnings);
    EXPECT_TRUE(warnings.empty()) << warnings[0];
    // Supported, so a file may require it.
    test::Json doc = test::readJson(corpus("spec_gloss.gltf"));
    doc["extensionsRequired"] = {"KHR_materials_pbrSpecularGlossiness"};
    auto required = test::scratchDir() / "required.gltf";
    test::writeText(required, doc.dump());
    EXPECT_EQ(loadGltf(required, warnings).materials, s.materials);
    EXPECT_TRUE(warnings.empty()) << warnings[0];
    test::Json want = expected("spec_gloss.gltf");
    const char* names[] = {"grey_dielectric", "gold", "grey_half_metal"};
    const float diffuse[] = {0.5f, 0.0f, 0.3f};
    const glm::vec3 specular[] = {glm::vec3(0.04f), glm::vec3(1.0f, 0.766f, 0.336f), glm::vec3(0.5f)};
    for (int i = 0; i < 3; ++i) {
        const MaterialLayer& l = byName(s, names[i]).layers.at(0);
        SCOPED_TRACE(names[i]);
        EXPECT_FALSE(l.albedo.texture.valid());
        for (int c = 0; c < 4; ++c)
            EXPECT_NEAR(l.albedo.factor[c], want["base_color"][i][c].get<float>(), 2e-5f) << "channel " << c;
        EXPECT_NEAR(l.metallic.factor, want["metallic"][i].get<float>(), 2e-5f);
        // shininess = 1 − roughness (the scene model's reading of glTF roughness).
        EXPECT_NEAR(l.shininess.evaluate(1.0f), 1.0f - want["roughness"][i].get<float>(), 1e-6f);
        float m = l.metallic.factor, maxSpec = std::max({specular[i].r, specular[i].g, specular[i].b});
        glm::vec3 base = glm::vec3(l.albedo.factor);
        glm::vec3 f0 = glm::mix(glm::vec3(0.04f), base, m);
        for (int c = 0; c < 3; ++c) {
            EXPECT_NEAR(base[c] * 0.96f * (1.0f - m), diffuse[i] * (1.0f - maxSpec), 2e-5f) << "diffuse " << c;
            EXPECT_NEAR(f0[c], specular[i][c], 2e-5f) << "f0 " << c;
        }
    }
}

// The textured material: both textures become new scene textures, converted texel by texel: a base colour
// (sRGB) and a metallic-roughness texture (G roughness, B metallic) sampled as the diffuse texture is.
TEST(GltfMaterials, SpecularGlossinessTexturesConvertTexelByTexel) {
    Scene s = loadGltf(corpus("spec_gloss.gltf"));
    test::Json want = expected("spec_gloss.gltf");
    const MaterialLayer& l = byName(s, "textured").layers.at(0);
    ASSERT_TRUE(l.albedo.texture.valid());
    ASSERT_TRUE(l.metallic.texture.valid());
    ASSERT_EQ(l.shininess.texture, l.metallic.texture);
    EXPECT_EQ(l.albedo.factor, glm::vec4(1.0f));
    EXPECT_EQ(l.metallic.channel, 2u);
    EXPECT_EQ(l.shininess.channel, 1u);
    EXPECT_EQ(l.metallic.evaluate(0.25f), 0.25f);  // metallic = texel
    EXPECT_EQ(l.shininess.evaluate(0.25f), 0.75f); // shininess = 1 − roughness texel
    // Only the converted textures remain: the sources, read by nothing else, are dropped with their images.
    EXPECT_EQ(s.textures.size(), 2u);
    EXPECT_EQ(s.images.size(), 2u);
    const Texture& baseTex = s.textures[l.albedo.texture.texture];
    const Texture& mrTex = s.textures[l.metallic.texture.texture];
    EXPECT_EQ(baseTex.usage, TextureUsage::Color);
    EXPECT_EQ(mrTex.usage, TextureUsage::Data);
    EXPECT_EQ(baseTex.sampler.magFilter, Filter::Nearest); // the source's sampler
    const TextureImage& base = s.images[baseTex.image];
    const TextureImage& mr = s.images[mrTex.image];
    ASSERT_EQ(base.width, 2u);
    ASSERT_EQ(base.height, 2u);
    ASSERT_EQ(mr.width, 2u);
    for (uint32_t t = 0; t < 4; ++t) {
        SCOPED_TRACE("texel " + std::to_string(t));
        const uint8_t* b = base.at(t % 2, t / 2);
        const uint8_t* m = mr.at(t % 2, t / 2);
        for (int c = 0; c < 3; ++c) // 8-bit sRGB: half a step is at most 0.0025 in linear below 1
            EXPECT_NEAR(srgbDecode(b[c]), want["texels_base_color"][t][c].get<double>(), 0.003) << "channel " << c;
        EXPECT_NEAR(b[3] / 255.0, want["texels_base_color"][t][3].get<double>(), 0.5 / 255);
        EXPECT_NEAR(m[1] / 255.0, want["texels_roughness"][t].get<double>(), 0.5 / 255 + 1e-6);
        EXPECT_NEAR(m[2] / 255.0, want["texels_metallic"][t].get<double>(), 0.5 / 255 + 1e-6);
    }
    // Exported, the converted material is plain metallic-roughness and loads back the same.
    auto file = test::scratchDir() / "spec_gloss.glb";
    exportGlb(s, file);
    Scene back = loadGltf(file);
    EXPECT_EQ(byName(back, "textured"), byName(s, "textured"));
    EXPECT_EQ(byName(back, "gold"), byName(s, "gold"));
}

// A source texture that a metallic-roughness material also samples stays, unchanged, next to the converted ones.
TEST(GltfMaterials, SpecularGlossinessSourceSharedWithAnotherMaterialIsKept) {
    test::Json doc = test::readJson(corpus("spec_gloss.gltf"));
    doc["materials"].push_back({{"name", "plain"}, {"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}}}});
    doc["meshes"][0]["primitives"][0]["material"] = 4; // the grey quad: it has no UVs, only (0, 0) is sampled
    doc["meshes"][0]["primitives"][0]["attributes"]["TEXCOORD_0"] =
        doc["meshes"][3]["primitives"][0]["attributes"]["TEXCOORD_0"];
    auto file = test::scratchDir() / "shared.gltf";
    test::writeText(file, doc.dump());
    Scene s = loadGltf(file);
    ASSERT_EQ(s.textures.size(), 3u);
    ASSERT_EQ(s.images.size(), 3u);
    const TextureRef& plain = byName(s, "plain").layers.at(0).albedo.texture;
    ASSERT_TRUE(plain.valid());
    const TextureImage& image = s.images[s.textures[plain.texture].image];
    EXPECT_EQ(s.textures[plain.texture].usage, TextureUsage::Color);
    ASSERT_EQ(image.width, 2u);
    EXPECT_EQ(image.at(0, 0)[0], 128); // the file's diffuse texels
    EXPECT_EQ(image.at(1, 1)[0], 255);
    EXPECT_EQ(image.at(1, 0)[0], 0);
    const TextureRef& converted = byName(s, "textured").layers.at(0).albedo.texture;
    EXPECT_NE(converted.texture, plain.texture);
    EXPECT_EQ(s.images[s.textures[converted.texture].image].name, "diffuse base colour (from specular-glossiness)");
}

// Files converted from specular-glossiness often keep a pbrMetallicRoughness fallback for viewers without the
// extension: it is not drawn, its textures raise no "unused" warning and are dropped with the conversion's sources.
TEST(GltfMaterials, SpecularGlossinessFallbackTexturesAreNeitherWarnedNorKept) {
    test::Json doc = test::readJson(corpus("spec_gloss.gltf"));
    doc["textures"].push_back({{"source", 0}}); // a texture only the fallback names
    doc["materials"][3]["pbrMetallicRoughness"] = {{"baseColorTexture", {{"index", 2}}},
                                                   {"metallicRoughnessTexture", {{"index", 1}}}};
    doc["materials"][1]["pbrMetallicRoughness"] = {{"baseColorFactor", {0.1, 0.2, 0.3, 1.0}}, {"metallicFactor", 0.0}};
    auto file = test::scratchDir() / "fallback.gltf";
    test::writeText(file, doc.dump());
    std::vector<std::string> warnings;
    Scene s = loadGltf(file, warnings);
    EXPECT_TRUE(warnings.empty()) << warnings[0];
    EXPECT_EQ(s.textures.size(), 2u);
    EXPECT_EQ(s.images.size(), 2u);
    // The extension wins over the fallback's factors.
    EXPECT_EQ(byName(s, "gold").layers.at(0), byName(loadGltf(corpus("spec_gloss.gltf")), "gold").layers.at(0));
}

TEST(GltfMaterials, EmissiveStrengthMultipliesTheEmissiveFactor) {
    Scene s = loadGltf(corpus("emissive_strength.gltf"));
    const Material& strong = byName(s, "strong");
    const Material& plain = byName(s, "plain");
    EXPECT_EQ(strong.emissiveStrength, 4.0f);
    EXPECT_EQ(plain.emissiveStrength, 1.0f);
    // What the GPU scene uploads (gpu_scene.cpp) and the G-buffer writes: factor × strength.
    EXPECT_EQ(strong.emissiveFactor * strong.emissiveStrength, glm::vec3(4.0f, 2.0f, 1.0f));
    EXPECT_EQ(plain.emissiveFactor * plain.emissiveStrength, glm::vec3(1.0f, 0.5f, 0.25f));
}

TEST(GltfMaterials, MaterialVariantSelectsEachPrimitivesMapping) {
    auto materialOf = [](const Scene& s, const std::string& mesh) {
        for (const Mesh& m : s.meshes)
            if (m.name == mesh) return s.materials.at(s.primitives.at(m.firstPrimitive).material).name;
        return std::string("(no mesh " + mesh + ")");
    };
    std::vector<std::string> warnings;
    Scene plain = loadGltf(corpus("variants.gltf"), warnings);
    EXPECT_TRUE(warnings.empty());
    EXPECT_EQ(materialOf(plain, "mapped"), "white");
    EXPECT_EQ(materialOf(plain, "unmapped"), "white");
    Scene red = loadGltf(corpus("variants.gltf"), warnings, "red");
    EXPECT_EQ(materialOf(red, "mapped"), "red");
    EXPECT_EQ(materialOf(red, "unmapped"), "white");
    Scene blue = loadGltf(corpus("variants.gltf"), warnings, "blue");
    EXPECT_EQ(materialOf(blue, "mapped"), "blue");
    EXPECT_EQ(materialOf(blue, "unmapped"), "white");
    EXPECT_TRUE(warnings.empty());

    test::expectUserError([&] { loadGltf(corpus("variants.gltf"), warnings, "green"); },
                          {"variants.gltf: extensions.KHR_materials_variants.variants: no variant named 'green'",
                           "'red', 'blue'", "(at /extensions/KHR_materials_variants/variants)"});
    test::expectUserError([&] { loadGltf(corpus("emissive_strength.gltf"), warnings, "red"); },
                          {"material_variant 'red'", "the file defines no material variants"});
    // Its own type, so that scene.gltf blames its param material_variant rather than the file.
    EXPECT_THROW(loadGltf(corpus("variants.gltf"), warnings, "green"), UnknownMaterialVariant);

    // A mapping naming a variant the file lacks is an error at its JSON pointer (the validator's error too).
    test::Json doc = test::readJson(corpus("variants.gltf"));
    doc["meshes"][0]["primitives"][0]["extensions"]["KHR_materials_variants"]["mappings"][1]["variants"] = {2};
    auto bad = test::scratchDir() / "bad_mapping.gltf";
    test::writeText(bad, doc.dump());
    test::expectUserError(
        [&] { loadGltf(bad, warnings, "red"); },
        {"meshes[0].primitives[0].extensions.KHR_materials_variants.mappings[1].variants: 2; expected "
         "an index into the file's 2 variants",
         "(at /meshes/0/primitives/0/extensions/KHR_materials_variants/mappings/1/variants)"});
}

// A material extension vitrine does not draw gets one warning naming it, what is lost and the materials using it;
// strict loading refuses the file naming it.
TEST(GltfMaterials, IgnoredMaterialExtensionsWarnOnceEachAndStrictRefuses) {
    std::vector<std::string> warnings;
    Scene s = loadGltf(corpus("ignored_material_extensions.gltf"), warnings);
    ASSERT_EQ(warnings.size(), 1u);
    const std::string& w = warnings[0];
    EXPECT_NE(w.find("KHR_materials_iridescence"), std::string::npos) << w;
    EXPECT_NE(w.find("iridescenceFactor"), std::string::npos) << w;
    EXPECT_NE(w.find("ignored"), std::string::npos) << w;
    EXPECT_NE(w.find("(at /extensionsUsed/0)"), std::string::npos) << w;
    EXPECT_NE(w.find("of materials[0]"), std::string::npos) << w;
    // The transmission next to it is read.
    EXPECT_EQ(byName(s, "glass").transmission, 1.0f);
    test::expectUserError([&] { loadGltfReporting(corpus("ignored_material_extensions.gltf"), true); },
                          {"1 warning", "which strict loading", "KHR_materials_iridescence"});
}

// KHR_materials_specular is read, not warned about: factors, the two textures (alpha as data, rgb as sRGB colour),
// and the defaults for a material without it.
TEST(GltfMaterials, SpecularExtensionIsReadWithoutWarnings) {
    std::vector<std::string> warnings;
    Scene s = loadGltf(corpus("specular.gltf"), warnings);
    EXPECT_TRUE(warnings.empty()) << warnings[0];
    test::Json want = expected("specular.gltf");
    const char* names[] = {"weak", "none", "tinted"};
    for (int i = 0; i < 3; ++i) {
        const Material& m = byName(s, names[i]);
        SCOPED_TRACE(names[i]);
        EXPECT_EQ(m.specular, want["strength"][i].get<float>());
        for (int c = 0; c < 3; ++c)
            EXPECT_EQ(m.specularColor[c], want["color"][i][c].get<float>());
        EXPECT_FALSE(m.specularTexture.valid());
        EXPECT_FALSE(m.specularColorTexture.valid());
        EXPECT_TRUE(m.hasSpecular());
    }
    const Material& t = byName(s, "textured");
    ASSERT_TRUE(t.specularTexture.valid());
    ASSERT_TRUE(t.specularColorTexture.valid());
    EXPECT_EQ(s.textures[t.specularTexture.texture].usage, TextureUsage::Data);
    EXPECT_EQ(s.textures[t.specularColorTexture.texture].usage, TextureUsage::Color);
    EXPECT_EQ(t.specular, 1.0f);
    EXPECT_EQ(t.specularColor, glm::vec3(1.0f));
    EXPECT_TRUE(t.hasSpecular());
    EXPECT_FALSE(Material{}.hasSpecular());
    // Supported, so a file may require it.
    test::Json doc = test::readJson(corpus("specular.gltf"));
    doc["extensionsRequired"] = {"KHR_materials_specular"};
    auto required = test::scratchDir() / "specular_required.gltf";
    test::writeText(required, doc.dump());
    EXPECT_EQ(loadGltf(required, warnings).materials, s.materials);
    EXPECT_TRUE(warnings.empty()) << warnings[0];
}

TEST(GltfMaterials, SpecularExtensionOutOfRangeIsAnErrorWithItsPath) {
    test::Json doc = test::readJson(corpus("specular.gltf"));
    doc["materials"][0]["extensions"]["KHR_materials_specular"]["specularFactor"] = 1.5;
    auto file = test::scratchDir() / "specular_bad.gltf";
    test::writeText(file, doc.dump());
    test::expectUserError([&] { loadGltf(file); },
                          {"specular_bad.gltf", "materials[0].extensions.KHR_materials_specular.specularFactor",
                           "expected a number in [0, 1]"});
    doc = test::readJson(corpus("specular.gltf"));
    doc["materials"][2]["extensions"]["KHR_materials_specular"]["specularColorFactor"] = {1.0, -0.5, 0.0};
    test::writeText(file, doc.dump());
    test::expectUserError(
        [&] { loadGltf(file); },
        {"materials[2].extensions.KHR_materials_specular.specularColorFactor[1]", "expected a number >= 0"});
}

// exportGlb writes the extension back: the materials survive a round trip.
TEST(GltfMaterials, SpecularExtensionSurvivesExport) {
    Scene s = loadGltf(corpus("specular.gltf"));
    auto file = test::scratchDir() / "specular_roundtrip.glb";
    exportGlb(s, file);
    std::vector<std::string> warnings;
    Scene back = loadGltf(file, warnings);
    EXPECT_TRUE(warnings.empty()) << warnings[0];
    for (const char* name : {"weak", "none", "tinted", "textured"}) {
        const Material& a = byName(s, name);
        const Material& b = byName(back, name);
        EXPECT_EQ(a.specular, b.specular) << name;
        EXPECT_EQ(a.specularColor, b.specularColor) << name;
        EXPECT_EQ(a.specularTexture.valid(), b.specularTexture.valid()) << name;
        EXPECT_EQ(a.specularColorTexture.valid(), b.specularColorTexture.valid()) << name;
    }
}

} // namespace
// KHR_materials_clearcoat is read, not warned about: the factors, the three textures (strength and roughness as data
// with their KHR_texture_transform, the coat normal map with its scale), and a factor of 0 kept as authored.
TEST(GltfMaterials, ClearcoatExtensionIsReadWithoutWarnings) {
    std::vector<std::string> warnings;
    Scene s = loadGltf(corpus("clearcoat.gltf"), warnings);
    EXPECT_TRUE(warnings.empty()) << warnings[0];
    test::Json want = expected("clearcoat.gltf");
    const char* names[] = {"full", "half", "zero", "textured"};
    for (int i = 0; i < 4; ++i) {
        const Material& m = byName(s, names[i]);
        SCOPED_TRACE(names[i]);
        EXPECT_EQ(m.clearcoat, want["clearcoat"][i].get<float>());
        EXPECT_EQ(m.clearcoatRoughness, want["roughness"][i].get<float>());
        EXPECT_EQ(m.clearcoatTexture.valid(), i == 3);
        EXPECT_EQ(m.clearcoatRoughnessTexture.valid(), i == 3);
        EXPECT_EQ(m.clearcoatNormal.texture.valid(), i == 3);
    }
    EXPECT_FALSE(byName(s, "zero").hasClearcoat());
    EXPECT_TRUE(byName(s, "half").hasClearcoat());
    const Material& t = byName(s, "textured");
    EXPECT_EQ(s.textures[t.clearcoatTexture.texture].usage, TextureUsage::Data);
    EXPECT_EQ(s.textures[t.clearcoatRoughnessTexture.texture].usage, TextureUsage::Data);
    EXPECT_EQ(s.textures[t.clearcoatNormal.texture.texture].usage, TextureUsage::Normal);
    EXPECT_EQ(t.clearcoatNormal.scale, 0.5f);
    EXPECT_EQ(t.clearcoatTexture.transform.scale, glm::vec2(1.0f));
    EXPECT_TRUE(usesNormalMap(t)); // the coat's normal map needs the vertices' tangents
    EXPECT_FALSE(usesNormalMap(byName(s, "full")));
    EXPECT_FALSE(Material{}.hasClearcoat());
    // Supported, so a file may require it.
    test::Json doc = test::readJson(corpus("clearcoat.gltf"));
    doc["extensionsRequired"] = {"KHR_materials_clearcoat"};
    auto required = test::scratchDir() / "clearcoat_required.gltf";
    test::writeText(required, doc.dump());
    EXPECT_EQ(loadGltf(required, warnings).materials, s.materials);
    EXPECT_TRUE(warnings.empty()) << warnings[0];
}

TEST(GltfMaterials, ClearcoatExtensionOutOfRangeIsAnErrorWithItsPath) {
    auto file = test::scratchDir() / "clearcoat_bad.gltf";
    for (const char* key : {"clearcoatFactor", "clearcoatRoughnessFactor"}) {
        for (double bad : {1.5, -0.25}) {
            test::Json doc = test::readJson(corpus("clearcoat.gltf"));
            doc["materials"][1]["extensions"]["KHR_materials_clearcoat"][key] = bad;
            test::writeText(file, doc.dump());
            test::expectUserError([&] { loadGltf(file); },
                                  {"clearcoat_bad.gltf",
                                   std::string("materials[1].extensions.KHR_materials_clearcoat.") + key,
                                   "expected a number in [0, 1]"});
        }
    }
    test::Json doc = test::readJson(corpus("clearcoat.gltf"));
    doc["materials"][3]["extensions"]["KHR_materials_clearcoat"]["clearcoatNormalTexture"]["index"] = 7;
    test::writeText(file, doc.dump());
    test::expectUserError([&] { loadGltf(file); },
                          {"materials[3].extensions.KHR_materials_clearcoat.clearcoatNormalTexture.index"});
}

// exportGlb writes the extension back: the materials survive a round trip.
TEST(GltfMaterials, ClearcoatExtensionSurvivesExport) {
    Scene s = loadGltf(corpus("clearcoat.gltf"));
    auto file = test::scratchDir() / "clearcoat_roundtrip.glb";
    exportGlb(s, file);
    std::vector<std::string> warnings;
    Scene back = loadGltf(file, warnings);
    EXPECT_TRUE(warnings.empty()) << warnings[0];
    for (const char* name : {"full", "half", "zero", "textured"}) {
        const Material& a = byName(s, name);
        const Material& b = byName(back, name);
        EXPECT_EQ(a.clearcoat, b.clearcoat) << name;
        EXPECT_EQ(a.clearcoatRoughness, b.clearcoatRoughness) << name;
        EXPECT_EQ(a.clearcoatTexture.valid(), b.clearcoatTexture.valid()) << name;
        EXPECT_EQ(a.clearcoatRoughnessTexture.valid(), b.clearcoatRoughnessTexture.valid()) << name;
        EXPECT_EQ(a.clearcoatNormal.texture.valid(), b.clearcoatNormal.texture.valid()) << name;
        EXPECT_EQ(a.clearcoatNormal.scale, b.clearcoatNormal.scale) << name;
    }
}

// KHR_materials_sheen is read, not warned about: the factors, the two textures (sRGB colour, roughness as data from
// alpha, with their KHR_texture_transform), and a black sheen kept as authored.
TEST(GltfMaterials, SheenExtensionIsReadWithoutWarnings) {
    std::vector<std::string> warnings;
    Scene s = loadGltf(corpus("sheen.gltf"), warnings);
    EXPECT_TRUE(warnings.empty()) << warnings[0];
    test::Json want = expected("sheen.gltf");
    const char* names[] = {"velvet", "satin", "black", "textured"};
    for (int i = 0; i < 4; ++i) {
        const Material& m = byName(s, names[i]);
        SCOPED_TRACE(names[i]);
        for (int c = 0; c < 3; ++c)
            EXPECT_EQ(m.sheenColor[c], want["sheen_color"][i][c].get<float>());
        EXPECT_EQ(m.sheenRoughness, want["roughness"][i].get<float>());
        EXPECT_EQ(m.sheenColorTexture.valid(), i == 3);
        EXPECT_EQ(m.sheenRoughnessTexture.valid(), i == 3);
        EXPECT_TRUE(m.hasSheen()); // the black one says a roughness
    }
    const Material& t = byName(s, "textured");
    EXPECT_EQ(s.textures[t.sheenColorTexture.texture].usage, TextureUsage::Color);
    EXPECT_EQ(s.textures[t.sheenRoughnessTexture.texture].usage, TextureUsage::Data);
    EXPECT_EQ(t.sheenColorTexture.transform.scale, glm::vec2(1.0f));
    EXPECT_FALSE(Material{}.hasSheen());
    // Supported, so a file may require it.
    test::Json doc = test::readJson(corpus("sheen.gltf"));
    doc["extensionsRequired"] = {"KHR_materials_sheen"};
    auto required = test::scratchDir() / "sheen_required.gltf";
    test::writeText(required, doc.dump());
    EXPECT_EQ(loadGltf(required, warnings).materials, s.materials);
    EXPECT_TRUE(warnings.empty()) << warnings[0];
}

TEST(GltfMaterials, SheenExtensionOutOfRangeIsAnErrorWithItsPath) {
    auto file = test::scratchDir() / "sheen_bad.gltf";
    for (double bad : {1.5, -0.25}) {
        test::Json doc = test::readJson(corpus("sheen.gltf"));
        doc["materials"][1]["extensions"]["KHR_materials_sheen"]["sheenRoughnessFactor"] = bad;
        test::writeText(file, doc.dump());
        test::expectUserError([&] { loadGltf(file); },
                              {"sheen_bad.gltf", "materials[1].extensions.KHR_materials_sheen.sheenRoughnessFactor",
                               "expected a number in [0, 1]"});
        doc = test::readJson(corpus("sheen.gltf"));
        doc["materials"][0]["extensions"]["KHR_materials_sheen"]["sheenColorFactor"][2] = bad;
        test::writeText(file, doc.dump());
        test::expectUserError(
            [&] { loadGltf(file); },
            {"materials[0].extensions.KHR_materials_sheen.sheenColorFactor[2]", "expected a number in [0, 1]"});
    }
    test::Json doc = test::readJson(corpus("sheen.gltf"));
    doc["materials"][3]["extensions"]["KHR_materials_sheen"]["sheenRoughnessTexture"]["index"] = 7;
    test::writeText(file, doc.dump());
    test::expectUserError([&] { loadGltf(file); },
                          {"materials[3].extensions.KHR_materials_sheen.sheenRoughnessTexture.index"});
}

// exportGlb writes the extension back: the materials survive a round trip, textures and their transforms included.
TEST(GltfMaterials, SheenExtensionSurvivesExport) {
    Scene s = loadGltf(corpus("sheen.gltf"));
    auto file = test::scratchDir() / "sheen_roundtrip.glb";
    exportGlb(s, file);
    std::vector<std::string> warnings;
    Scene back = loadGltf(file, warnings);
    EXPECT_TRUE(warnings.empty()) << warnings[0];
    for (const char* name : {"velvet", "satin", "black", "textured"}) {
        const Material& a = byName(s, name);
        const Material& b = byName(back, name);
        EXPECT_EQ(a.sheenColor, b.sheenColor) << name;
        EXPECT_EQ(a.sheenRoughness, b.sheenRoughness) << name;
        EXPECT_EQ(a.sheenColorTexture.valid(), b.sheenColorTexture.valid()) << name;
        EXPECT_EQ(a.sheenRoughnessTexture.valid(), b.sheenRoughnessTexture.valid()) << name;
        EXPECT_EQ(a.sheenColorTexture.transform.scale, b.sheenColorTexture.transform.scale) << name;
        EXPECT_TRUE(b.hasSheen()) << name;
    }
    const Material& t = byName(back, "textured");
    EXPECT_EQ(back.textures[t.sheenColorTexture.texture].usage, TextureUsage::Color);
    EXPECT_EQ(back.textures[t.sheenRoughnessTexture.texture].usage, TextureUsage::Data);
}

// KHR_materials_volume is read: thicknessFactor, the thickness texture (data, green channel, with its
// KHR_texture_transform), attenuationDistance (absent: +infinity) and attenuationColor, against volume.gltf's
// asset.extras.expect; a material without the extension gets the spec's defaults (thin-walled, no attenuation).
// volume.gltf's meshes are single quads, which bound no volume: the loader warns once for each whose material has a
// thickness (core/scene/closed_mesh.hpp; not "thin", thicknessFactor 0), naming the primitive.
std::vector<std::string> openVolumeWarnings(const std::vector<std::string>& warnings) {
    std::vector<std::string> found;
    for (const std::string& w : warnings)
        if (w.find("KHR_materials_volume") != std::string::npos && w.find("needs a closed mesh") != std::string::npos)
            found.push_back(w);
    return found;
}

// The warning is about faces that bound nothing, not about the extension: a cube of volume glass (8 corners shared by
// its 12 triangles) loads without one; the same cube without its top face, or split so that the top is in another
// material, is warned about once, naming its primitive.
TEST(GltfMaterials, VolumeOnAClosedCubeIsNotWarnedAbout) {
    std::vector<uint8_t> bin;
    auto put = [&](const void* p, size_t n) {
        bin.insert(bin.end(), static_cast<const uint8_t*>(p), static_cast<const uint8_t*>(p) + n);
    };
    for (int c = 0; c < 8; ++c) {
        const float v[3] = {c & 1 ? 1.0f : -1.0f, c & 2 ? 1.0f : -1.0f, c & 4 ? 1.0f : -1.0f};
        put(v, sizeof v);
    }
    // Outward counter-clockwise: -x, +x, -y, +y (the top), -z, +z.
    const uint16_t faces[6][6] = {{0, 4, 6, 0, 6, 2}, {1, 3, 7, 1, 7, 5}, {0, 1, 5, 0, 5, 4},
                                  {2, 6, 7, 2, 7, 3}, {0, 2, 3, 0, 3, 1}, {4, 5, 7, 4, 7, 6}};
    put(faces, sizeof faces);
    const std::string json = R"({"asset": {"version": "2.0"},
        "extensionsUsed": ["KHR_materials_transmission", "KHR_materials_volume"],
        "buffers": [{"byteLength": 168}],
        "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 96},
                        {"buffer": 0, "byteOffset": 96, "byteLength": 72}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 8, "type": "VEC3", "min": [-1, -1, -1], "max": [1, 1, 1]},
            {"bufferView": 1, "componentType": 5123, "count": 36, "type": "SCALAR"},
            {"bufferView": 1, "byteOffset": 0, "componentType": 5123, "count": 18, "type": "SCALAR"},
            {"bufferView": 1, "byteOffset": 48, "componentType": 5123, "count": 12, "type": "SCALAR"},
            {"bufferView": 1, "byteOffset": 36, "componentType": 5123, "count": 6, "type": "SCALAR"}],
        "materials": [
            {"name": "glass", "extensions": {"KHR_materials_transmission": {"transmissionFactor": 1},
                                             "KHR_materials_volume": {"thicknessFactor": 2}}},
            {"name": "other", "extensions": {"KHR_materials_transmission": {"transmissionFactor": 1},
                                             "KHR_materials_volume": {"thicknessFactor": 2}}}],
        "meshes": [
            {"name": "cube", "primitives": [{"attributes": {"POSITION": 0}, "indices": 1, "material": 0}]},
            {"name": "lidless", "primitives": [{"attributes": {"POSITION": 0}, "indices": 2, "material": 0},
                                               {"attributes": {"POSITION": 0}, "indices": 3, "material": 0}]},
            {"name": "split", "primitives": [{"attributes": {"POSITION": 0}, "indices": 2, "material": 0},
                                             {"attributes": {"POSITION": 0}, "indices": 3, "material": 0},
                                             {"attributes": {"POSITION": 0}, "indices": 4, "material": 1}]},
            {"name": "halves", "primitives": [{"attributes": {"POSITION": 0}, "indices": 2, "material": 0},
                                              {"attributes": {"POSITION": 0}, "indices": 3, "material": 0},
                                              {"attributes": {"POSITION": 0}, "indices": 4, "material": 0}]}],
        "nodes": [{"mesh": 0}, {"mesh": 1}, {"mesh": 2}, {"mesh": 3}],
        "scenes": [{"nodes": [0, 1, 2, 3]}], "scene": 0})";
    const auto file = test::scratchDir() / "volume_cubes.glb";
    test::writeBytes(file, test::makeGlb(json, bin));
    std::vector<std::string> warnings;
    const Scene s = loadGltf(file, warnings);
    ASSERT_EQ(s.meshes.size(), 4u);
    // The lidless cube's glass and the split cube's two materials (the top alone in "other" is a quad too) are open;
    // the whole cube and the cube in three primitives of one material are not.
    std::vector<std::string> named;
    for (const std::string& w : warnings)
        named.push_back(w.substr(w.find("meshes[")).substr(0, 23));
    EXPECT_EQ(named, (std::vector<std::string>{"meshes[1].primitives[0]", "meshes[2].primitives[0]",
                                               "meshes[2].primitives[2]"}))
        << testing::PrintToString(warnings);
    for (const std::string& w : warnings)
        EXPECT_NE(w.find("needs a closed mesh"), std::string::npos) << w;
}

TEST(GltfMaterials, VolumeExtensionIsReadWarningOfOpenMeshesOnly) {
    std::vector<std::string> warnings;
    Scene s = loadGltf(corpus("volume.gltf"), warnings);
    ASSERT_EQ(openVolumeWarnings(warnings).size(), 3u);
    EXPECT_EQ(warnings.size(), 3u) << warnings[0];
    for (const char* mesh : {"meshes[0].primitives[0]", "meshes[2].primitives[0]", "meshes[3].primitives[0]"})
        EXPECT_EQ(std::count_if(warnings.begin(), warnings.end(),
                                [&](const std::string& w) { return w.find(mesh) != std::string::npos; }),
                  1)
            << mesh;
    test::Json want = expected("volume.gltf");
    for (int i = 0; i < 4; ++i) {
        std::string name = want["materials"][i].get<std::string>();
        const Material& m = byName(s, name);
        SCOPED_TRACE(name);
        EXPECT_EQ(m.transmission, 1.0f);
        EXPECT_EQ(m.thickness, want["thickness"][i].get<float>());
        if (want["attenuation_distance"][i].is_null())
            EXPECT_TRUE(std::isinf(m.attenuationDistance) && m.attenuationDistance > 0.0f) << m.attenuationDistance;
        else
            EXPECT_EQ(m.attenuationDistance, want["attenuation_distance"][i].get<float>());
        for (int c = 0; c < 3; ++c)
            EXPECT_EQ(m.attenuationColor[c], want["attenuation_color"][i][c].get<float>());
        EXPECT_EQ(m.thicknessTexture.valid(), name == "textured");
        EXPECT_TRUE(m.hasVolume());
    }
    const Material& t = byName(s, "textured");
    EXPECT_EQ(s.textures[t.thicknessTexture.texture].usage, TextureUsage::Data);
    EXPECT_EQ(t.thicknessTexture.transform.scale, glm::vec2(1.0f));
    // The spec's defaults, which draw the thin-walled surface of before.
    const Material& backdrop = byName(s, "backdrop");
    EXPECT_EQ(backdrop.thickness, 0.0f);
    EXPECT_TRUE(std::isinf(backdrop.attenuationDistance));
    EXPECT_EQ(backdrop.attenuationColor, glm::vec3(1.0f));
    EXPECT_FALSE(backdrop.hasVolume());
    EXPECT_FALSE(Material{}.hasVolume());
    // An empty extension object is the defaults too.
    test::Json doc = test::readJson(corpus("volume.gltf"));
    doc["materials"][0]["extensions"]["KHR_materials_volume"] = test::Json::object();
    auto empty = test::scratchDir() / "volume_empty.gltf";
    test::writeText(empty, doc.dump());
    Scene emptyScene = loadGltf(empty, warnings);
    const Material& e = byName(emptyScene, "tinted");
    EXPECT_EQ(e.thickness, 0.0f);
    EXPECT_TRUE(std::isinf(e.attenuationDistance));
    EXPECT_EQ(e.attenuationColor, glm::vec3(1.0f));
    EXPECT_FALSE(e.thicknessTexture.valid());
    // Supported, so a file may require it.
    doc = test::readJson(corpus("volume.gltf"));
    doc["extensionsRequired"] = {"KHR_materials_volume"};
    auto required = test::scratchDir() / "volume_required.gltf";
    test::writeText(required, doc.dump());
    EXPECT_EQ(loadGltf(required, warnings).materials, s.materials);
    EXPECT_EQ(openVolumeWarnings(warnings).size(), warnings.size()) << warnings[0];
}

// The thickness texture's texels as the loader reads them: the green channel, not the others (volume.gltf's image has
// different red, blue and alpha), times thicknessFactor, at each of the quad's four texels.
TEST(GltfMaterials, VolumeThicknessTextureIsReadFromItsGreenChannel) {
    Scene s = loadGltf(corpus("volume.gltf"));
    test::Json want = expected("volume.gltf");
    const Material& t = byName(s, "textured");
    ASSERT_TRUE(t.thicknessTexture.valid());
    const TextureImage& img = s.images[s.textures[t.thicknessTexture.texture].image];
    ASSERT_EQ(img.width, 2u);
    ASSERT_EQ(img.height, 2u);
    for (uint32_t i = 0; i < 4; ++i) {
        float texel = img.at(i % 2, i / 2)[1] / 255.0f;
        EXPECT_NEAR(t.thickness * texel, want["texels_thickness"][i].get<double>(), 1e-6) << i;
    }
}

TEST(GltfMaterials, VolumeExtensionOutOfRangeIsAnErrorWithItsPath) {
    auto file = test::scratchDir() / "volume_bad.gltf";
    auto expectError = [&](const std::string& key, test::Json value, const std::string& element,
                           const std::string& expected) {
        test::Json doc = test::readJson(corpus("volume.gltf"));
        doc["materials"][1]["extensions"]["KHR_materials_volume"][key] = value;
        test::writeText(file, doc.dump());
        test::expectUserError([&] { loadGltf(file); },
                              {"volume_bad.gltf", "materials[1].extensions.KHR_materials_volume." + element, expected});
    };
    expectError("thicknessFactor", -0.5, "thicknessFactor", "expected a number >= 0");
    expectError("attenuationDistance", 0.0, "attenuationDistance", "expected a number > 0");
    expectError("attenuationDistance", -1.0, "attenuationDistance", "expected a number > 0");
    expectError("attenuationColor", {0.5, 1.5, 0.5}, "attenuationColor[1]", "expected a number in [0, 1]");
    expectError("attenuationColor", {0.5, 0.5, -0.25}, "attenuationColor[2]", "expected a number in [0, 1]");
    expectError("thicknessTexture", {{"index", 7}}, "thicknessTexture.index", "");
}

// exportGlb writes the extension back: the materials survive a round trip, the texture and its transform included, an
// infinite attenuationDistance stays infinite (written as the property's absence, JSON having no infinity), and
// thicknessFactor 0 with a colour stays as authored.
TEST(GltfMaterials, VolumeExtensionSurvivesExport) {
    Scene s = loadGltf(corpus("volume.gltf"));
    auto file = test::scratchDir() / "volume_roundtrip.glb";
    exportGlb(s, file);
    std::vector<std::string> warnings;
    Scene back = loadGltf(file, warnings);
    EXPECT_EQ(openVolumeWarnings(warnings).size(), warnings.size()) << warnings[0]; // the quads are still open
    for (const char* name : {"tinted", "thin", "clear", "textured"}) {
        const Material& a = byName(s, name);
        const Material& b = byName(back, name);
        EXPECT_EQ(a.thickness, b.thickness) << name;
        EXPECT_EQ(a.attenuationDistance, b.attenuationDistance) << name;
        EXPECT_EQ(a.attenuationColor, b.attenuationColor) << name;
        EXPECT_EQ(a.thicknessTexture.valid(), b.thicknessTexture.valid()) << name;
        EXPECT_EQ(a.thicknessTexture.transform, b.thicknessTexture.transform) << name;
        EXPECT_EQ(a.transmission, b.transmission) << name;
        EXPECT_TRUE(b.hasVolume()) << name;
    }
    EXPECT_TRUE(std::isinf(byName(back, "clear").attenuationDistance));
    EXPECT_FALSE(byName(back, "backdrop").hasVolume());
    const Material& t = byName(back, "textured");
    EXPECT_EQ(back.textures[t.thicknessTexture.texture].usage, TextureUsage::Data);
    // The node's scale, which the attenuation depends on, is kept too.
    auto node = std::find_if(back.nodes.begin(), back.nodes.end(), [](const Node& n) { return n.name == "tinted"; });
    ASSERT_NE(node, back.nodes.end());
    EXPECT_EQ(node->local.scale, glm::vec3(2.0f));
}

} // namespace vitrine::scene
