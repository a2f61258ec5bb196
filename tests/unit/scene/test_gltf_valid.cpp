// Files the Khronos glTF-Validator calls valid load (issue #29): data: URIs that are not base64, accessors without a
// bufferView (zeros plus sparse substitutions, indices included); invalid ones end with a message naming the JSON
// pointer; what vitrine ignores is a warning, once, and strict loading makes warnings errors. Every file is written
// here, small, by hand.

#include "core/scene/gltf.hpp"

#include "test_util.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <cstring>

namespace vitrine::scene {
namespace {

using test::expectUserError;
using test::Json;

void put(std::vector<uint8_t>& b, std::initializer_list<float> values) {
    for (float f : values) {
        uint8_t bytes[4];
        std::memcpy(bytes, &f, 4);
        b.insert(b.end(), bytes, bytes + 4);
    }
}

void putU16(std::vector<uint8_t>& b, std::initializer_list<uint16_t> values) {
    for (uint16_t v : values)
        b.insert(b.end(), {static_cast<uint8_t>(v & 0xFF), static_cast<uint8_t>(v >> 8)});
}

std::string base64(const std::vector<uint8_t>& data) {
    static const char* kAlphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out;
    for (size_t i = 0; i < data.size(); i += 3) {
        uint32_t v = uint32_t(data[i]) << 16 | (i + 1 < data.size() ? uint32_t(data[i + 1]) << 8 : 0) |
                     (i + 2 < data.size() ? data[i + 2] : 0);
        out += kAlphabet[v >> 18 & 63];
        out += kAlphabet[v >> 12 & 63];
        out += i + 1 < data.size() ? kAlphabet[v >> 6 & 63] : '=';
        out += i + 2 < data.size() ? kAlphabet[v & 63] : '=';
    }
    return out;
}

// Every byte as %XX (RFC 2397's percent-encoded form).
std::string percent(const std::vector<uint8_t>& data) {
    std::string out;
    for (uint8_t c : data) {
        char hex[4];
        std::snprintf(hex, sizeof hex, "%%%02X", c);
        out += hex;
    }
    return out;
}

std::string base64Uri(const std::vector<uint8_t>& data) { return "data:application/octet-stream;base64," + base64(data); }

// Positions (0,0,0) (1,0,0) (0,1,0), then three normals (0,0,1): 72 bytes.
std::vector<uint8_t> triangleBytes() {
    std::vector<uint8_t> b;
    put(b, {0, 0, 0, 1, 0, 0, 0, 1, 0});
    put(b, {0, 0, 1, 0, 0, 1, 0, 0, 1});
    return b;
}

// One mesh (accessor 0: POSITION, 1: NORMAL, both on buffer 0) on one node; `uri` is buffer 0's.
Json triangleDoc(const std::string& uri) {
    Json doc = {
        {"asset", {{"version", "2.0"}}},
        {"scene", 0},
        {"scenes", {{{"nodes", {0}}}}},
        {"nodes", {{{"mesh", 0}}}},
        {"meshes", {{{"primitives", {{{"attributes", {{"POSITION", 0}, {"NORMAL", 1}}}}}}}}},
        {"buffers", {{{"uri", uri}, {"byteLength", 72}}}},
        {"bufferViews", {{{"buffer", 0}, {"byteOffset", 0}, {"byteLength", 36}},
                         {{"buffer", 0}, {"byteOffset", 36}, {"byteLength", 36}}}},
        {"accessors",
         {{{"bufferView", 0}, {"componentType", 5126}, {"count", 3}, {"type", "VEC3"}, {"min", {0, 0, 0}},
           {"max", {1, 1, 0}}},
          {{"bufferView", 1}, {"componentType", 5126}, {"count", 3}, {"type", "VEC3"}}}},
    };
    return doc;
}

class GltfValid : public ::testing::Test {
protected:
    void SetUp() override { mDir = test::scratchDir(); }
    std::filesystem::path write(const std::string& name, const Json& doc) {
        test::writeText(mDir / name, doc.dump(2));
        return mDir / name;
    }
    static void expectTriangle(const Scene& scene) {
        ASSERT_EQ(scene.primitives.size(), 1u);
        ASSERT_EQ(scene.vertices.size(), 3u);
        EXPECT_EQ(scene.vertices[0].position, glm::vec3(0, 0, 0));
        EXPECT_EQ(scene.vertices[1].position, glm::vec3(1, 0, 0));
        EXPECT_EQ(scene.vertices[2].position, glm::vec3(0, 1, 0));
    }
    std::filesystem::path mDir;
};

// RFC 2397: `data:[<media type>][;base64],<data>`; without ;base64 the data is percent-encoded octets. tinygltf only
// decodes base64 with a few media types and took the rest for file names ("File not found : data:...").
TEST_F(GltfValid, NonBase64DataUris) {
    Json doc = triangleDoc("data:application/gltf-buffer," + percent(triangleBytes()));
    // The validator's own example, a one-byte buffer, and a data URI with no media type at all.
    doc["buffers"].push_back({{"uri", "data:application/gltf-buffer,0"}, {"byteLength", 1}});
    doc["buffers"].push_back({{"uri", "data:,A%20b"}, {"byteLength", 3}});
    std::vector<std::string> warnings;
    Scene scene = loadGltf(write("percent.gltf", doc), warnings);
    expectTriangle(scene);
    EXPECT_TRUE(warnings.empty()) << warnings.front();

    // In a GLB, with the triangle in the binary chunk: the JSON is rewritten for tinygltf into a new container.
    Json glb = doc;
    glb["buffers"][0] = {{"byteLength", 72}};
    test::writeBytes(mDir / "percent.glb", test::makeGlb(glb.dump(), triangleBytes()));
    expectTriangle(loadGltf(mDir / "percent.glb"));

    // A data URI whose length is not byteLength, or whose escapes are broken, is named with its JSON pointer.
    doc["buffers"][1]["byteLength"] = 2;
    expectUserError([&] { loadGltf(write("short.gltf", doc)); },
                    {"short.gltf", "buffers[1].uri", "/buffers/1/uri", "holds 1 bytes; expected byteLength 2"});
    doc["buffers"][1] = {{"uri", "data:application/gltf-buffer,%G0"}, {"byteLength", 1}};
    expectUserError([&] { loadGltf(write("escape.gltf", doc)); },
                    {"escape.gltf", "/buffers/1/uri", "not followed by two hex digits"});
}

// glTF 2.0 3.6.2.3: an accessor without a bufferView is zeros. The validator's mesh/valid.gltf has such an index
// accessor, which tinygltf refused ("accessor[0] invalid bufferView"): here a degenerate triangle 0, 0, 0.
TEST_F(GltfValid, IndexAccessorWithoutBufferViewIsZeros) {
    Json doc = triangleDoc(base64Uri(triangleBytes()));
    doc["accessors"].push_back({{"componentType", 5123}, {"count", 3}, {"type", "SCALAR"}});
    doc["meshes"][0]["primitives"][0]["indices"] = 2;
    Scene scene = loadGltf(write("zero_indices.gltf", doc));
    expectTriangle(scene);
    ASSERT_EQ(scene.primitives[0].indexCount, 3u);
    ASSERT_EQ(scene.indices.size(), 3u);
    EXPECT_EQ(scene.indices, (std::vector<uint32_t>{0, 0, 0}));
}

// Sparse-only accessors (no bufferView, a sparse block): zeros with the substitutions, for vertex positions and for
// indices alike.
TEST_F(GltfValid, SparseOnlyAccessors) {
    std::vector<uint8_t> b;
    put(b, {0, 0, 1, 0, 0, 1, 0, 0, 1}); // 0..36: normals
    putU16(b, {1, 2});                   // 36..40: positions' sparse indices
    put(b, {1, 0, 0, 0, 1, 0});          // 40..64: positions' sparse values
    putU16(b, {1, 2});                   // 64..68: indices' sparse indices
    putU16(b, {2, 1});                   // 68..72: indices' sparse values
    Json doc = triangleDoc(base64Uri(b));
    doc["bufferViews"] = {{{"buffer", 0}, {"byteOffset", 0}, {"byteLength", 36}},
                          {{"buffer", 0}, {"byteOffset", 36}, {"byteLength", 4}},
                          {{"buffer", 0}, {"byteOffset", 40}, {"byteLength", 24}},
                          {{"buffer", 0}, {"byteOffset", 64}, {"byteLength", 4}},
                          {{"buffer", 0}, {"byteOffset", 68}, {"byteLength", 4}}};
    doc["accessors"] = {
        {{"componentType", 5126},
         {"count", 3},
         {"type", "VEC3"},
         {"min", {0, 0, 0}},
         {"max", {1, 1, 0}},
         {"sparse",
          {{"count", 2}, {"indices", {{"bufferView", 1}, {"componentType", 5123}}}, {"values", {{"bufferView", 2}}}}}},
        {{"bufferView", 0}, {"componentType", 5126}, {"count", 3}, {"type", "VEC3"}},
        {{"componentType", 5123},
         {"count", 3},
         {"type", "SCALAR"},
         {"sparse",
          {{"count", 2}, {"indices", {{"bufferView", 3}, {"componentType", 5123}}}, {"values", {{"bufferView", 4}}}}}},
    };
    doc["meshes"][0]["primitives"][0]["indices"] = 2;
    Scene scene = loadGltf(write("sparse_only.gltf", doc));
    expectTriangle(scene);
    EXPECT_EQ(scene.indices, (std::vector<uint32_t>{0, 2, 1}));

    // A sparse index past the accessor's count is named, not written out of bounds.
    b[68 - 2] = 3; // indices' sparse index 2 → 3
    doc["buffers"][0]["uri"] = base64Uri(b);
    expectUserError([&] { loadGltf(write("sparse_range.gltf", doc)); },
                    {"sparse_range.gltf", "meshes[0].primitives[0].indices", "/meshes/0/primitives/0/indices",
                     "index 3 at position 1 >= count 3"});
}

// A skin {} lacks the required joints: tinygltf refused it with an empty reason. Now every missing required property
// is named with its pointer, and a tinygltf refusal never reads as an empty message.
TEST_F(GltfValid, MissingRequiredPropertiesAreNamed) {
    Json doc = triangleDoc(base64Uri(triangleBytes()));
    doc["skins"] = {Json::object()};
    expectUserError([&] { loadGltf(write("empty_skin.gltf", doc)); },
                    {"empty_skin.gltf: skins[0].joints: missing; expected a non-empty array of node indices",
                     "(at /skins/0/joints)"});
    doc["skins"] = {{{"joints", {7}}}};
    expectUserError([&] { loadGltf(write("skin_joint.gltf", doc)); }, {"/skins/0/joints/0", "index 7 out of range"});
    doc.erase("skins");
    doc["accessors"][1].erase("type");
    expectUserError([&] { loadGltf(write("no_type.gltf", doc)); }, {"/accessors/1/type", "missing"});
}

// An extension in extensionsUsed that vitrine does not implement is ignored with exactly one warning naming it
// (one in extensionsRequired stays an error, see GltfErrors).
TEST_F(GltfValid, UnsupportedUsedExtensionWarnsOnce) {
    Json doc = triangleDoc(base64Uri(triangleBytes()));
    doc["extensionsUsed"] = {"KHR_materials_anisotropy", "KHR_texture_transform"};
    doc["materials"] = {{{"extensions", {{"KHR_materials_anisotropy", {{"anisotropyStrength", 1}}}}}}};
    doc["meshes"][0]["primitives"][0]["material"] = 0;
    std::vector<std::string> warnings;
    Scene scene = loadGltf(write("anisotropy.gltf", doc), warnings);
    expectTriangle(scene);
    ASSERT_EQ(warnings.size(), 1u);
    EXPECT_NE(
        warnings[0].find("anisotropy.gltf: extensionsUsed[0]: extension 'KHR_materials_anisotropy' is not supported"),
        std::string::npos)
        << warnings[0];
    EXPECT_NE(warnings[0].find("ignored"), std::string::npos) << warnings[0];
    EXPECT_NE(warnings[0].find("(at /extensionsUsed/0)"), std::string::npos) << warnings[0];
}

// loadGltfReporting(): what the scene node and export-scene call. Warnings are printed once each on stderr; strict
// makes them an error that lists them.
TEST_F(GltfValid, ReportingPrintsWarningsOnceAndStrictRefuses) {
    Json doc = triangleDoc(base64Uri(triangleBytes()));
    doc["extensionsUsed"] = {"KHR_materials_anisotropy"};
    doc["nodes"].push_back({{"name", "second"}, {"mesh", 0}});
    doc["scenes"][0]["nodes"].push_back(1);
    doc["meshes"][0]["primitives"][0]["attributes"]["TEXCOORD_5"] = 0; // ignored attribute, met once
    auto file = write("report.gltf", doc);
    ::testing::internal::CaptureStderr();
    loadGltfReporting(file, false);
    std::string err = ::testing::internal::GetCapturedStderr();
    auto count = [&](const std::string& s) {
        size_t n = 0;
        for (size_t at = err.find(s); at != std::string::npos; at = err.find(s, at + 1))
            ++n;
        return n;
    };
    EXPECT_EQ(count("warning: "), 2u) << err;
    EXPECT_EQ(count("KHR_materials_anisotropy"), 1u) << err;
    EXPECT_EQ(count("(at /meshes/0/primitives/0/attributes/TEXCOORD_5)"), 1u) << err;

    expectUserError([&] { loadGltfReporting(file, true); },
                    {"report.gltf: 2 warnings, which strict loading", "KHR_materials_anisotropy", "TEXCOORD_5"});
    // Without warnings strict changes nothing.
    loadGltfReporting(write("clean.gltf", triangleDoc(base64Uri(triangleBytes()))), true);
}

} // namespace
} // namespace vitrine::scene
