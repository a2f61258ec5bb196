// Keyframe sampling, looping, camera paths and projection conventions.

#include "core/scene/scene.hpp"

#include "test_util.hpp"

#include <cmath>

#include <glm/gtc/matrix_transform.hpp>
#include <gtest/gtest.h>

namespace vitrine::scene {
namespace {

AnimationSampler twoKeys(Interpolation mode) {
    AnimationSampler s;
    s.interpolation = mode;
    s.times = {0.0f, 2.0f};
    if (mode == Interpolation::CubicSpline) {
        s.values = {glm::vec4(0), {1, 2, 3, 0}, glm::vec4(0), glm::vec4(0), {3, 2, -1, 0}, glm::vec4(0)};
    } else {
        s.values = {{1, 2, 3, 0}, {3, 2, -1, 0}};
    }
    return s;
}

TEST(Animation, LinearStepAndCubicSampling) {
    EXPECT_EQ(twoKeys(Interpolation::Linear).sample(1.0f, AnimationPath::Translation), glm::vec4(2, 2, 1, 0));
    EXPECT_EQ(twoKeys(Interpolation::Linear).sample(0.5f, AnimationPath::Translation), glm::vec4(1.5f, 2, 2, 0));
    EXPECT_EQ(twoKeys(Interpolation::Linear).sample(-1.0f, AnimationPath::Translation), glm::vec4(1, 2, 3, 0));
    EXPECT_EQ(twoKeys(Interpolation::Linear).sample(9.0f, AnimationPath::Translation), glm::vec4(3, 2, -1, 0));
    EXPECT_EQ(twoKeys(Interpolation::Step).sample(1.99f, AnimationPath::Translation), glm::vec4(1, 2, 3, 0));
    // Hermite with zero tangents is symmetric: the midpoint at mid-time, eased elsewhere.
    glm::vec4 mid = twoKeys(Interpolation::CubicSpline).sample(1.0f, AnimationPath::Translation);
    EXPECT_NEAR(mid.x, 2.0f, 1e-6f);
    EXPECT_NEAR(mid.z, 1.0f, 1e-6f);
    glm::vec4 early = twoKeys(Interpolation::CubicSpline).sample(0.5f, AnimationPath::Translation);
    EXPECT_NEAR(early.x, 1.0f + 2.0f * (3 * 0.0625f - 2 * 0.015625f), 1e-6f); // h01(0.25) = 3s² − 2s³
}

TEST(Animation, RotationSlerps) {
    AnimationSampler s;
    s.times = {0.0f, 1.0f};
    s.values = {toVec4(glm::quat(1, 0, 0, 0)), toVec4(glm::angleAxis(1.5707963f, glm::vec3(0, 1, 0)))};
    glm::quat half = toQuat(s.sample(0.5f, AnimationPath::Rotation));
    glm::quat expected = glm::angleAxis(0.78539816f, glm::vec3(0, 1, 0));
    EXPECT_NEAR(std::abs(glm::dot(half, expected)), 1.0f, 1e-6f);
}

TEST(Animation, EvaluateLoopsAndComposesTheHierarchy) {
    Scene scene;
    scene.nodes.resize(2);
    scene.nodes[0].children = {1};
    scene.nodes[0].local.translation = glm::vec3(10, 0, 0);
    Animation a;
    a.loop = true;
    a.samplers.push_back(twoKeys(Interpolation::Linear));
    a.channels.push_back({1, AnimationPath::Translation, 0});
    scene.animations.push_back(a);
    scene.finalize();
    EXPECT_FALSE(scene.nodes[0].dynamic);
    EXPECT_TRUE(scene.nodes[1].dynamic);
    EXPECT_EQ(glm::vec3(scene.evaluate(1.0).nodeWorld[1][3]), glm::vec3(12, 2, 1));
    EXPECT_EQ(glm::vec3(scene.evaluate(3.0).nodeWorld[1][3]), glm::vec3(12, 2, 1)); // 3 s wraps to 1 s
    EXPECT_EQ(glm::vec3(scene.evaluate(-1.0).nodeWorld[1][3]), glm::vec3(12, 2, 1));
}

TEST(CameraPath, PassesThroughItsKeysAndInterpolates) {
    Scene scene;
    scene.name = "paths";
    scene.cameras.push_back(Camera());
    CameraPath path;
    path.name = "walk";
    path.keys = {{0.0f, {0, 1, 0}, glm::quat(1, 0, 0, 0), 0.8f},
                 {2.0f, {4, 1, 0}, glm::angleAxis(0.5f, glm::vec3(0, 1, 0)), 0.6f},
                 {4.0f, {4, 1, -4}, glm::angleAxis(1.0f, glm::vec3(0, 1, 0)), 0.6f}};
    scene.cameraPaths.push_back(path);
    for (const CameraKey& k : path.keys) {
        CameraState s = scene.cameraAt("walk", k.time);
        EXPECT_NEAR(glm::distance(s.position, k.position), 0.0f, 1e-5f);
        EXPECT_NEAR(std::abs(glm::dot(s.orientation, k.orientation)), 1.0f, 1e-6f);
    }
    CameraState mid = scene.cameraAt("walk", 1.0);
    EXPECT_NEAR(mid.lens.yfov, 0.7f, 1e-6f);
    // Hermite at s = 0.5 with tangents (2,0,0) and ((4,1,-4) - (0,1,0)) / 4: x = 2 + 0.5 - 0.25, z = 0.25.
    EXPECT_NEAR(mid.position.x, 2.25f, 1e-6f);
    EXPECT_NEAR(mid.position.z, 0.25f, 1e-6f);
    // The view matrix takes the camera position to the origin and looks down -Z.
    glm::vec4 origin = mid.view * glm::vec4(mid.position, 1.0f);
    EXPECT_NEAR(glm::length(glm::vec3(origin)), 0.0f, 1e-5f);

    scene.cameraPaths[0].smooth = false;
    EXPECT_NEAR(scene.cameraAt("walk", 1.0).position.x, 2.0f, 1e-6f);
    test::expectUserError([&] { scene.cameraAt("run", 0.0); }, {"'run'", "not found", "walk"});
}

TEST(CameraPath, ProjectionFollowsVulkanConventions) {
    CameraState s;
    s.lens.yfov = 1.0f;
    s.lens.znear = 0.5f;
    s.lens.zfar = 50.0f;
    auto ndc = [&](glm::vec3 p, bool reverse) {
        glm::vec4 c = s.projection(2.0f, reverse) * glm::vec4(p, 1.0f);
        return glm::vec3(c) / c.w;
    };
    EXPECT_NEAR(ndc({0, 0, -0.5f}, false).z, 0.0f, 1e-6f);
    EXPECT_NEAR(ndc({0, 0, -50.0f}, false).z, 1.0f, 1e-5f);
    EXPECT_NEAR(ndc({0, 0, -0.5f}, true).z, 1.0f, 1e-6f);
    EXPECT_NEAR(ndc({0, 0, -50.0f}, true).z, 0.0f, 1e-5f);
    float top = 10.0f * std::tan(0.5f);
    EXPECT_NEAR(ndc({0, top, -10.0f}, false).y, -1.0f, 1e-5f); // +y up in view space is -y in Vulkan NDC
    EXPECT_NEAR(ndc({2.0f * top, 0, -10.0f}, false).x, 1.0f, 1e-5f);
    s.lens.zfar = 0.0f; // infinite
    EXPECT_NEAR(ndc({0, 0, -1e6f}, false).z, 1.0f, 1e-5f);
    EXPECT_NEAR(s.lens.focalLengthMm(), 12.0f / std::tan(0.5f), 1e-4f);
}

} // namespace
} // namespace vitrine::scene
