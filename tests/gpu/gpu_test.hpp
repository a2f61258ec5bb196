#pragma once

#include "core/gpu/context.hpp"
#include "core/image/image.hpp"

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <functional>
#include <map>
#include <string>

namespace vitrine::scene {
struct Scene;
}

namespace vitrine::test {

// One Vulkan context (validation on) for the whole GPU test binary; every test fails if the
// validation layer reported anything while it ran.
Context& gpu();

class GpuTest : public ::testing::Test {
protected:
    void SetUp() override;
    void TearDown() override;

private:
    size_t mMessagesBefore = 0;
};

// Validates, compiles and runs a graph given as JSON; returns every graph output of the last frame. stop: the run's
// RunOptions::stop (what Ctrl-C sets in `vitrine run`).
std::map<std::string, Image> runGraph(const nlohmann::json& graph, std::function<bool()> stop = {});
std::map<std::string, Image> runGraphFile(const std::string& path, const std::vector<std::string>& sets = {});

// Finalizes and validates a scene built in a test and writes it as <name>.glb into a scratch folder of
// this test process (removed when the program ends), for scene.gltf.
std::filesystem::path writeSceneGlb(scene::Scene& s, const std::string& name);
// This process's scratch directory (removed when the tests end); writeSceneGlb() writes there.
std::filesystem::path scratchDir();

// A camera orientation looking from eye at target, +Y up (cameras look down their local -Z).
glm::quat lookRotation(glm::vec3 eye, glm::vec3 target);

double rmse(const Image& a, const Image& b); // over RGB
double maxAbsDiff(const Image& a, const Image& b); // over RGBA; infinity where either has a NaN, or the sizes differ

} // namespace vitrine::test
