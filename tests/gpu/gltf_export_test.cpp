// What export-scene writes for another tool matches what vitrine renders: the museum's KHR_lights_punctual sun is the
// sun that the museum graph's sky.procedural node lights it with (issue #29 item 7).
#include "tests/gpu/gpu_test.hpp"

#include "core/scene/gltf.hpp"
#include "core/scene/museum.hpp"
#include "core/shading/sky.hpp"
#include "shaders/sky/sky.h"

#include <cstdio>
#include <fstream>
#include <iterator>

namespace vitrine::test {
namespace {

using nlohmann::json;

json glbJson(const std::filesystem::path& file) {
    std::ifstream in(file, std::ios::binary);
    std::vector<uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    uint32_t length = bytes[12] | bytes[13] << 8 | bytes[14] << 16 | uint32_t(bytes[15]) << 24;
    return json::parse(std::string(bytes.begin() + 20, bytes.begin() + 20 + length));
}

class GltfExport : public GpuTest {};

// The sky node of graphs/museum.json (its params as the file has them) on the museum scene gives the sun's RGB
// illuminance (sh texel 9, what lighting.deferred lights with); the exported GLB's directional light must say the
// same: color × intensity within the fp32-vs-fp64 difference of the sky shader and the CPU model (2e-3), and its
// node must point the light along the scene's sun.
TEST_F(GltfExport, MuseumSunIsTheSkyNodesSun) {
    std::ifstream in(std::string(VITRINE_SOURCE_DIR) + "/graphs/museum.json");
    json museumGraph = json::parse(in);
    json sky = museumGraph["nodes"]["sky"];
    ASSERT_EQ(sky["type"], "sky.procedural");
    ASSERT_EQ(sky["in"]["scene"], "scene.scene"); // its sun direction is the scene's
    json graph = {{"format", "vitrine-graph/1"},
                  {"frame", {{"width", 16}, {"height", 16}}},
                  {"nodes",
                   {{"scene", {{"type", "scene.museum"}, {"params", {{"texture_size", 16}}}}},
                    {"sky", {{"type", "sky.procedural"}, {"in", {{"scene", "scene.scene"}}}, {"params", sky["params"]}}}}},
                  {"outputs", {{"sh", "sky.sh"}}}};
    auto out = runGraph(graph);
    const Image& sh = out.at("sh");
    glm::dvec3 skySun(sh.at(SKY_TEXEL_SUN_ILLUMINANCE, 0)[0], sh.at(SKY_TEXEL_SUN_ILLUMINANCE, 0)[1],
                      sh.at(SKY_TEXEL_SUN_ILLUMINANCE, 0)[2]);

    scene::MuseumOptions options;
    options.textureSize = 16;
    scene::Scene museum = scene::buildMuseum(options);
    auto file = std::filesystem::path(VITRINE_TEST_OUT) / "gltf_export" / "museum_sun.glb";
    std::filesystem::create_directories(file.parent_path());
    scene::exportGlb(museum, file);
    json doc = glbJson(file);
    const json& lights = doc["extensions"]["KHR_lights_punctual"]["lights"];
    const json* sun = nullptr;
    for (const json& l : lights)
        if (l["type"] == "directional") sun = &l;
    ASSERT_NE(sun, nullptr);
    glm::dvec3 color((*sun)["color"][0].get<double>(), (*sun)["color"][1].get<double>(),
                     (*sun)["color"][2].get<double>());
    glm::dvec3 exported = color * (*sun)["intensity"].get<double>();
    std::printf("sky node's sun %.0f lux (%.0f, %.0f, %.0f); exported light %.0f lux (%.0f, %.0f, %.0f)\n",
                shading::luminance709(skySun), skySun.x, skySun.y, skySun.z, shading::luminance709(exported),
                exported.x, exported.y, exported.z);
    EXPECT_LT(glm::length(exported - skySun) / glm::length(skySun), 2e-3);
    EXPECT_LE(std::max({color.x, color.y, color.z}), 1.0); // glTF's colour range

    // Its node: a directional light shines down -Z; the node's -Z must be the direction away from the sun.
    glm::dquat q(1, 0, 0, 0);
    for (const json& n : doc["nodes"]) {
        if (n.contains("extensions") && n["extensions"].contains("KHR_lights_punctual") &&
            &lights[n["extensions"]["KHR_lights_punctual"]["light"].get<size_t>()] == sun)
            q = glm::dquat(n["rotation"][3].get<double>(), n["rotation"][0].get<double>(),
                           n["rotation"][1].get<double>(), n["rotation"][2].get<double>());
    }
    glm::dvec3 shines = q * glm::dvec3(0, 0, -1);
    glm::dvec3 toSun(sh.at(SKY_TEXEL_SUN_DIRECTION, 0)[0], sh.at(SKY_TEXEL_SUN_DIRECTION, 0)[1],
                     sh.at(SKY_TEXEL_SUN_DIRECTION, 0)[2]);
    EXPECT_LT(glm::length(shines + toSun), 1e-5);
}

} // namespace
} // namespace vitrine::test
