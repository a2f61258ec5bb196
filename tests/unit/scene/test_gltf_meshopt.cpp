// EXT_meshopt_compression (issue #29 item 3): files compressed by an independent encoder — Debian's gltfpack, installed
// by tools/install-deps.sh — load as the geometry they were made from; every mode and filter of the extension, written
// here with libmeshoptimizer's encoders, decodes to the values encoded; bad fields and corrupt data give errors naming
// the field.

#include "core/scene/gltf.hpp"

#include "test_util.hpp"

#include <gtest/gtest.h>
#include <meshoptimizer.h>

#include <glm/gtc/quaternion.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <cstring>

namespace vitrine::scene {
namespace {

using test::Json;

// One triangle corner in world space.
struct Corner {
    glm::vec3 position, normal;
    glm::vec2 uv;
};
using Triangle = std::array<Corner, 3>;

std::vector<Triangle> worldTriangles(const Scene& s) {
    std::vector<Triangle> out;
    for (const MeshInstance& instance : s.instances) {
        const Mesh& mesh = s.meshes[instance.mesh];
        const glm::mat3 normalMatrix = glm::transpose(glm::inverse(glm::mat3(instance.world)));
        for (uint32_t p = 0; p < mesh.primitiveCount; ++p) {
            const Primitive& prim = s.primitives[mesh.firstPrimitive + p];
            for (uint32_t k = 0; k + 2 < prim.indexCount; k += 3) {
                Triangle t;
                for (int j = 0; j < 3; ++j) {
                    const Vertex& v = s.vertices[prim.vertexOffset + s.indices[prim.firstIndex + k + j]];
                    t[j] = {glm::vec3(instance.world * glm::vec4(v.position, 1.0f)),
                            glm::normalize(normalMatrix * v.normal), v.uv0};
                }
                // Triangles of zero area (a UV sphere's poles) draw nothing; gltfpack removes them.
                const glm::vec3 e = glm::cross(t[1].position - t[0].position, t[2].position - t[0].position);
                if (glm::length(e) > 1e-9f) out.push_back(t);
            }
        }
    }
    return out;
}

glm::vec3 centroid(const Triangle& t) {
    return (t[0].position + t[1].position + t[2].position) / 3.0f;
}

// Every triangle of `want` has one in `got` with the same corners in the same winding: positions within
// positionTolerance, normals within normalTolerance, texture coordinates within uvTolerance (< 0: not compared).
// gltfpack reorders vertices and triangles and merges primitives, so triangles are matched by their centroids.
void expectSameTriangles(const std::vector<Triangle>& want, const std::vector<Triangle>& got, float positionTolerance,
                         float normalTolerance, float uvTolerance, const std::string& what) {
    ASSERT_EQ(got.size(), want.size()) << what;
    int bad = 0;
    for (const Triangle& w : want) {
        const glm::vec3 c = centroid(w);
        const Triangle* best = nullptr;
        float bestDistance = 1e30f;
        for (const Triangle& g : got) {
            const float d = glm::distance(centroid(g), c);
            if (d < bestDistance) bestDistance = d, best = &g;
        }
        // The corner of best at w[0], then the winding's order from there.
        int first = 0;
        for (int j = 1; j < 3; ++j)
            if (glm::distance((*best)[j].position, w[0].position) <
                glm::distance((*best)[first].position, w[0].position))
                first = j;
        for (int j = 0; j < 3 && bad < 5; ++j) {
            const Corner& a = w[j];
            const Corner& b = (*best)[(first + j) % 3];
            const bool ok = glm::distance(a.position, b.position) <= positionTolerance &&
                            glm::distance(a.normal, b.normal) <= normalTolerance &&
                            (uvTolerance < 0.0f || glm::distance(a.uv, b.uv) <= uvTolerance);
            if (!ok) {
                ++bad;
                ADD_FAILURE() << what << ": corner at (" << a.position.x << ", " << a.position.y << ", " << a.position.z
                              << ") normal (" << a.normal.x << ", " << a.normal.y << ", " << a.normal.z << ") uv ("
                              << a.uv.x << ", " << a.uv.y << ") is (" << b.position.x << ", " << b.position.y << ", "
                              << b.position.z << ") normal (" << b.normal.x << ", " << b.normal.y << ", " << b.normal.z
                              << ") uv (" << b.uv.x << ", " << b.uv.y << ")";
            }
        }
    }
}

// gltfpack (Debian's, installed by tools/install-deps.sh) on `source` with `options` into `out`.
void gltfpack(const std::filesystem::path& source, const std::filesystem::path& out, const std::string& options) {
    const std::filesystem::path log = out.string() + ".log";
    const std::string command =
        "gltfpack -i '" + source.string() + "' -o '" + out.string() + "' " + options + " > '" + log.string() + "' 2>&1";
    ASSERT_EQ(std::system(command.c_str()), 0) << command << " failed (is gltfpack installed? tools/install-deps.sh):\n"
                                               << std::string(test::readBytes(log).begin(), test::readBytes(log).end());
}

Json gltfJson(const std::filesystem::path& file) {
    if (file.extension() == ".gltf") return test::readJson(file);
    const std::vector<uint8_t> glb = test::readBytes(file);
    uint32_t length = 0;
    std::memcpy(&length, glb.data() + 12, 4);
    return Json::parse(glb.begin() + 20, glb.begin() + 20 + length);
}

// How many bufferViews are compressed, and how many of them with a filter.
std::pair<int, int> compressedViews(const Json& doc) {
    int views = 0, filtered = 0;
    for (const Json& v : doc.value("bufferViews", Json::array())) {
        if (!v.contains("extensions") || !v["extensions"].contains("EXT_meshopt_compression")) continue;
        ++views;
        filtered += v["extensions"]["EXT_meshopt_compression"].value("filter", "NONE") != "NONE";
    }
    return {views, filtered};
}

TEST(GltfMeshopt, GltfpackFilesLoadAsTheirSources) {
    const std::filesystem::path dir = test::scratchDir();
    const std::filesystem::path sources[] = {
        test::dataDir() / "viewer" / "white_sphere.gltf", test::dataDir() / "viewer" / "textured.gltf",
        test::dataDir() / "viewer" / "metal_spheres.gltf", test::dataDir() / "corpus" / "morph_cube.gltf"};
    for (const std::filesystem::path& source : sources) {
        const Scene original = loadGltf(source);
        const std::vector<Triangle> want = worldTriangles(original);
        const float size = glm::length(original.bounds.max - original.bounds.min);
        const std::string name = source.stem().string();
        // -c -noq: compressed, no quantization: float data through the codecs, so the same values exactly.
        // -cc: quantized (KHR_mesh_quantization: positions 14 bits, normals 8 bits) and compressed with filters.
        for (const auto& [options, file] : {std::pair<std::string, std::string>{"-c -noq", name + "_exact.glb"},
                                            std::pair<std::string, std::string>{"-cc", name + "_quantized.gltf"}}) {
            const std::filesystem::path out = dir / file;
            gltfpack(source, out, options);
            const auto [views, filtered] = compressedViews(gltfJson(out));
            EXPECT_GE(views, 2) << file << ": gltfpack compressed no vertex and index data";
            if (options == "-cc") EXPECT_GE(filtered, 1) << file << ": no view used a filter";
            std::vector<std::string> warnings;
            const Scene packed = loadGltf(out, warnings);
            for (const std::string& w : warnings)
                EXPECT_EQ(w.find("EXT_meshopt"), std::string::npos) << w;
            if (options == "-cc") {
                // Positions to 14 bits of the mesh's extent, normals to 8 bits; texture coordinates are dequantized
                // by a texture transform gltfpack adds, which worldTriangles() does not apply.
                expectSameTriangles(want, worldTriangles(packed), 2e-4f * size, 0.03f, -1.0f, file);
            } else {
                expectSameTriangles(want, worldTriangles(packed), 1e-5f * size, 1e-5f, 1e-6f, file);
            }
        }
    }
}

// A file with one compressed view per mode and filter, encoded here by libmeshoptimizer's encoders: a two-triangle quad
// (float positions, NONE; int8 normals, OCTAHEDRAL; TRIANGLES indices, 16-bit) drawn again as a second primitive whose
// 32-bit indices are INDICES, and a node animation whose rotations are QUATERNION (int16) and translations EXPONENTIAL.
class MeshoptModes : public ::testing::Test {
protected:
    void SetUp() override {
        mDir = test::scratchDir();
        const float positions[4][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
        const float normals[4][4] = {{0, 0, 1, 0}, {0.6f, 0, 0.8f, 0}, {0, -0.6f, 0.8f, 0}, {0.48f, 0.6f, 0.64f, 0}};
        const unsigned int triangles[6] = {0, 1, 2, 0, 2, 3};
        const unsigned int sequence[6] = {0, 2, 3, 0, 1, 2};
        const float times[3] = {0.0f, 1.0f, 2.0f};
        const float h = std::sqrt(0.5f);
        const float rotations[3][4] = {{0, 0, 0, 1}, {0, h, 0, h}, {h, 0, 0, h}};
        const float translations[3][3] = {{0, 0, 0}, {1.5f, -2.25f, 1e-3f}, {-3e4f, 0.125f, 7.0f}};
        for (int i = 0; i < 4; ++i)
            mNormals[i] = glm::vec3(normals[i][0], normals[i][1], normals[i][2]);
        for (int i = 0; i < 3; ++i) {
            mRotations[i] = glm::vec4(rotations[i][0], rotations[i][1], rotations[i][2], rotations[i][3]);
            mTranslations[i] = glm::vec3(translations[i][0], translations[i][1], translations[i][2]);
        }

        std::vector<uint8_t> packed; // the compressed buffer
        mDoc = {{"asset", {{"version", "2.0"}}},
                {"extensionsUsed", {"EXT_meshopt_compression", "KHR_mesh_quantization"}},
                {"extensionsRequired", {"EXT_meshopt_compression", "KHR_mesh_quantization"}},
                {"bufferViews", Json::array()},
                {"accessors", Json::array()}};
        size_t fallbackLength = 0;
        // Appends a compressed view of `count` elements of `stride` bytes (decoded size) and its accessor.
        auto view = [&](const std::vector<uint8_t>& encoded, size_t count, size_t stride, const char* mode,
                        const char* filter, Json accessor, bool vertexStride) {
            Json ext = {{"buffer", 0},
                        {"byteOffset", packed.size()},
                        {"byteLength", encoded.size()},
                        {"byteStride", stride},
                        {"count", count},
                        {"mode", mode}};
            if (std::strcmp(filter, "NONE") != 0) ext["filter"] = filter;
            packed.insert(packed.end(), encoded.begin(), encoded.end());
            packed.resize((packed.size() + 3) / 4 * 4);
            Json v = {{"buffer", 1},
                      {"byteOffset", fallbackLength},
                      {"byteLength", count * stride},
                      {"extensions", {{"EXT_meshopt_compression", ext}}}};
            if (vertexStride) v["byteStride"] = stride;
            fallbackLength += (count * stride + 3) / 4 * 4;
            accessor["bufferView"] = mDoc["bufferViews"].size();
            accessor["count"] = count;
            mDoc["bufferViews"].push_back(v);
            mDoc["accessors"].push_back(accessor);
        };
        auto vertices = [](const void* data, size_t count, size_t stride) {
            std::vector<uint8_t> out(meshopt_encodeVertexBufferBound(count, stride));
            out.resize(meshopt_encodeVertexBuffer(out.data(), out.size(), data, count, stride));
            return out;
        };
        view(vertices(positions, 4, 12), 4, 12, "ATTRIBUTES", "NONE",
             {{"componentType", 5126}, {"type", "VEC3"}, {"min", {0, 0, 0}}, {"max", {1, 1, 0}}}, true);
        int8_t octahedral[4][4];
        meshopt_encodeFilterOct(octahedral, 4, 4, 8, &normals[0][0]);
        view(vertices(octahedral, 4, 4), 4, 4, "ATTRIBUTES", "OCTAHEDRAL",
             {{"componentType", 5120}, {"normalized", true}, {"type", "VEC3"}}, true);
        std::vector<uint8_t> tri(meshopt_encodeIndexBufferBound(6, 4));
        tri.resize(meshopt_encodeIndexBuffer(tri.data(), tri.size(), triangles, 6)); // decoded as 16-bit
        view(tri, 6, 2, "TRIANGLES", "NONE", {{"componentType", 5123}, {"type", "SCALAR"}}, false);
        std::vector<uint8_t> seq(meshopt_encodeIndexSequenceBound(6, 4));
        seq.resize(meshopt_encodeIndexSequence(seq.data(), seq.size(), sequence, 6));
        view(seq, 6, 4, "INDICES", "NONE", {{"componentType", 5125}, {"type", "SCALAR"}}, false);
        view(vertices(times, 3, 4), 3, 4, "ATTRIBUTES", "NONE",
             {{"componentType", 5126}, {"type", "SCALAR"}, {"min", {0.0}}, {"max", {2.0}}}, false);
        int16_t quaternions[3][4];
        meshopt_encodeFilterQuat(quaternions, 3, 8, 16, &rotations[0][0]);
        view(vertices(quaternions, 3, 8), 3, 8, "ATTRIBUTES", "QUATERNION",
             {{"componentType", 5122}, {"normalized", true}, {"type", "VEC4"}}, false);
        uint32_t exponential[3][3];
        meshopt_encodeFilterExp(exponential, 3, 12, 24, &translations[0][0]);
        view(vertices(exponential, 3, 12), 3, 12, "ATTRIBUTES", "EXPONENTIAL",
             {{"componentType", 5126}, {"type", "VEC3"}}, false);

        mDoc["buffers"] = {
            {{"byteLength", packed.size()}},
            {{"byteLength", fallbackLength}, {"extensions", {{"EXT_meshopt_compression", {{"fallback", true}}}}}}};
        mDoc["meshes"] = {{{"primitives",
                            {{{"attributes", {{"POSITION", 0}, {"NORMAL", 1}}}, {"indices", 2}},
                             {{"attributes", {{"POSITION", 0}, {"NORMAL", 1}}}, {"indices", 3}}}}}};
        mDoc["nodes"] = {{{"mesh", 0}}};
        mDoc["scenes"] = {{{"nodes", {0}}}};
        mDoc["scene"] = 0;
        mDoc["animations"] = {{{"samplers", {{{"input", 4}, {"output", 5}}, {{"input", 4}, {"output", 6}}}},
                               {"channels",
                                {{{"sampler", 0}, {"target", {{"node", 0}, {"path", "rotation"}}}},
                                 {{"sampler", 1}, {"target", {{"node", 0}, {"path", "translation"}}}}}}}};
        mPacked = packed;
    }

    std::filesystem::path write(const Json& doc, const std::vector<uint8_t>& bin, const std::string& name) const {
        const std::filesystem::path file = mDir / name;
        test::writeBytes(file, test::makeGlb(doc.dump(), bin));
        return file;
    }

    std::filesystem::path mDir;
    Json mDoc;
    std::vector<uint8_t> mPacked;
    glm::vec3 mNormals[4];
    glm::vec4 mRotations[3];
    glm::vec3 mTranslations[3];
};

TEST_F(MeshoptModes, EveryModeAndFilterDecodesAsEncoded) {
    const Scene s = loadGltf(write(mDoc, mPacked, "modes.glb"));
    ASSERT_EQ(s.meshes.size(), 1u);
    const Mesh& mesh = s.meshes[0];
    ASSERT_EQ(mesh.primitiveCount, 2u);
    const glm::vec3 positions[4] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
    const uint32_t wanted[2][6] = {{0, 1, 2, 0, 2, 3}, {0, 2, 3, 0, 1, 2}}; // TRIANGLES, INDICES
    for (uint32_t p = 0; p < 2; ++p) {
        const Primitive& prim = s.primitives[mesh.firstPrimitive + p];
        ASSERT_EQ(prim.indexCount, 6u);
        for (int k = 0; k < 6; ++k) {
            const Vertex& v = s.vertices[prim.vertexOffset + s.indices[prim.firstIndex + k]];
            const uint32_t i = wanted[p][k];
            EXPECT_EQ(v.position, positions[i]) << "primitive " << p << ", corner " << k;
            // 8-bit octahedral: within 1/127 per component, a few times over after renormalising.
            EXPECT_LT(glm::distance(v.normal, glm::normalize(mNormals[i])), 0.02f)
                << "primitive " << p << ", corner " << k;
        }
    }
    // The animation's keys: rotations to 16 bits per component, translations to 24 bits of mantissa.
    for (int k = 0; k < 3; ++k) {
        const glm::mat4 world = s.evaluate(double(k)).nodeWorld[0];
        const glm::quat q(mRotations[k].w, mRotations[k].x, mRotations[k].y, mRotations[k].z);
        const glm::mat3 rotation = glm::mat3_cast(q);
        for (int c = 0; c < 3; ++c)
            for (int r = 0; r < 3; ++r)
                EXPECT_NEAR(world[c][r], rotation[c][r], 2e-4f) << "key " << k;
        // The vector's components share the exponent of its largest (libmeshoptimizer 0.18).
        const float largest =
            std::max({std::abs(mTranslations[k].x), std::abs(mTranslations[k].y), std::abs(mTranslations[k].z)});
        for (int c = 0; c < 3; ++c)
            EXPECT_NEAR(world[3][c], mTranslations[k][c], largest * std::ldexp(1.0f, -22)) << "key " << k;
    }
}

TEST_F(MeshoptModes, BadFieldsAndCorruptDataNameTheView) {
    const std::string ext = "bufferViews[1].extensions.EXT_meshopt_compression";
    {
        Json doc = mDoc;
        doc["bufferViews"][1]["extensions"]["EXT_meshopt_compression"]["mode"] = "VERTICES";
        const auto file = write(doc, mPacked, "mode.glb");
        test::expectUserError([&] { loadGltf(file); }, {"mode.glb", ext + ".mode", "'VERTICES'", "ATTRIBUTES"});
    }
    {
        Json doc = mDoc;
        doc["bufferViews"][1]["extensions"]["EXT_meshopt_compression"]["filter"] = "QUATERNION"; // on 4-byte normals
        const auto file = write(doc, mPacked, "filter.glb");
        test::expectUserError([&] { loadGltf(file); }, {"filter.glb", ext + ".byteStride", "QUATERNION expects 8"});
    }
    {
        Json doc = mDoc;
        doc["bufferViews"][1]["extensions"]["EXT_meshopt_compression"]["count"] = 5;
        const auto file = write(doc, mPacked, "count.glb");
        test::expectUserError([&] { loadGltf(file); }, {"count.glb", ext + ".count", "byteLength 16"});
    }
    {
        Json doc = mDoc;
        doc["bufferViews"][1]["extensions"]["EXT_meshopt_compression"]["byteLength"] = mPacked.size() * 2;
        const auto file = write(doc, mPacked, "range.glb");
        test::expectUserError([&] { loadGltf(file); }, {"range.glb", ext, "of buffer 0, which holds"});
    }
    {
        // The normals' compressed bytes overwritten: the vertex codec's header byte is no longer one it knows.
        std::vector<uint8_t> corrupt = mPacked;
        const size_t at = mDoc["bufferViews"][1]["extensions"]["EXT_meshopt_compression"]["byteOffset"].get<size_t>();
        corrupt[at] = 0xff;
        const auto file = write(mDoc, corrupt, "corrupt.glb");
        test::expectUserError([&] { loadGltf(file); }, {"corrupt.glb", ext, "do not decode as mode ATTRIBUTES",
                                                        "meshopt_decodeVertexBuffer", "libmeshoptimizer 0."});
    }
    {
        // A view that is not compressed reading the fallback buffer, which holds no data.
        Json doc = mDoc;
        doc["bufferViews"][2].erase("extensions");
        const auto file = write(doc, mPacked, "fallback.glb");
        test::expectUserError([&] { loadGltf(file); }, {"fallback.glb", "bufferViews[2].buffer", "fallback"});
    }
}

} // namespace
} // namespace vitrine::scene
