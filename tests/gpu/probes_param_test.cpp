// The scene nodes' `probes` / `probes_mode` params: a probe file merged into or replacing the scene's reflection
// probes, checked on the compiled graph's scene object (setup() applies it; no GPU work is needed), and its errors
// naming the graph's param, the probe file and the JSON pointer.
#include "core/base/error.hpp"
#include "core/graph/compiler.hpp"
#include "core/graph/loader.hpp"
#include "core/graph/registry.hpp"
#include "core/scene/gpu_scene.hpp"
#include "core/scene/museum.hpp"
#include "core/scene/scene.hpp"

#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <unistd.h>

namespace vitrine::test {
namespace {

using nlohmann::json;
namespace fs = std::filesystem;

class ProbesParam : public ::testing::Test {
protected:
    void SetUp() override {
        mDir = fs::temp_directory_path() / ("vitrine_probes_param_" + std::to_string(::getpid()));
        fs::create_directories(mDir);
    }
    void TearDown() override { fs::remove_all(mDir); }

    std::string writeProbes(const std::string& text) {
        fs::path file = mDir / "probes.json";
        std::ofstream(file) << text;
        return file.string();
    }
    // A graph of one scene node (`type` with `params`) feeding a G-buffer.
    static json graph(const std::string& type, const json& params) {
        return {{"format", "vitrine-graph/1"},
                {"frame", {{"width", 16}, {"height", 16}}},
                {"nodes",
                 {{"scene", {{"type", type}, {"params", params}}},
                  {"gbuffer", {{"type", "gbuffer.layered"}, {"in", {{"scene", "scene.scene"}}}}}}},
                {"outputs", {{"normal", "gbuffer.normal"}}}};
    }
    // The scene the compiled graph's scene node publishes.
    static std::vector<scene::ReflectionProbe> probesOf(const json& doc) {
        CompiledGraph g = compileGraph(validateGraph(doc, (fs::temp_directory_path() / "g.json").string(),
                                                     NodeRegistry::global()));
        int r = g.findResource("scene.scene");
        EXPECT_GE(r, 0);
        if (r < 0) return {};
        auto object = std::dynamic_pointer_cast<SceneObject>(g.resources[r].object);
        EXPECT_NE(object, nullptr);
        return object ? object->scene().probes : std::vector<scene::ReflectionProbe>{};
    }
    static std::string errorOf(const json& doc) {
        try {
            compileGraph(validateGraph(doc, "g.json", NodeRegistry::global()));
        } catch (const UserError& e) {
            return e.what();
        }
        ADD_FAILURE() << "expected a UserError";
        return {};
    }

    fs::path mDir;
};

TEST_F(ProbesParam, MergeOverridesByNameAndAddsTheRest) {
    scene::MuseumOptions options;
    options.textureSize = 16;
    const std::vector<scene::ReflectionProbe> own = scene::buildMuseum(options).probes;
    ASSERT_GT(own.size(), 4u);
    const std::string replaced = own[3].name;
    std::string file = writeProbes(R"({"probes": [
        {"name": ")" + replaced + R"(", "position": [0, 1.5, 0], "halfExtents": [3, 3, 3], "fade": 0.75},
        {"name": "extra", "shape": "sphere", "position": [0, 1, 12], "radius": 2.5, "priority": 3}]})");
    std::vector<scene::ReflectionProbe> p = probesOf(graph("scene.museum", {{"texture_size", 16}, {"probes", file}}));
    ASSERT_EQ(p.size(), own.size() + 1);
    EXPECT_EQ(p[3].name, replaced);
    EXPECT_EQ(p[3].halfExtents, glm::vec3(3.0f));
    EXPECT_EQ(p[3].fade, 0.75f);
    EXPECT_EQ(p[2].center, own[2].center) << "the others are untouched";
    EXPECT_EQ(p.back().name, "extra");
    EXPECT_EQ(p.back().shape, scene::ProbeShape::Sphere);
    EXPECT_EQ(p.back().priority, 3);
    // Without the param the museum keeps its own.
    EXPECT_EQ(probesOf(graph("scene.museum", {{"texture_size", 16}})).size(), own.size());
}

TEST_F(ProbesParam, ReplaceUsesTheFileOnlyOnMuseumAndGltf) {
    std::string none = writeProbes(R"({"probes": []})");
    EXPECT_TRUE(probesOf(graph("scene.museum", {{"texture_size", 16}, {"probes", none}, {"probes_mode", "replace"}}))
                    .empty());
    std::string one = writeProbes(R"({"probes": [{"name": "only", "position": [0, 0, 0], "halfExtents": [1, 1, 1]}]})");
    const std::string quad = std::string(VITRINE_SOURCE_DIR) + "/tests/data/gltf/quad.gltf";
    std::vector<scene::ReflectionProbe> p =
        probesOf(graph("scene.gltf", {{"path", quad}, {"probes", one}, {"probes_mode", "replace"}}));
    ASSERT_EQ(p.size(), 1u);
    EXPECT_EQ(p[0].name, "only");
}

TEST_F(ProbesParam, ErrorsNameTheParamTheFileAndThePointer) {
    std::string bad = writeProbes(R"({"probes": [{"position": [0, 1, 0], "halfExtents": [1, 1, 1], "fade": -1}]})");
    std::string message = errorOf(graph("scene.museum", {{"texture_size", 16}, {"probes", bad}}));
    for (const std::string& part : {std::string("g.json: /nodes/scene/params/probes: "), bad + ": /probes/0/fade: ",
                                    std::string("expected a number >= 0 (metres), got -1")})
        EXPECT_NE(message.find(part), std::string::npos) << part << " not in: " << message;
    const std::string missing = (mDir / "nope.json").string();
    message = errorOf(graph("scene.museum", {{"texture_size", 16}, {"probes", missing}}));
    for (const std::string& part : {std::string("/nodes/scene/params/probes: "), missing, std::string("cannot open")})
        EXPECT_NE(message.find(part), std::string::npos) << part << " not in: " << message;
    message = errorOf(graph("scene.museum", {{"texture_size", 16}, {"probes", bad}, {"probes_mode", "add"}}));
    EXPECT_NE(message.find("/nodes/scene/params/probes_mode"), std::string::npos) << message;
}

} // namespace
} // namespace vitrine::test
