// Reflection probes as scene content: the VITRINE_reflection_probes glTF extension (export → load gives back the
// same probes, bad input names its element), probe files (JSON pointers in errors, merge and replace), the
// influence-volume geometry against hand-computed cases, and the content hash.

#include "core/scene/gltf.hpp"
#include "core/scene/probes.hpp"

#include "test_util.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include <glm/gtc/quaternion.hpp>

namespace vitrine::scene {
namespace {

using test::expectUserError;
using test::Json;

// Two probes whose floats have no short decimal form, a rotated box and a sphere.
std::vector<ReflectionProbe> oddProbes() {
    ReflectionProbe box;
    box.name = "rotated box";
    box.position = {0.1f, 1.0f / 3.0f, -2.7182817f};
    box.center = {0.3f, 0.5f, -2.5f};
    box.halfExtents = {1.1f, 0.7f, 2.0f / 3.0f};
    box.rotation = glm::angleAxis(0.7f, glm::normalize(glm::vec3(0.2f, 1.0f, -0.1f)));
    box.fade = 0.35f;
    box.priority = 2;
    box.projectionCenter = {0.4f, 0.6f, -2.4f};
    box.projectionHalfExtents = {3.3f, 2.1f, 2.0f / 7.0f + 2.5f};
    ReflectionProbe sphere;
    sphere.name = "sphere";
    sphere.shape = ProbeShape::Sphere;
    sphere.position = {5.0f, 1.5f, 1e-7f};
    sphere.center = {5.2f, 1.2f, 0.1f};
    sphere.halfExtents = glm::vec3(1.7f);
    sphere.fade = 0.0f;
    sphere.priority = -3;
    return {box, sphere};
}

void expectSameProbes(const std::vector<ReflectionProbe>& a, const std::vector<ReflectionProbe>& b) {
    ASSERT_EQ(a.size(), b.size());
    for (size_t i = 0; i < a.size(); ++i) {
        SCOPED_TRACE("probe " + std::to_string(i));
        EXPECT_EQ(a[i].name, b[i].name);
        EXPECT_EQ(a[i].position, b[i].position);
        EXPECT_EQ(a[i].shape, b[i].shape);
        EXPECT_EQ(a[i].center, b[i].center);
        EXPECT_EQ(a[i].halfExtents, b[i].halfExtents);
        EXPECT_EQ(a[i].rotation, b[i].rotation);
        EXPECT_EQ(a[i].fade, b[i].fade);
        EXPECT_EQ(a[i].priority, b[i].priority);
        EXPECT_EQ(a[i].projectionCenter, b[i].projectionCenter);
        EXPECT_EQ(a[i].projectionHalfExtents, b[i].projectionHalfExtents);
    }
}

// ---------------------------------------------------------------------------------------------
// Influence volumes

TEST(ProbeVolume, BoxDepthIsInItsOwnAxes) {
    ReflectionProbe p;
    p.center = {1, 2, 3};
    p.halfExtents = {2, 1, 0.5f};
    p.rotation = glm::angleAxis(glm::radians(90.0f), glm::vec3(0, 1, 0)); // box x → world −z, box z → world x
    // Along world x the box reaches its z half extent (0.5), along world z its x half extent (2).
    EXPECT_NEAR(influenceDepth(p, {1, 2, 3}), 0.5f, 1e-6f);
    EXPECT_NEAR(influenceDepth(p, {1.4f, 2, 3}), 0.1f, 1e-6f);
    EXPECT_NEAR(influenceDepth(p, {1.7f, 2, 3}), -0.2f, 1e-6f);
    EXPECT_NEAR(influenceDepth(p, {1, 2, 4.6f}), 0.4f, 1e-6f); // nearest face: 0.4 to the end, 0.5 to the side
    EXPECT_NEAR(influenceDepth(p, {1, 2.9f, 3}), 0.1f, 1e-6f);
    EXPECT_TRUE(insideInfluence(p, {1, 2, 4.9f}));
    EXPECT_FALSE(insideInfluence(p, {1, 2, 5.1f}));
    EXPECT_TRUE(insideInfluence(p, {1, 2, 5.1f}, 0.11f));
}

TEST(ProbeVolume, RotationTakesTheBoxToTheWorld) {
    // Rx(90°) then Ry(90°): box x → world −z, box y → world x, box z → world −y. A world x offset is measured
    // against the box's y half extent (1), not its z one (0.5) as the inverse rotation would have it.
    ReflectionProbe p;
    p.halfExtents = {2, 1, 0.5f};
    p.rotation = glm::angleAxis(glm::radians(90.0f), glm::vec3(0, 1, 0)) *
                 glm::angleAxis(glm::radians(90.0f), glm::vec3(1, 0, 0));
    EXPECT_NEAR(influenceDepth(p, {0.7f, 0, 0}), 0.3f, 1e-5f);
    EXPECT_NEAR(influenceDepth(p, {0, 0.4f, 0}), 0.1f, 1e-5f);
    EXPECT_NEAR(influenceDepth(p, {0, 0, 1.9f}), 0.1f, 1e-5f);
}

TEST(ProbeVolume, SphereDepthAndFadeWeight) {
    ReflectionProbe p;
    p.shape = ProbeShape::Sphere;
    p.center = {0, 1, 0};
    p.halfExtents = glm::vec3(2.0f);
    p.fade = 0.5f;
    EXPECT_NEAR(influenceDepth(p, {0, 1, 0}), 2.0f, 1e-6f);
    EXPECT_NEAR(influenceDepth(p, {1.2f, 1.0f, 1.6f}), 0.0f, 1e-6f); // |(1.2, 1.6)| = 2
    EXPECT_NEAR(fadeWeight(p, {0, 1, 1.9f}), 0.2f, 1e-5f);            // 0.1 m inside of a 0.5 m fade
    EXPECT_EQ(fadeWeight(p, {0, 1, 1.0f}), 1.0f);
    EXPECT_EQ(fadeWeight(p, {0, 1, 2.5f}), 0.0f);
    p.fade = 0.0f; // a step
    EXPECT_EQ(fadeWeight(p, {0, 1, 1.99f}), 1.0f);
    EXPECT_EQ(fadeWeight(p, {0, 1, 2.01f}), 0.0f);
}

// ---------------------------------------------------------------------------------------------
// glTF

TEST(ProbeGltf, ExportThenLoadGivesTheSameProbes) {
    Scene scene = loadGltf(test::dataDir() / "quad.gltf");
    ASSERT_TRUE(scene.probes.empty());
    uint64_t without = scene.contentHash();
    scene.probes = oddProbes();
    scene.validate();
    EXPECT_NE(scene.contentHash(), without);
    auto file = test::scratchDir() / "probes.glb";
    exportGlb(scene, file);
    Scene back = loadGltf(file);
    expectSameProbes(back.probes, scene.probes);
    EXPECT_EQ(back.contentHash(), scene.contentHash());
}

TEST(ProbeGltf, ReadsTheDocumentedExample) {
    // The example of VITRINE_reflection_probes.md, typed in by hand: what a user would write.
    Json doc = test::readJson(test::dataDir() / "quad.gltf");
    doc["extensionsUsed"].push_back("VITRINE_reflection_probes");
    doc["extensionsRequired"] = {"VITRINE_reflection_probes"};
    doc["scenes"][0]["extensions"]["VITRINE_reflection_probes"] = Json::parse(R"({"probes": [
        {"name": "hall_nave_3", "position": [-2.0, 1.7, -0.5], "shape": "box", "center": [-2.0, 4.65, 0.0],
         "halfExtents": [2.5, 5.05, 5.0], "rotation": [0.0, 0.0, 0.0, 1.0], "fade": 1.0, "priority": 0},
        {"name": "sphere_alcove", "position": [3.0, 1.5, 2.0], "shape": "sphere", "center": [3.0, 1.2, 2.0],
         "radius": 1.5, "fade": 0.4, "priority": 1},
        {"position": [1, 2, 3], "halfExtents": [1, 1, 1]}]})");
    auto file = test::scratchDir() / "example.gltf";
    test::writeText(file, doc.dump(2));
    Scene s = loadGltf(file);
    ASSERT_EQ(s.probes.size(), 3u);
    EXPECT_EQ(s.probes[0].name, "hall_nave_3");
    EXPECT_EQ(s.probes[0].halfExtents, glm::vec3(2.5f, 5.05f, 5.0f));
    EXPECT_EQ(s.probes[0].center, glm::vec3(-2.0f, 4.65f, 0.0f));
    EXPECT_EQ(s.probes[0].fade, 1.0f);
    EXPECT_EQ(s.probes[1].shape, ProbeShape::Sphere);
    EXPECT_EQ(s.probes[1].halfExtents, glm::vec3(1.5f));
    EXPECT_EQ(s.probes[1].position, glm::vec3(3.0f, 1.5f, 2.0f));
    EXPECT_EQ(s.probes[1].fade, 0.4f);
    EXPECT_EQ(s.probes[1].priority, 1);
    // Defaults: a box centred on its capture point, unrotated, fade 0.5, priority 0.
    EXPECT_EQ(s.probes[2].name, "");
    EXPECT_EQ(s.probes[2].shape, ProbeShape::Box);
    EXPECT_EQ(s.probes[2].center, glm::vec3(1, 2, 3));
    EXPECT_EQ(s.probes[2].rotation, glm::quat(1, 0, 0, 0));
    EXPECT_EQ(s.probes[2].fade, 0.5f);
    EXPECT_EQ(s.probes[2].priority, 0);
}

TEST(ProbeGltf, ExporterListsTheExtensionOnlyWithProbes) {
    Scene scene = loadGltf(test::dataDir() / "quad.gltf");
    auto dir = test::scratchDir();
    auto used = [](const std::filesystem::path& file) {
        std::vector<uint8_t> bytes = test::readBytes(file);
        uint32_t length = bytes[12] | bytes[13] << 8 | bytes[14] << 16 | bytes[15] << 24;
        Json doc = Json::parse(std::string(bytes.begin() + 20, bytes.begin() + 20 + length));
        bool listed = false;
        for (const Json& e : doc["extensionsUsed"])
            listed = listed || e == "VITRINE_reflection_probes";
        EXPECT_EQ(listed, doc["scenes"][0].contains("extensions")) << "listed iff written";
        return listed;
    };
    exportGlb(scene, dir / "none.glb");
    EXPECT_FALSE(used(dir / "none.glb"));
    scene.probes = oddProbes();
    exportGlb(scene, dir / "some.glb");
    EXPECT_TRUE(used(dir / "some.glb"));
}

class ProbeGltfErrors : public ::testing::Test {
protected:
    // quad.gltf with `ext` as its scene's VITRINE_reflection_probes; the error of loading it.
    void expectError(const Json& ext, const std::vector<std::string>& parts) {
        Json doc = test::readJson(test::dataDir() / "quad.gltf");
        doc["scenes"][0]["extensions"]["VITRINE_reflection_probes"] = ext;
        auto file = test::scratchDir() / "bad_probes.gltf";
        test::writeText(file, doc.dump());
        std::vector<std::string> all = parts;
        all.push_back("bad_probes.gltf: ");
        expectUserError([&] { loadGltf(file); }, all);
    }
    // One probe, `good` with `edit` merged into it (null values remove keys).
    void expectProbeError(const Json& edit, const std::string& key, const std::string& what) {
        Json probe = {{"name", "p"}, {"position", {0, 1, 0}}, {"halfExtents", {1, 2, 1}}, {"fade", 0.5}};
        probe.merge_patch(edit);
        expectError({{"probes", {probe}}},
                    {"scenes[0].extensions.VITRINE_reflection_probes.probes[0]" + key + ": ", what});
    }
};

TEST_F(ProbeGltfErrors, TheExtensionObject) {
    expectError({{"probes", 3}}, {"scenes[0].extensions.VITRINE_reflection_probes.probes: ", "expected an array"});
    expectError(Json::object(), {"VITRINE_reflection_probes.probes: ", "missing"});
    expectError({{"probes", Json::array()}, {"probe", 1}},
                {"VITRINE_reflection_probes.probe: ", "unknown key; expected probes"});
    expectError({{"probes", {1}}}, {"VITRINE_reflection_probes.probes[0]: ", "expected a JSON object"});
}

TEST_F(ProbeGltfErrors, EachKeyNamesItsPath) {
    expectProbeError({{"position", nullptr}}, ".position", "missing; expected an array of 3 numbers");
    expectProbeError({{"position", {0, 1}}}, ".position", "expected an array of 3 numbers, got [0,1]");
    expectProbeError({{"center", {0, "1", 0}}}, ".center", "expected an array of 3 finite numbers");
    expectProbeError({{"fade", -0.1}}, ".fade", "expected a number >= 0 (metres), got -0.1");
    expectProbeError({{"fade", "wide"}}, ".fade", "expected a number >= 0");
    expectProbeError({{"halfExtents", nullptr}}, ".halfExtents", "missing");
    expectProbeError({{"halfExtents", {1, 0, 1}}}, ".halfExtents", "expected three numbers > 0, got [1,0,1]");
    expectProbeError({{"radius", 1}}, ".radius", "a box takes halfExtents");
    expectProbeError({{"shape", "cube"}}, ".shape", "'cube'; expected box or sphere");
    expectProbeError({{"shape", "sphere"}}, ".halfExtents", "a sphere takes radius");
    expectProbeError({{"shape", "sphere"}, {"halfExtents", nullptr}}, ".radius", "missing; expected the sphere's radius");
    expectProbeError({{"shape", "sphere"}, {"halfExtents", nullptr}, {"radius", 0}}, ".radius",
                     "expected a number > 0 (metres), got 0");
    expectProbeError({{"shape", "sphere"}, {"halfExtents", nullptr}, {"radius", 2}, {"rotation", {0, 0, 0, 1}}},
                     ".rotation", "a sphere has no rotation");
    expectProbeError({{"rotation", {0, 0, 0, 2}}}, ".rotation", "expected a unit quaternion [x, y, z, w]");
    expectProbeError({{"priority", 9}}, ".priority", "expected an integer in [-8, 8], got 9");
    expectProbeError({{"priority", 1.5}}, ".priority", "expected an integer in [-8, 8], got 1.5");
    expectProbeError({{"name", 7}}, ".name", "expected a string");
    expectProbeError({{"fadeDistance", 1}}, ".fadeDistance", "unknown key");
    expectProbeError({{"projectionHalfExtents", {1, 0, 1}}}, ".projectionHalfExtents",
                     "expected three numbers > 0, got [1,0,1]");
    expectProbeError({{"projectionHalfExtents", {4, 4}}}, ".projectionHalfExtents", "expected an array of 3 numbers");
    expectProbeError({{"projectionCenter", {0, 1, 0}}}, ".projectionCenter",
                     "given without projectionHalfExtents; expected both");
    expectProbeError({{"projectionHalfExtents", {4, 4, 4}}, {"projectionCenter", {0, "1", 0}}}, ".projectionCenter",
                     "expected an array of 3 finite numbers");
    expectProbeError(
        {{"shape", "sphere"}, {"halfExtents", nullptr}, {"radius", 2}, {"projectionHalfExtents", {4, 4, 4}}},
        ".projectionHalfExtents", "a sphere's parallax proxy is the sphere");
}

TEST_F(ProbeGltfErrors, CapturePointOutsideItsProjectionBox) {
    // Inside the influence volume (half height 2 around y = 1), 0.25 m above the projection box (half height 1.25
    // around y = 0.5... its top at 1.75, the capture point at 2).
    expectProbeError({{"center", {0, 1, 0}},
                      {"position", {0, 2, 0}},
                      {"projectionCenter", {0, 0.5, 0}},
                      {"projectionHalfExtents", {5, 1.25, 5}}},
                     ".position", "lies outside the projection box (0.25");
    // The projection box takes the influence volume's centre when it has none of its own.
    Json doc = test::readJson(test::dataDir() / "quad.gltf");
    doc["scenes"][0]["extensions"]["VITRINE_reflection_probes"] = {{"probes",
                                                                    {{{"position", {0, 1, 0}},
                                                                      {"center", {0, 1, 0}},
                                                                      {"halfExtents", {1, 2, 1}},
                                                                      {"projectionHalfExtents", {6, 3, 6}}}}}};
    auto file = test::scratchDir() / "projection.gltf";
    test::writeText(file, doc.dump());
    auto probes = loadGltf(file).probes;
    ASSERT_EQ(probes.size(), 1u);
    EXPECT_EQ(probes[0].projectionCenter, glm::vec3(0, 1, 0));
    EXPECT_EQ(probes[0].projectionHalfExtents, glm::vec3(6, 3, 6));
    // Scene::validate() holds a probe built in code to the same rules (an internal error: code built it).
    Scene scene = loadGltf(file);
    auto invalid = [&](const std::string& what) {
        try {
            scene.validate();
            ADD_FAILURE() << "validate() accepted it; expected: " << what;
        } catch (const std::exception& e) {
            EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
        }
    };
    scene.probes[0].projectionCenter = {0, 10, 0};
    invalid("capture point lies outside its projection box");
    scene.probes[0].shape = ProbeShape::Sphere;
    invalid("has a projection box but is a sphere");
}

TEST_F(ProbeGltfErrors, CapturePointOutsideItsVolume) {
    // Box of half height 2 around y = 1: y = 3.5 is 0.5 m above its top.
    expectProbeError({{"center", {0, 1, 0}}, {"position", {0, 3.5, 0}}}, ".position",
                     "lies outside the influence volume (0.5");
    // The same test in the box's own axes: rotated 90° about z, its long axis (y, half 2) lies along world x.
    Json doc = test::readJson(test::dataDir() / "quad.gltf");
    doc["scenes"][0]["extensions"]["VITRINE_reflection_probes"] = {
        {"probes",
         {{{"position", {1.5, 0, 0}}, {"center", {0, 0, 0}}, {"halfExtents", {1, 2, 1}},
           {"rotation", {0, 0, 0.70710678, 0.70710678}}}}}};
    auto file = test::scratchDir() / "rotated.gltf";
    test::writeText(file, doc.dump());
    EXPECT_EQ(loadGltf(file).probes.size(), 1u) << "inside along the rotated long axis";
}

TEST_F(ProbeGltfErrors, DuplicateNames) {
    Json a = {{"name", "hall"}, {"position", {0, 1, 0}}, {"halfExtents", {1, 2, 1}}};
    Json b = {{"position", {0, 1, 0}}, {"halfExtents", {1, 2, 1}}};
    expectError({{"probes", {a, b, b, a}}},
                {"probes[3].name: ", "'hall' is also the name of scenes[0].extensions.VITRINE_reflection_probes.probes[0]"});
}

// ---------------------------------------------------------------------------------------------
// Probe files and how they combine with a scene's probes

class ProbeFile : public ::testing::Test {
protected:
    std::filesystem::path write(const std::string& text) {
        auto file = test::scratchDir() / "probes.json";
        test::writeText(file, text);
        return file;
    }
    void expectError(const std::string& text, const std::vector<std::string>& parts) {
        auto file = write(text);
        std::vector<std::string> all = parts;
        all.push_back(file.string() + ":");
        expectUserError([&] { readProbeFile(file); }, all);
    }
};

TEST_F(ProbeFile, ReadsTheSameProbesAsTheExtension) {
    auto file = write(R"({"probes": [{"name": "a", "position": [0, 1, 0], "halfExtents": [1, 2, 3], "fade": 0.25},
                                     {"shape": "sphere", "position": [4, 1, 0], "radius": 2, "priority": 3}]})");
    std::vector<ReflectionProbe> p = readProbeFile(file);
    ASSERT_EQ(p.size(), 2u);
    EXPECT_EQ(p[0].name, "a");
    EXPECT_EQ(p[0].halfExtents, glm::vec3(1, 2, 3));
    EXPECT_EQ(p[0].fade, 0.25f);
    EXPECT_EQ(p[1].shape, ProbeShape::Sphere);
    EXPECT_EQ(p[1].halfExtents, glm::vec3(2.0f));
    EXPECT_EQ(p[1].priority, 3);
    EXPECT_TRUE(readProbeFile(write(R"({"probes": []})")).empty());
}

TEST_F(ProbeFile, ErrorsNameTheFileAndTheJsonPointer) {
    expectUserError([] { readProbeFile("/nonexistent-dir/probes.json"); },
                    {"/nonexistent-dir/probes.json", "cannot open"});
    expectError("{\"probes\": [\n  {\"position\": [0, 1, 0],}]}", {":2:", "JSON syntax error"});
    expectError("[]", {": /: ", "expected a JSON object {\"probes\": [...]}"});
    expectError(R"({"probe": []})", {": /probe: ", "unknown key; expected probes"});
    expectError(R"({})", {": /probes: ", "missing; expected an array of probes"});
    expectError(R"({"probes": {}})", {": /probes: ", "expected an array of probes"});
    expectError(R"({"probes": [{"position": [0, 1, 0], "halfExtents": [1, 1, 1]},
                               {"shape": "sphere", "position": [0, 1, 0], "radius": -2}]})",
                {": /probes/1/radius: ", "expected a number > 0 (metres), got -2"});
    expectError(R"({"probes": [{"position": [0, 1, 0], "halfExtents": [1, 1, 1], "a/b": 1}]})",
                {": /probes/0/a~1b: ", "unknown key"});
    expectError(R"({"probes": [{"name": "x", "position": [0, 1, 0], "halfExtents": [1, 1, 1]},
                               {"name": "x", "position": [0, 1, 0], "halfExtents": [1, 1, 1]}]})",
                {": /probes/1/name: ", "'x' is also the name of /probes/0"});
}

TEST(ProbeMergeTest, MergeReplacesByNameInPlaceAndAppendsTheRest) {
    std::vector<ReflectionProbe> scene(3), file(3);
    scene[0].name = "a", scene[1].name = "b", scene[2].name = "";
    file[0].name = "b", file[0].fade = 0.9f;
    file[1].name = "new";
    file[2].name = ""; // unnamed probes never replace anything
    std::vector<ReflectionProbe> merged = scene;
    applyProbes(merged, file, ProbeMerge::Merge);
    ASSERT_EQ(merged.size(), 5u);
    EXPECT_EQ(merged[0].name, "a");
    EXPECT_EQ(merged[1].name, "b");
    EXPECT_EQ(merged[1].fade, 0.9f);
    EXPECT_EQ(merged[2].name, "");
    EXPECT_EQ(merged[3].name, "new");
    EXPECT_EQ(merged[4].name, "");

    std::vector<ReflectionProbe> replaced = scene;
    applyProbes(replaced, file, ProbeMerge::Replace);
    ASSERT_EQ(replaced.size(), 3u);
    EXPECT_EQ(replaced[0].fade, 0.9f);
    applyProbes(replaced, {}, ProbeMerge::Replace);
    EXPECT_TRUE(replaced.empty());
}

// ---------------------------------------------------------------------------------------------
// Content hash: every field of a probe is content (the bake cache and ibl.capture key on it)

TEST(ProbeHash, EveryFieldChangesTheContentHash) {
    Scene scene = loadGltf(test::dataDir() / "quad.gltf");
    scene.probes = oddProbes();
    const uint64_t base = scene.contentHash();
    auto changed = [&](auto edit) {
        Scene s = scene;
        edit(s.probes[0]);
        return s.contentHash() != base;
    };
    EXPECT_TRUE(changed([](ReflectionProbe& p) { p.name += "x"; }));
    EXPECT_TRUE(changed([](ReflectionProbe& p) { p.position.y += 0.01f; }));
    EXPECT_TRUE(changed([](ReflectionProbe& p) { p.shape = ProbeShape::Sphere; }));
    EXPECT_TRUE(changed([](ReflectionProbe& p) { p.center.x += 0.01f; }));
    EXPECT_TRUE(changed([](ReflectionProbe& p) { p.halfExtents.z += 0.01f; }));
    EXPECT_TRUE(changed([](ReflectionProbe& p) { p.rotation = glm::quat(1, 0, 0, 0); }));
    EXPECT_TRUE(changed([](ReflectionProbe& p) { p.fade += 0.01f; }));
    EXPECT_TRUE(changed([](ReflectionProbe& p) { p.priority += 1; }));
    EXPECT_TRUE(changed([](ReflectionProbe& p) { p.projectionCenter.x += 0.01f; }));
    EXPECT_TRUE(changed([](ReflectionProbe& p) { p.projectionHalfExtents.y += 0.01f; }));
    EXPECT_TRUE(changed([](ReflectionProbe& p) { p.projectionHalfExtents = glm::vec3(0.0f); }));
    Scene reordered = scene;
    std::swap(reordered.probes[0], reordered.probes[1]);
    EXPECT_NE(reordered.contentHash(), base) << "the order decides the cube-map layers";
}

TEST(ProbeHash, ProbesDoNotChangeTheLightTransportHash) {
    // The lightmap bake is keyed by lightmapHash(), path-traced references by lightTransportHash(): moving or
    // adding a probe must re-bake neither, while any other content (here one vertex) still does.
    Scene scene = loadGltf(test::dataDir() / "quad.gltf");
    const uint64_t without = scene.lightTransportHash(), lightmapWithout = scene.lightmapHash();
    scene.probes = oddProbes();
    EXPECT_EQ(scene.lightTransportHash(), without);
    EXPECT_EQ(scene.lightmapHash(), lightmapWithout);
    scene.probes[0].position.x += 0.5f;
    EXPECT_EQ(scene.lightTransportHash(), without);
    EXPECT_EQ(scene.lightmapHash(), lightmapWithout);
    EXPECT_NE(scene.contentHash(), scene.lightTransportHash());
    scene.vertices[0].position.x += 0.01f;
    EXPECT_NE(scene.lightTransportHash(), without);
    EXPECT_NE(scene.lightmapHash(), lightmapWithout);
}

TEST(ProbeHash, LightmapUvsChangeTheLightmapHashButNotTheLightTransportHash) {
    // Re-packing the lightmap charts re-bakes the lightmap but keeps a converged reference (hours on a CPU) — unless
    // a material samples texture set 1, when uv1 is light transport too.
    Scene scene = loadGltf(test::dataDir() / "quad.gltf"); // its metallic-roughness texture reads TEXCOORD_1
    for (MaterialLayer& l : scene.materials[scene.primitives[0].material].layers)
        for (TextureRef* r : {&l.albedo.texture, &l.normal.texture, &l.shininess.texture, &l.metallic.texture,
                              &l.cavity.texture, &l.mask.texture})
            r->uvSet = 0;
    ASSERT_FALSE(usesUvSet(scene.materials[scene.primitives[0].material], 1));
    const uint64_t transport = scene.lightTransportHash(), lightmap = scene.lightmapHash(),
                   content = scene.contentHash();
    scene.vertices[scene.primitives[0].vertexOffset].uv1.x += 0.25f;
    EXPECT_EQ(scene.lightTransportHash(), transport);
    EXPECT_NE(scene.lightmapHash(), lightmap);
    EXPECT_NE(scene.contentHash(), content);
    const uint64_t movedUv = scene.lightmapHash();
    scene.meshes[0].lightmapChartGap = 0.01f;
    EXPECT_EQ(scene.lightTransportHash(), transport);
    EXPECT_NE(scene.lightmapHash(), movedUv);

    Scene sampled = loadGltf(test::dataDir() / "quad.gltf");
    ASSERT_TRUE(usesUvSet(sampled.materials[sampled.primitives[0].material], 1));
    const uint64_t sampledTransport = sampled.lightTransportHash();
    sampled.vertices[sampled.primitives[0].vertexOffset].uv1.x += 0.25f;
    EXPECT_NE(sampled.lightTransportHash(), sampledTransport);
}

} // namespace
} // namespace vitrine::scene
