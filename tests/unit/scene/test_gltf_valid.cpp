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

// Whether one of warnings has every part.
bool warned(const std::vector<std::string>& warnings, std::initializer_list<const char*> parts) {
    for (const std::string& w : warnings) {
        bool all = true;
        for (const char* p : parts)
            all = all && w.find(p) != std::string::npos;
        if (all) return true;
    }
    return false;
}

// Files the Khronos validator (main at 434283b, test/) reports with 0 errors that vitrine refused: now each loads
// with a warning naming what is not drawn, at its JSON pointer. Textures without a `source` (a texture-source
// extension, or none), a texCoord beyond the two UV sets vitrine keeps, buffers with no data vitrine can read (no
// uri outside a .glb's first buffer, or a remote uri: zeros), weights that sum to 0 (drawn unskinned), a primitive
// without POSITION (skipped), TRIANGLES whose count is not a multiple of 3 (the rest dropped), yfov >= π, an
// accessor type glTF does not define (while nothing reads it).
TEST_F(GltfValid, WhatTheValidatorAcceptsLoadsWithWarnings) {
    const std::string uri = base64Uri(triangleBytes());
    {
        Json doc = triangleDoc(uri);
        doc["textures"] = {{{"name", "basisu only"}}, {{"source", 0}}};
        doc["images"] = {{{"uri", base64Uri({0x89, 'P', 'N', 'G'})}}}; // not decodable either
        doc["materials"] = {{{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}}},
                             {"normalTexture", {{"index", 1}}},
                             {"emissiveTexture", {{"index", 1}, {"texCoord", 2}}}}};
        doc["meshes"][0]["primitives"][0]["material"] = 0;
        std::vector<std::string> warnings;
        Scene scene = loadGltf(write("sourceless.gltf", doc), warnings);
        expectTriangle(scene);
        EXPECT_TRUE(scene.textures.empty());
        EXPECT_TRUE(scene.images.empty());
        EXPECT_TRUE(warned(warnings, {"/textures/0/source", "drawn without it"}));
        EXPECT_TRUE(warned(warnings, {"/images/0", "could not be decoded"}));
        EXPECT_TRUE(warned(warnings, {"/materials/0/emissiveTexture/texCoord", "TEXCOORD_0 and TEXCOORD_1"}));
    }
    {
        // TEXCOORD_0 on a buffer without a uri, COLOR_0 on a remote one: zeros, each warned once.
        Json doc = triangleDoc(uri);
        doc["buffers"].push_back({{"byteLength", 24}});
        doc["buffers"].push_back({{"uri", "https://example.com/colour.bin"}, {"byteLength", 48}});
        doc["bufferViews"].push_back({{"buffer", 1}, {"byteLength", 24}});
        doc["bufferViews"].push_back({{"buffer", 2}, {"byteLength", 48}});
        doc["accessors"].push_back({{"bufferView", 2}, {"componentType", 5126}, {"count", 3}, {"type", "VEC2"}});
        doc["accessors"].push_back({{"bufferView", 3}, {"componentType", 5126}, {"count", 3}, {"type", "VEC4"}});
        doc["meshes"][0]["primitives"][0]["attributes"]["TEXCOORD_0"] = 2;
        doc["meshes"][0]["primitives"][0]["attributes"]["COLOR_0"] = 3;
        std::vector<std::string> warnings;
        Scene scene = loadGltf(write("no_uri.gltf", doc), warnings);
        expectTriangle(scene);
        for (const Vertex& v : scene.vertices) {
            EXPECT_EQ(v.uv0, glm::vec2(0.0f));
            EXPECT_EQ(glm::vec3(v.color), glm::vec3(0.0f));
        }
        EXPECT_TRUE(warned(warnings, {"/buffers/1", "has no uri", "(24) read as zeros"}));
        EXPECT_TRUE(warned(warnings, {"/buffers/2", "https://example.com/colour.bin", "not a local file"}));
        doc["buffers"][1]["byteLength"] = 1ll << 40;
        expectUserError([&] { loadGltf(write("huge_no_uri.gltf", doc)); }, {"/buffers/1", "no data vitrine can read"});
    }
    {
        // A skin whose weights are all 0 (the accessor has no bufferView), a primitive without POSITION, four vertices
        // of TRIANGLES, a 4-radian yfov and an unused accessor of type "NotaVEC3".
        Json doc = triangleDoc(uri);
        doc["accessors"].push_back({{"componentType", 5121}, {"count", 3}, {"type", "VEC4"}});     // JOINTS_0: 2
        doc["accessors"].push_back({{"componentType", 5126}, {"count", 3}, {"type", "VEC4"}});     // WEIGHTS_0: 3
        doc["accessors"].push_back({{"componentType", 5126}, {"count", 4}, {"type", "VEC3"}});     // 4 zeros: 4
        doc["accessors"].push_back({{"componentType", 5126}, {"count", 1}, {"type", "NotaVEC3"}}); // 5
        doc["meshes"][0]["primitives"][0]["attributes"]["JOINTS_0"] = 2;
        doc["meshes"][0]["primitives"][0]["attributes"]["WEIGHTS_0"] = 3;
        doc["meshes"][0]["primitives"].push_back({{"attributes", {{"NORMAL", 1}}}});
        doc["meshes"][0]["primitives"].push_back({{"attributes", {{"POSITION", 4}}}});
        doc["skins"] = {{{"joints", {1}}}};
        doc["nodes"][0]["skin"] = 0;
        doc["nodes"].push_back({{"camera", 0}});
        doc["scenes"][0]["nodes"].push_back(1);
        doc["cameras"] = {{{"type", "perspective"}, {"perspective", {{"yfov", 4.0}, {"znear", 0.1}}}}};
        std::vector<std::string> warnings;
        Scene scene = loadGltf(write("odd.gltf", doc), warnings);
        ASSERT_EQ(scene.primitives.size(), 2u);
        EXPECT_FALSE(scene.primitives[0].skinned);
        EXPECT_EQ(scene.vertices[1].position, glm::vec3(1, 0, 0)); // where the file puts it, not collapsed
        EXPECT_EQ(scene.primitives[1].indexCount, 3u);
        ASSERT_EQ(scene.cameras.size(), 1u);
        EXPECT_FLOAT_EQ(scene.cameras[0].yfov, 3.14f);
        EXPECT_TRUE(warned(warnings, {"/meshes/0/primitives/0/attributes/WEIGHTS_0", "3 of 3", "unskinned"}));
        EXPECT_TRUE(warned(warnings, {"/meshes/0/primitives/1/attributes", "no POSITION", "skipped"}));
        EXPECT_TRUE(warned(warnings, {"/meshes/0/primitives/2", "not a multiple of 3", "last 1"}));
        EXPECT_TRUE(warned(warnings, {"/cameras/0/perspective/yfov", "3.14"}));
        EXPECT_TRUE(warned(warnings, {"/accessors/5/type", "NotaVEC3", "nothing may read"}));
        // Read, the accessor of unknown type is an error naming it.
        doc["meshes"][0]["primitives"][2]["attributes"]["POSITION"] = 5;
        expectUserError([&] { loadGltf(write("read_unknown.gltf", doc)); },
                        {"/meshes/0/primitives/2/attributes/POSITION", "accessors[5]", "'\"NotaVEC3\"'"});
    }
}

// JSON has one kind of number: 1.0, 1e0 and 10e-1 are the integer 1 wherever glTF wants an integer (the validator's
// json/integer_written_as_float.gltf). The triangle loads as from integers, and tinygltf reads the rewritten JSON.
TEST_F(GltfValid, IntegersWrittenAsFloats) {
    Json doc = triangleDoc(base64Uri(triangleBytes()));
    doc["scene"] = 0.0;
    doc["scenes"][0]["nodes"][0] = 0.0;
    doc["nodes"][0]["mesh"] = 1e0;
    doc["nodes"][0]["mesh"] = 0.0;
    doc["meshes"][0]["primitives"][0]["attributes"]["POSITION"] = 0.0;
    doc["meshes"][0]["primitives"][0]["attributes"]["NORMAL"] = 1.0;
    doc["buffers"][0]["byteLength"] = 72.0;
    doc["bufferViews"][1]["byteOffset"] = 36.0;
    doc["accessors"][0]["componentType"] = 5126.0;
    doc["accessors"][0]["count"] = 3.0;
    std::vector<std::string> warnings;
    Scene scene = loadGltf(write("floats.gltf", doc), warnings);
    expectTriangle(scene);
    EXPECT_EQ(scene.vertices[2].normal, glm::vec3(0, 0, 1));
    EXPECT_TRUE(warnings.empty()) << warnings.front();
    // Not integral: still refused, naming it.
    doc["accessors"][0]["count"] = 2.5;
    expectUserError([&] { loadGltf(write("fraction.gltf", doc)); },
                    {"fraction.gltf", "accessors[0].count", "/accessors/0/count", "expected an integer, got 2.5"});
}

} // namespace
} // namespace vitrine::scene
