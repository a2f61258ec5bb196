// Malformed files give a UserError naming the file, the element and what was expected; never a crash.

#include "core/scene/gltf.hpp"

#include "test_util.hpp"

#include <gtest/gtest.h>

#include <cstring>
#include <limits>

namespace vitrine::scene {
namespace {

using test::expectUserError;
using test::Json;

class GltfErrors : public ::testing::Test {
protected:
    void SetUp() override {
        mDir = test::scratchDir();
        mDoc = test::readJson(test::dataDir() / "quad.gltf");
        mBuffer = test::dataUriBytes(mDoc["buffers"][0]["uri"]);
    }
    // Writes doc as name in the scratch directory and returns its path.
    std::filesystem::path write(const std::string& name, const Json& doc) {
        test::writeText(mDir / name, doc.dump(2));
        return mDir / name;
    }
    std::vector<uint8_t> glb() const {
        Json doc = mDoc;
        doc["buffers"][0] = {{"byteLength", mBuffer.size()}};
        return test::makeGlb(doc.dump(), mBuffer);
    }

    std::filesystem::path mDir;
    Json mDoc;
    std::vector<uint8_t> mBuffer;
};

TEST_F(GltfErrors, LightmapChartGapMustBeAUvDistance) {
    Json doc = mDoc;
    doc["meshes"][0]["extras"]["vitrine"]["lightmapChartGap"] = -0.5;
    const auto negative = write("negative_gap.gltf", doc);
    expectUserError([&] { loadGltf(negative); },
                    {"negative_gap.gltf", "meshes[0].extras.vitrine.lightmapChartGap", "[0, 1)"});
    doc["meshes"][0]["extras"]["vitrine"]["lightmapChartGap"] = "wide";
    const auto text = write("text_gap.gltf", doc);
    expectUserError([&] { loadGltf(text); }, {"text_gap.gltf", "lightmapChartGap", "expected a number"});
}

TEST_F(GltfErrors, BadJson) {
    expectUserError([] { loadGltf(test::dataDir() / "bad_json.gltf"); }, {"bad_json.gltf", "JSON", "not valid JSON"});
}

TEST_F(GltfErrors, MissingAndEmptyFiles) {
    expectUserError([&] { loadGltf(mDir / "nothing.gltf"); }, {"nothing.gltf", "cannot open"});
    test::writeText(mDir / "empty.gltf", "");
    expectUserError([&] { loadGltf(mDir / "empty.gltf"); }, {"empty.gltf", "is empty"});
}

TEST_F(GltfErrors, TruncatedGlb) {
    std::vector<uint8_t> bytes = glb();
    std::vector<uint8_t> cut(bytes.begin(), bytes.begin() + bytes.size() / 2);
    test::writeBytes(mDir / "cut.glb", cut);
    expectUserError([&] { loadGltf(mDir / "cut.glb"); }, {"cut.glb", "GLB header", "truncated"});

    // Cut inside the binary chunk with the header's total length patched to match: the chunk itself is short.
    std::vector<uint8_t> shortBin(bytes.begin(), bytes.end() - 16);
    uint32_t length = static_cast<uint32_t>(shortBin.size());
    for (int i = 0; i < 4; ++i)
        shortBin[8 + i] = static_cast<uint8_t>(length >> (8 * i));
    test::writeBytes(mDir / "short_bin.glb", shortBin);
    expectUserError([&] { loadGltf(mDir / "short_bin.glb"); }, {"short_bin.glb", "GLB chunk 1 (BIN)", "truncated"});

    // Every truncation is an error, and never a crash. (A new file each time: rewriting one file makes
    // ext4 flush it on close, which is slow.)
    for (size_t size = 0; size < bytes.size(); size += 5) {
        auto file = mDir / ("cut_" + std::to_string(size) + ".glb");
        test::writeBytes(file, std::vector<uint8_t>(bytes.begin(), bytes.begin() + size));
        EXPECT_THROW(loadGltf(file), UserError) << "size " << size;
    }
}

// A damaged GLB header is reported field by field, not as "not valid JSON".
TEST_F(GltfErrors, GlbHeaderFieldsAreNamed) {
    const std::vector<uint8_t> good = glb();
    auto patched = [&](size_t at, uint32_t value) {
        std::vector<uint8_t> b = good;
        for (int i = 0; i < 4; ++i)
            b[at + i] = static_cast<uint8_t>(value >> (8 * i));
        return b;
    };
    auto expectFor = [&](const std::string& name, const std::vector<uint8_t>& bytes,
                         const std::vector<std::string>& parts) {
        test::writeBytes(mDir / name, bytes);
        std::vector<std::string> all = {name};
        all.insert(all.end(), parts.begin(), parts.end());
        expectUserError([&] { loadGltf(mDir / name); }, all);
    };
    expectFor("magic.glb", patched(0, 0x58546C67u), {"GLB header: magic is 'glTX' (0x58546C67); expected 'glTF'"});
    // Whatever the name: bytes no JSON text starts with are read as a GLB header.
    expectFor("magic.bin", patched(0, 0x00000001u), {"GLB header: magic is '\\x01\\0\\0\\0'"});
    expectFor("version.glb", patched(4, 1), {"GLB header: version 1; expected 2"});
    expectFor("long.glb", patched(8, static_cast<uint32_t>(good.size() + 4)), {"GLB header: length declares"});
    expectFor("short.glb", patched(8, 16), {"GLB header: length 16 leaves no room for the JSON chunk"});
    expectFor("chunk0.glb", patched(16, 0x004E4942u), {"GLB chunk 0: type is 'BIN\\0' (0x004E4942); expected 'JSON'"});
    const uint32_t jsonLength = good[12] | good[13] << 8 | good[14] << 16 | uint32_t(good[15]) << 24;
    expectFor("chunk1.glb", patched(20 + jsonLength + 4, 0x4E4F534Au), {"GLB chunk 1: type is 'JSON'"});
    expectFor("bin_length.glb", patched(20 + jsonLength, 6), {"GLB chunk 1 (BIN): length 6; expected a multiple of 4"});
    expectFor("empty_json.glb", patched(12, 0), {"GLB chunk 0 (JSON): is empty"});
}

TEST_F(GltfErrors, NumbersTooLargeAndNestingTooDeep) {
    test::writeText(mDir / "big.gltf", "{\"asset\": {\"version\": \"2.0\"},\n \"scene\": 1e999}");
    expectUserError([&] { loadGltf(mDir / "big.gltf"); }, {"big.gltf: JSON line 2, column 11", "'1e999' is too large"});
    test::writeText(mDir / "deep.gltf", "{\"asset\": {\"version\": \"2.0\"}, \"extras\": " + std::string(100000, '['));
    expectUserError([&] { loadGltf(mDir / "deep.gltf"); }, {"deep.gltf: JSON line 1, column", "nesting deeper than"});
}

// Found by fuzz_gltf: a camera animated over 1e29 s made the number of 30 Hz path samples a float beyond size_t
// (undefined behaviour, then an endless loop). Times must be finite (readAccessor) and a camera path at most 10^6
// samples.
TEST_F(GltfErrors, CameraAnimationTimesOutOfRange) {
    auto withLastTime = [&](float t) {
        std::vector<uint8_t> buffer = mBuffer;
        std::memcpy(buffer.data() + 140 + 4, &t, 4); // bufferViews[4]: the sampler's two key times
        Json doc = mDoc;
        doc["animations"][0]["channels"][0]["target"]["node"] = 1; // move the camera node "cam"
        doc["accessors"][4].erase("max");
        doc["buffers"][0] = {{"byteLength", buffer.size()}};
        return test::makeGlb(doc.dump(), buffer);
    };
    test::writeBytes(mDir / "long.glb", withLastTime(1e29f));
    expectUserError([&] { loadGltf(mDir / "long.glb"); }, {"long.glb", "camera node 'cam'", "at most 1000000 samples"});
    test::writeBytes(mDir / "nan.glb", withLastTime(std::numeric_limits<float>::quiet_NaN()));
    expectUserError([&] { loadGltf(mDir / "nan.glb"); }, {"nan.glb", "animations[0].samplers[0].input", "not a finite"});
    // Nine hours of camera animation is still a path; ten hours (1.08 million samples) is not.
    test::writeBytes(mDir / "nine_hours.glb", withLastTime(9 * 3600.0f));
    EXPECT_NO_THROW(loadGltf(mDir / "nine_hours.glb"));
    test::writeBytes(mDir / "ten_hours.glb", withLastTime(10 * 3600.0f));
    expectUserError([&] { loadGltf(mDir / "ten_hours.glb"); }, {"ten_hours.glb", "span 36000 s"});
}

TEST_F(GltfErrors, MissingBufferFile) {
    mDoc["buffers"][0]["uri"] = "missing.bin";
    auto file = write("missing_buffer.gltf", mDoc);
    expectUserError([&] { loadGltf(file); }, {"missing_buffer.gltf", "buffers[0].uri", "'missing.bin' not found"});
}

TEST_F(GltfErrors, MissingTextureFile) {
    mDoc["images"][0] = {{"uri", "missing.png"}};
    auto file = write("missing_texture.gltf", mDoc);
    expectUserError([&] { loadGltf(file); }, {"missing_texture.gltf", "images[0].uri", "'missing.png' not found"});
}

// An image that does not decode (damaged, or a format stb_image lacks, such as WebP) is left out with a warning, and
// the material is drawn without the textures that use it (the Khronos validator reports damaged data as an error; a
// viewer still shows the rest).
TEST_F(GltfErrors, UndecodableImageIsLeftOutWithAWarning) {
    test::writeText(mDir / "not_a.png", "this is not a PNG");
    mDoc["images"][0] = {{"uri", "not_a.png"}};
    auto file = write("bad_texture.gltf", mDoc);
    std::vector<std::string> warnings;
    Scene scene = loadGltf(file, warnings);
    EXPECT_TRUE(scene.images.empty());
    EXPECT_TRUE(scene.textures.empty());
    ASSERT_FALSE(warnings.empty());
    EXPECT_NE(warnings.front().find("images[0]: could not be decoded ('not_a.png')"), std::string::npos)
        << warnings.front();
}

// A texCoord beyond TEXCOORD_1 (legal glTF; vitrine's vertices keep two sets): that texture is left out of the
// material, with a warning; the others stay.
TEST_F(GltfErrors, ThirdUvSetLeavesTheTextureOut) {
    mDoc["materials"][0]["normalTexture"]["texCoord"] = 2;
    std::vector<std::string> warnings;
    Scene scene = loadGltf(write("third_uv.gltf", mDoc), warnings);
    ASSERT_EQ(scene.materials.size(), 1u);
    EXPECT_FALSE(scene.materials[0].layers[0].normal.texture.valid());
    EXPECT_TRUE(scene.materials[0].layers[0].albedo.texture.valid());
    ASSERT_FALSE(warnings.empty());
    EXPECT_NE(warnings.front().find("materials[0].normalTexture.texCoord: 2"), std::string::npos) << warnings.front();
}

// tinygltf's own messages named no element for these; the preflight names them.
TEST_F(GltfErrors, LightsAndTopLevelElementsAreNamed) {
    Json doc = mDoc;
    doc["materials"][0] = "material";
    expectUserError([&] { loadGltf(write("string_material.gltf", doc)); },
                    {"string_material.gltf", "materials[0]", "/materials/0", "expected a JSON object"});
    doc = mDoc;
    doc["extensionsUsed"] = {"KHR_lights_punctual"};
    doc["extensions"]["KHR_lights_punctual"]["lights"] = {Json::object()};
    expectUserError([&] { loadGltf(write("typeless_light.gltf", doc)); },
                    {"/extensions/KHR_lights_punctual/lights/0/type", "directional, point or spot"});
    doc["extensions"]["KHR_lights_punctual"]["lights"][0]["type"] = "spot";
    expectUserError([&] { loadGltf(write("spotless_spot.gltf", doc)); },
                    {"/extensions/KHR_lights_punctual/lights/0/spot", "innerConeAngle, outerConeAngle"});
}

TEST_F(GltfErrors, AccessorBeyondItsBufferView) {
    mDoc["accessors"][0]["count"] = 100;
    auto file = write("accessor_range.gltf", mDoc);
    expectUserError([&] { loadGltf(file); }, {"accessor_range.gltf", "meshes[0].primitives[0].attributes.POSITION",
                                              "accessors[0]", "exceed bufferViews[0]", "expected the accessor to fit"});
}

TEST_F(GltfErrors, AbsurdCountsFailBeforeAllocating) {
    mDoc["accessors"][0]["count"] = 1099511627776ull; // 2^40 elements
    auto file = write("huge.gltf", mDoc);
    expectUserError([&] { loadGltf(file); }, {"huge.gltf", "attributes.POSITION", "exceed bufferViews[0]"});
    mDoc["accessors"][0].erase("bufferView"); // all zeros: legal glTF, but not this many
    file = write("huge_zeros.gltf", mDoc);
    expectUserError([&] { loadGltf(file); }, {"huge_zeros.gltf", "attributes.POSITION", "without a bufferView"});
}

TEST_F(GltfErrors, AccessorIndexOutOfRange) {
    mDoc["meshes"][0]["primitives"][0]["attributes"]["NORMAL"] = 42;
    auto file = write("accessor_index.gltf", mDoc);
    expectUserError([&] { loadGltf(file); }, {"accessor_index.gltf", "meshes[0].primitives[0].attributes.NORMAL",
                                              "index 42 out of range", "6 accessors"});
}

TEST_F(GltfErrors, VertexIndexOutOfRange) {
    std::vector<uint8_t> bin = mBuffer;
    bin[128 + 2 * 4] = 7; // the fifth index (u16 at byte 136) becomes 7; the quad has 4 vertices
    test::writeBytes(mDir / "quad.bin", bin);
    mDoc["buffers"][0]["uri"] = "quad.bin";
    auto file = write("index_range.gltf", mDoc);
    expectUserError([&] { loadGltf(file); },
                    {"index_range.gltf", "meshes[0].primitives[0].indices", "index 7 at position 4", "expected < 4"});
}

TEST_F(GltfErrors, BufferViewBeyondItsBuffer) {
    mDoc["bufferViews"][5]["byteLength"] = 1000;
    auto file = write("view_range.gltf", mDoc);
    expectUserError([&] { loadGltf(file); }, {"view_range.gltf", "bufferViews[5]", "exceed buffers[0]"});
}

TEST_F(GltfErrors, UnsupportedRequiredExtension) {
    mDoc["extensionsRequired"] = {"KHR_texture_transform", "KHR_draco_mesh_compression"};
    auto file = write("required.gltf", mDoc);
    expectUserError([&] { loadGltf(file); },
                    {"required.gltf", "extensionsRequired[1]", "KHR_draco_mesh_compression", "not supported"});
    // Merely used (not required) unknown extensions are fine.
    mDoc.erase("extensionsRequired");
    mDoc["extensionsUsed"].push_back("EXT_something_else");
    EXPECT_NO_THROW(loadGltf(write("used.gltf", mDoc)));
}

TEST_F(GltfErrors, MaterialTextureIndexOutOfRange) {
    mDoc["materials"][0]["normalTexture"]["index"] = 9;
    auto file = write("texture_index.gltf", mDoc);
    expectUserError([&] { loadGltf(file); },
                    {"texture_index.gltf", "materials[0].normalTexture.index", "out of range"});
}

TEST_F(GltfErrors, AnimationOutputCount) {
    mDoc["accessors"][5]["count"] = 1;
    auto file = write("animation.gltf", mDoc);
    expectUserError([&] { loadGltf(file); }, {"animation.gltf", "animations[0].samplers[0].output", "expected 2"});
}

TEST_F(GltfErrors, LayerExtensionTypos) {
    Json doc = test::readJson(test::dataDir() / "layered.gltf");
    Json& layer = doc["materials"][0]["extensions"]["VITRINE_material_layers"]["layers"][1];
    layer["albdo"] = layer["albedo"];
    auto file = write("typo.gltf", doc);
    expectUserError([&] { loadGltf(file); },
                    {"typo.gltf", "materials[0].extensions.VITRINE_material_layers.layers[1].albdo", "unknown key"});
    layer.erase("albdo");
    layer["overrides"] = {"albedo", "roughness"};
    file = write("override.gltf", doc);
    expectUserError([&] { loadGltf(file); }, {"layers[1].overrides", "\"roughness\"", "expected albedo"});
    layer["overrides"] = {"albedo"};
    layer["mask"]["channel"] = 4;
    file = write("channel.gltf", doc);
    expectUserError([&] { loadGltf(file); }, {"layers[1].mask.channel", "expected 0..3"});
}

TEST_F(GltfErrors, HierarchyMustBeATree) {
    mDoc["nodes"][4]["children"] = {3}; // 3 → 4 → 3
    auto file = write("cycle.gltf", mDoc);
    expectUserError([&] { loadGltf(file); }, {"cycle.gltf", "nodes[", "expected a tree"});
}

// Byte flips anywhere in a valid GLB load or fail with a UserError; nothing else may escape.
TEST_F(GltfErrors, CorruptedBytesNeverCrash) {
    std::vector<uint8_t> bytes = glb();
    for (size_t at = 0; at < bytes.size(); at += 3) {
        std::vector<uint8_t> bad = bytes;
        bad[at] ^= static_cast<uint8_t>(0x5a + at);
        auto file = mDir / ("flip_" + std::to_string(at) + ".glb");
        test::writeBytes(file, bad);
        try {
            loadGltf(file);
        } catch (const UserError&) {
        } catch (const std::exception& e) {
            ADD_FAILURE() << "byte " << at << ": not a UserError: " << e.what();
        }
    }
}

} // namespace
} // namespace vitrine::scene
