// Loading hand-written glTF files: exact values in, exact values out.

#include "core/scene/gltf.hpp"

#include "test_util.hpp"

#include <algorithm>
#include <functional>

#include <gtest/gtest.h>

namespace vitrine::scene {
namespace {

using test::Json;

void expectVec(const glm::vec3& a, const glm::vec3& b, float tol = 0.0f) {
    EXPECT_NEAR(a.x, b.x, tol);
    EXPECT_NEAR(a.y, b.y, tol);
    EXPECT_NEAR(a.z, b.z, tol);
}

TEST(GltfLoad, QuadGeometryIsExact) {
    Scene scene = loadGltf(test::dataDir() / "quad.gltf");
    EXPECT_EQ(scene.name, "quad scene");
    ASSERT_EQ(scene.meshes.size(), 1u);
    ASSERT_EQ(scene.primitives.size(), 1u);
    EXPECT_EQ(scene.indices, (std::vector<uint32_t>{0, 1, 2, 0, 2, 3}));
    ASSERT_EQ(scene.vertices.size(), 4u);
    const glm::vec3 positions[4] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
    const glm::vec2 uvs[4] = {{0, 1}, {1, 1}, {1, 0}, {0, 0}};
    for (int i = 0; i < 4; ++i) {
        EXPECT_EQ(scene.vertices[i].position, positions[i]);
        EXPECT_EQ(scene.vertices[i].normal, glm::vec3(0, 0, 1));
        EXPECT_EQ(scene.vertices[i].uv0, uvs[i]);
        EXPECT_EQ(scene.vertices[i].uv1, uvs[i]); // the file reuses the TEXCOORD_0 accessor
        EXPECT_EQ(scene.vertices[i].color, glm::vec4(1.0f));
        // No TANGENT in the file: generated; u runs along +x, v along -y, so t = +x and w = +1.
        EXPECT_NEAR(scene.vertices[i].tangent.x, 1.0f, 1e-6f);
        EXPECT_NEAR(scene.vertices[i].tangent.y, 0.0f, 1e-6f);
        EXPECT_EQ(scene.vertices[i].tangent.w, 1.0f);
    }
    const Primitive& p = scene.primitives[0];
    EXPECT_EQ(p.indexCount, 6u);
    EXPECT_EQ(p.vertexCount, 4u);
    EXPECT_EQ(p.material, 0u);
}

TEST(GltfLoad, QuadMaterialAndTextureTransform) {
    Scene scene = loadGltf(test::dataDir() / "quad.gltf");
    ASSERT_EQ(scene.materials.size(), 1u);
    const Material& m = scene.materials[0];
    EXPECT_EQ(m.name, "painted");
    ASSERT_EQ(m.layers.size(), 1u);
    const MaterialLayer& l = m.layers[0];
    EXPECT_EQ(l.albedo.factor, glm::vec4(0.8f, 0.4f, 0.2f, 1.0f));
    EXPECT_EQ(l.albedo.texture.texture, 0);
    EXPECT_EQ(l.albedo.texture.uvSet, 0u);
    EXPECT_EQ(l.albedo.texture.transform.offset, glm::vec2(0.5f, 0.25f));
    EXPECT_EQ(l.albedo.texture.transform.scale, glm::vec2(2.0f, 3.0f));
    EXPECT_EQ(l.albedo.texture.transform.rotation, 0.5f);
    // roughness 0.75 → shininess = mix(1, 0.25, texel.g)
    EXPECT_FLOAT_EQ(l.shininess.factor, 0.25f);
    EXPECT_EQ(l.shininess.atZero, 1.0f);
    EXPECT_EQ(l.shininess.channel, 1u);
    EXPECT_EQ(l.shininess.texture.texture, 1);
    EXPECT_EQ(l.shininess.texture.uvSet, 1u);
    EXPECT_EQ(l.metallic.factor, 0.25f);
    EXPECT_EQ(l.metallic.channel, 2u);
    EXPECT_EQ(l.metallic.texture.texture, 1);
    EXPECT_EQ(l.normal.scale, 0.6f);
    EXPECT_EQ(l.normal.texture.texture, 2);
    // Occlusion (strength 0.5) → cavity; glTF texture 0 is colour already, so a linear copy is made.
    EXPECT_EQ(l.cavity.factor, 1.0f);
    EXPECT_EQ(l.cavity.atZero, 0.5f);
    ASSERT_EQ(scene.textures.size(), 4u);
    EXPECT_EQ(l.cavity.texture.texture, 3);
    EXPECT_EQ(scene.textures[3].image, 0u);
    EXPECT_EQ(scene.textures[0].colorSpace(), ColorSpace::Srgb);
    EXPECT_EQ(scene.textures[1].colorSpace(), ColorSpace::Linear);
    EXPECT_EQ(scene.textures[2].usage, TextureUsage::Normal);
    EXPECT_EQ(scene.textures[3].usage, TextureUsage::Data);
    EXPECT_EQ(m.emissiveFactor, glm::vec3(1.0f, 0.5f, 0.0f));
    EXPECT_EQ(m.emissiveStrength, 4.0f);
    EXPECT_TRUE(m.doubleSided);

    const Sampler& s = scene.textures[0].sampler;
    EXPECT_EQ(s.magFilter, Filter::Nearest);
    EXPECT_EQ(s.minFilter, Filter::Nearest);
    EXPECT_EQ(s.mipFilter, MipFilter::Nearest);
    EXPECT_EQ(s.wrapU, Wrap::ClampToEdge);
    EXPECT_EQ(s.wrapV, Wrap::MirroredRepeat);
    EXPECT_EQ(scene.textures[1].sampler, Sampler());

    ASSERT_EQ(scene.images.size(), 1u);
    const TextureImage& image = scene.images[0];
    ASSERT_EQ(image.width, 2u);
    ASSERT_EQ(image.height, 2u);
    EXPECT_EQ(image.pixels, (std::vector<uint8_t>{255, 0, 0, 255, 0, 255, 0, 255, 0, 0, 255, 255, 255, 255, 255, 128}));
}

TEST(GltfLoad, TextureTransformMatchesTheSpecExample) {
    // KHR_texture_transform's example: offset (0, 1), rotation π/2, scale 0.5 shows the lower-left quadrant
    // of the image rotated: uv (1, 0) must land on (0, 0.5) and (0, 1) on (0.5, 1).
    UvTransform t{{0.0f, 1.0f}, {0.5f, 0.5f}, 1.57079632679f};
    glm::vec2 a = t.apply({1.0f, 0.0f}), b = t.apply({0.0f, 1.0f});
    EXPECT_NEAR(a.x, 0.0f, 1e-6f);
    EXPECT_NEAR(a.y, 0.5f, 1e-6f);
    EXPECT_NEAR(b.x, 0.5f, 1e-6f);
    EXPECT_NEAR(b.y, 1.0f, 1e-6f);
}

TEST(GltfLoad, QuadNodesCamerasSunAndAnimation) {
    Scene scene = loadGltf(test::dataDir() / "quad.gltf");
    ASSERT_EQ(scene.nodes.size(), 5u);
    EXPECT_EQ(scene.nodes[0].name, "quad");
    EXPECT_EQ(scene.nodes[0].local.translation, glm::vec3(1, 2, 3));
    EXPECT_EQ(scene.roots, (std::vector<uint32_t>{0, 1, 2, 3}));
    ASSERT_EQ(scene.instances.size(), 2u);
    EXPECT_EQ(scene.instances[0].node, 0u);
    EXPECT_TRUE(scene.instances[0].dynamic); // the animation moves it
    EXPECT_EQ(scene.instances[1].node, 4u);
    EXPECT_FALSE(scene.instances[1].dynamic);
    expectVec(glm::vec3(scene.instances[1].world[3]), glm::vec3(10, 0, -1), 1e-6f); // R_y(90°)·(1,0,0) + (10,0,0)

    ASSERT_EQ(scene.cameras.size(), 1u);
    EXPECT_FLOAT_EQ(scene.cameras[0].yfov, 0.7f);
    EXPECT_FLOAT_EQ(scene.cameras[0].znear, 0.1f);
    EXPECT_FLOAT_EQ(scene.cameras[0].zfar, 100.0f);
    EXPECT_FLOAT_EQ(scene.cameras[0].aspectRatio, 1.5f);
    CameraState cam = scene.cameraAt("cam", 0.0);
    EXPECT_EQ(cam.position, glm::vec3(0, 1, 5));
    EXPECT_FLOAT_EQ(cam.lens.yfov, 0.7f);
    test::expectUserError([&] { scene.cameraAt("nope", 0.0); }, {"'nope'", "not found", "cam"});

    ASSERT_TRUE(scene.hasSun);
    expectVec(scene.sun.toSun, glm::vec3(0, 1, 0), 1e-6f);
    EXPECT_EQ(scene.sun.illuminance, 50000.0f);
    EXPECT_EQ(scene.sun.color, glm::vec3(1.0f, 0.9f, 0.8f));

    // The known LINEAR channel: (1,2,3) at t=0 → (3,2,-1) at t=2; clamped outside.
    ASSERT_EQ(scene.animations.size(), 1u);
    EXPECT_EQ(scene.animations[0].name, "slide");
    expectVec(glm::vec3(scene.evaluate(1.0).nodeWorld[0][3]), glm::vec3(2, 2, 1), 1e-6f);
    expectVec(glm::vec3(scene.evaluate(0.5).nodeWorld[0][3]), glm::vec3(1.5f, 2, 2), 1e-6f);
    expectVec(glm::vec3(scene.evaluate(5.0).nodeWorld[0][3]), glm::vec3(3, 2, -1), 1e-6f);
    EXPECT_EQ(scene.evaluate(1.0).instanceWorld.size(), 2u);
}

// The same content as a GLB (buffer and image in the binary chunk) and with an external .bin.
TEST(GltfLoad, GlbAndExternalBufferGiveTheSameScene) {
    Json doc = test::readJson(test::dataDir() / "quad.gltf");
    std::vector<uint8_t> buffer = test::dataUriBytes(doc["buffers"][0]["uri"]);
    std::vector<uint8_t> png = test::dataUriBytes(doc["images"][0]["uri"]);
    ASSERT_EQ(buffer.size(), 172u);
    uint64_t reference = loadGltf(test::dataDir() / "quad.gltf").contentHash();
    auto dir = test::scratchDir();

    Json glb = doc;
    std::vector<uint8_t> bin = buffer;
    bin.insert(bin.end(), png.begin(), png.end());
    glb["buffers"][0] = {{"byteLength", bin.size()}};
    glb["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", buffer.size()}, {"byteLength", png.size()}});
    glb["images"][0] = {{"name", "checker"}, {"mimeType", "image/png"}, {"bufferView", 6}};
    test::writeBytes(dir / "quad.glb", test::makeGlb(glb.dump(), bin));
    EXPECT_EQ(loadGltf(dir / "quad.glb").contentHash(), reference);

    Json external = doc;
    external["buffers"][0]["uri"] = "quad%20data.bin"; // URIs are percent-encoded
    test::writeBytes(dir / "quad data.bin", buffer);
    test::writeText(dir / "external.gltf", external.dump());
    EXPECT_EQ(loadGltf(dir / "external.gltf").contentHash(), reference);
}

// u8 and u32 indices, and a normalised-u8 COLOR_0, appended to the quad's buffer as an external .bin.
TEST(GltfLoad, IndexAndAttributeEncodings) {
    Json doc = test::readJson(test::dataDir() / "quad.gltf");
    std::vector<uint8_t> bin = test::dataUriBytes(doc["buffers"][0]["uri"]);
    auto append = [&](const std::vector<uint8_t>& bytes) {
        while (bin.size() % 4)
            bin.push_back(0);
        size_t at = bin.size();
        bin.insert(bin.end(), bytes.begin(), bytes.end());
        doc["bufferViews"].push_back({{"buffer", 0}, {"byteOffset", at}, {"byteLength", bytes.size()}});
        return doc["bufferViews"].size() - 1;
    };
    size_t u8View = append({0, 1, 2, 0, 2, 3});
    std::vector<uint8_t> u32;
    for (uint32_t i : {0u, 1u, 2u, 0u, 2u, 3u}) {
        for (int b = 0; b < 4; ++b)
            u32.push_back(static_cast<uint8_t>(i >> (8 * b)));
    }
    size_t u32View = append(u32);
    size_t colorView = append({255, 0, 0, 255, 0, 255, 0, 255, 0, 0, 255, 255, 51, 102, 153, 255});
    doc["accessors"].push_back(
        {{"bufferView", colorView}, {"componentType", 5121}, {"normalized", true}, {"count", 4}, {"type", "VEC4"}});
    doc["meshes"][0]["primitives"][0]["attributes"]["COLOR_0"] = doc["accessors"].size() - 1;
    doc["buffers"][0] = {{"byteLength", bin.size()}, {"uri", "quad.bin"}};
    auto dir = test::scratchDir();
    test::writeBytes(dir / "quad.bin", bin);
    for (auto [view, type] : {std::pair{u8View, 5121}, std::pair{u32View, 5125}}) {
        doc["accessors"][3] = {{"bufferView", view}, {"componentType", type}, {"count", 6}, {"type", "SCALAR"}};
        test::writeText(dir / "encodings.gltf", doc.dump());
        Scene scene = loadGltf(dir / "encodings.gltf");
        EXPECT_EQ(scene.indices, (std::vector<uint32_t>{0, 1, 2, 0, 2, 3})) << "componentType " << type;
        EXPECT_EQ(scene.vertices[0].color, glm::vec4(1, 0, 0, 1));
        EXPECT_EQ(scene.vertices[1].color, glm::vec4(0, 1, 0, 1));
        EXPECT_EQ(scene.vertices[3].color, glm::vec4(0.2f, 0.4f, 0.6f, 1.0f)); // 51/255, alpha is vertex AO: 1
    }
}

// A camera node moved by an animation becomes a camera path sampled from it.
TEST(GltfLoad, AnimatedCameraNodeBecomesAPath) {
    Json doc = test::readJson(test::dataDir() / "quad.gltf");
    doc["animations"][0]["channels"].push_back({{"sampler", 0}, {"target", {{"node", 1}, {"path", "translation"}}}});
    auto file = test::scratchDir() / "camera.gltf";
    test::writeText(file, doc.dump());
    Scene scene = loadGltf(file);
    const CameraPath* path = scene.findCameraPath("cam");
    ASSERT_NE(path, nullptr);
    EXPECT_EQ(path->keys.size(), 61u); // 2 s at 30 Hz
    expectVec(scene.cameraAt("cam", 1.0).position, glm::vec3(2, 2, 1), 1e-5f);
    expectVec(scene.cameraAt("cam", 2.0).position, glm::vec3(3, 2, -1), 1e-3f);
}

TEST(GltfLoad, WarnsAboutWhatItIgnores) {
    Json doc = test::readJson(test::dataDir() / "quad.gltf");
    doc["meshes"][0]["primitives"][0]["attributes"].erase("TEXCOORD_1");
    doc["meshes"][0]["primitives"][0]["attributes"]["COLOR_1"] = 0; // JOINTS_0 is read now (skins)
    auto file = test::scratchDir() / "warnings.gltf";
    test::writeText(file, doc.dump());
    std::vector<std::string> warnings;
    Scene scene = loadGltf(file, warnings);
    auto has = [&](const std::string& a, const std::string& b) {
        return std::any_of(warnings.begin(), warnings.end(), [&](const std::string& w) {
            return w.find(a) != std::string::npos && w.find(b) != std::string::npos;
        });
    };
    EXPECT_TRUE(has("meshes[0].primitives[0]", "TEXCOORD_1")) << testing::PrintToString(warnings);
    EXPECT_TRUE(has("attributes.COLOR_1", "ignored")) << testing::PrintToString(warnings);
    EXPECT_EQ(scene.vertices[0].uv1, glm::vec2(0.0f));
}

TEST(GltfLoad, LayerExtension) {
    Scene scene = loadGltf(test::dataDir() / "layered.gltf");
    ASSERT_EQ(scene.materials.size(), 1u);
    const Material& m = scene.materials[0];
    ASSERT_EQ(m.layers.size(), 2u);
    const MaterialLayer& gold = m.layers[0];
    EXPECT_EQ(gold.name, "gold");
    EXPECT_EQ(gold.albedo.factor, glm::vec4(1.0f, 0.766f, 0.336f, 1.0f));
    EXPECT_EQ(gold.normal.scale, 0.5f);
    EXPECT_EQ(gold.normal.texture.transform.scale, glm::vec2(4.0f));
    EXPECT_EQ(scene.textures[gold.normal.texture.texture].usage, TextureUsage::Normal);
    EXPECT_EQ(gold.shininess.factor, 0.9f);
    EXPECT_FALSE(gold.shininess.texture.valid());
    EXPECT_EQ(gold.metallic.factor, 1.0f);
    EXPECT_EQ(gold.cavity.atZero, 0.5f);
    EXPECT_EQ(gold.cavity.channel, 2u);
    EXPECT_EQ(gold.overrides, uint32_t(kLayerAll));

    const MaterialLayer& dirt = m.layers[1];
    EXPECT_EQ(dirt.name, "dirt");
    EXPECT_EQ(dirt.overrides, uint32_t(kLayerAlbedo | kLayerShininess | kLayerMetallic));
    EXPECT_EQ(dirt.shininess.factor, 0.2f);
    EXPECT_EQ(dirt.shininess.atZero, 0.05f);
    EXPECT_EQ(dirt.shininess.texture.uvSet, 1u);
    EXPECT_EQ(dirt.mask.factor, 0.8f);
    EXPECT_EQ(dirt.mask.channel, 0u);
    EXPECT_EQ(dirt.mask.texture.transform.offset, glm::vec2(0.1f, 0.2f));
    EXPECT_EQ(dirt.mask.texture.transform.scale, glm::vec2(0.5f));
    EXPECT_EQ(dirt.mask.texture.transform.rotation, 0.25f);
    EXPECT_EQ(scene.textures[dirt.mask.texture.texture].usage, TextureUsage::Data);
    // mix(0.05, 0.2, 0.5) = 0.125
    EXPECT_FLOAT_EQ(dirt.shininess.evaluate(0.5f), 0.125f);
}

} // namespace

// KHR_lights_punctual point and spot lights, KHR_materials_unlit, _transmission and _ior, as written by hand.
Json lightsAndGlassDoc() {
    Json doc = test::readJson(test::dataDir() / "quad.gltf");
    doc["extensions"]["KHR_lights_punctual"]["lights"].push_back(
        {{"name", "bulb"}, {"type", "point"}, {"color", {1.0, 0.5, 0.25}}, {"intensity", 12.0}, {"range", 4.0}});
    doc["extensions"]["KHR_lights_punctual"]["lights"].push_back(
        {{"type", "spot"}, {"intensity", 30.0}, {"spot", {{"innerConeAngle", 0.25}, {"outerConeAngle", 0.5}}}});
    doc["nodes"][3]["extensions"]["KHR_lights_punctual"] = {{"light", 1}}; // the group, translated and rotated
    doc["nodes"][1]["extensions"]["KHR_lights_punctual"] = {{"light", 2}}; // the camera node
    Json& m = doc["materials"][0];
    m["extensions"]["KHR_materials_unlit"] = Json::object();
    m["extensions"]["KHR_materials_transmission"] = {{"transmissionFactor", 0.75}};
    m["extensions"]["KHR_materials_ior"] = {{"ior", 1.33}};
    m["alphaMode"] = "BLEND";
    doc["extensionsRequired"] = {"KHR_lights_punctual", "KHR_materials_unlit", "KHR_materials_transmission",
                                 "KHR_materials_ior"};
    return doc;
}

TEST(GltfLoad, PunctualLightsUnlitTransmissionAndIor) {
    auto file = test::scratchDir() / "lights.gltf";
    test::writeText(file, lightsAndGlassDoc().dump());
    Scene scene = loadGltf(file);
    ASSERT_TRUE(scene.hasSun); // the directional light is still the sun
    ASSERT_EQ(scene.lights.size(), 2u);
    const PunctualLight& point = scene.lights[1].type == LightType::Point ? scene.lights[1] : scene.lights[0];
    const PunctualLight& spot = scene.lights[1].type == LightType::Spot ? scene.lights[1] : scene.lights[0];
    EXPECT_EQ(point.type, LightType::Point);
    EXPECT_EQ(point.name, "bulb");
    EXPECT_EQ(point.color, glm::vec3(1.0f, 0.5f, 0.25f));
    EXPECT_EQ(point.intensity, 12.0f);
    EXPECT_EQ(point.range, 4.0f);
    EXPECT_EQ(scene.nodes[point.node].name, "group");
    EXPECT_EQ(spot.type, LightType::Spot);
    EXPECT_EQ(spot.intensity, 30.0f);
    EXPECT_EQ(spot.range, 0.0f);
    EXPECT_EQ(spot.innerConeAngle, 0.25f);
    EXPECT_EQ(spot.outerConeAngle, 0.5f);
    EXPECT_EQ(scene.nodes[spot.node].name, "cam");
    const Material& m = scene.materials[0];
    EXPECT_TRUE(m.unlit);
    EXPECT_EQ(m.transmission, 0.75f);
    EXPECT_EQ(m.ior, 1.33f);
    EXPECT_EQ(m.alphaMode, AlphaMode::Blend);
    EXPECT_TRUE(m.transparent());

    // Export and load again: the same scene.
    auto glb = test::scratchDir() / "lights.glb";
    exportGlb(scene, glb);
    Scene back = loadGltf(glb);
    EXPECT_EQ(back.contentHash(), scene.contentHash());
    ASSERT_EQ(back.lights.size(), 2u);
    EXPECT_EQ(back.lights[0].node, scene.lights[0].node);
    EXPECT_TRUE(back.materials[0].unlit);
    EXPECT_EQ(back.materials[0].transmission, 0.75f);
    EXPECT_EQ(back.materials[0].ior, 1.33f);
}

TEST(GltfLoad, BadPunctualLightsAndGlassAreUserErrors) {
    struct Case {
        std::function<void(Json&)> edit;
        std::vector<std::string> expected;
    };
    const Case cases[] = {
        {[](Json& d) { d["extensions"]["KHR_lights_punctual"]["lights"][1]["type"] = "area"; },
         {"lights[1].type", "'area'", "expected directional, point or spot"}},
        {[](Json& d) { d["extensions"]["KHR_lights_punctual"]["lights"][2]["spot"]["innerConeAngle"] = 0.6; },
         {"lights[2].spot", "innerConeAngle < outerConeAngle"}},
        {[](Json& d) { d["extensions"]["KHR_lights_punctual"]["lights"][1]["intensity"] = -1.0; },
         {"lights[1].intensity", "expected a number >= 0"}},
        {[](Json& d) { d["materials"][0]["extensions"]["KHR_materials_transmission"]["transmissionFactor"] = 1.5; },
         {"materials[0].extensions.KHR_materials_transmission.transmissionFactor", "[0, 1]"}},
        {[](Json& d) { d["materials"][0]["extensions"]["KHR_materials_ior"]["ior"] = 0.5; },
         {"materials[0].extensions.KHR_materials_ior.ior", "[1, 10]"}},
    };
    int i = 0;
    for (const Case& c : cases) {
        Json doc = lightsAndGlassDoc();
        c.edit(doc);
        auto file = test::scratchDir() / ("bad_" + std::to_string(i++) + ".gltf");
        test::writeText(file, doc.dump());
        test::expectUserError([&] { loadGltf(file); }, c.expected);
    }
}

} // namespace vitrine::scene
