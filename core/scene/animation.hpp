#pragma once

// Node animations with glTF semantics: a channel drives one node's translation, rotation or scale from a
// sampler of keyframes. Sampled on the CPU by Scene::evaluate() once per frame.

#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

namespace vitrine::scene {

enum class Interpolation : uint8_t { Step, Linear, CubicSpline };
enum class AnimationPath : uint8_t { Translation, Rotation, Scale, Weights };

struct AnimationSampler {
    Interpolation interpolation = Interpolation::Linear;
    std::vector<float> times; // seconds, non-decreasing
    // Translation/scale: xyz (w unused, 0). Rotation: a quaternion as x, y, z, w.
    // CubicSpline: three per key, in-tangent, value, out-tangent (glTF order); tangents are per second.
    // Weights (morph targets): `width` elements per key (per in-tangent, value and out-tangent when cubic), the
    // weight in x, as glTF lays them out.
    std::vector<glm::vec4> values;
    uint32_t width = 1;

    // The value at time t (clamped to the keys). Rotations are slerped (linear) or normalised (cubic).
    glm::vec4 sample(float t, AnimationPath path) const;
    // The `width` morph weights at time t (clamped to the keys), each interpolated like a scalar.
    std::vector<float> sampleWeights(float t) const;
};

struct AnimationChannel {
    uint32_t node = 0;
    AnimationPath path = AnimationPath::Translation;
    uint32_t sampler = 0;
};

struct Animation {
    std::string name;
    std::vector<AnimationSampler> samplers;
    std::vector<AnimationChannel> channels;
    // Wrap time into [start, end) instead of clamping: walk cycles, patrols.
    bool loop = false;

    float startTime() const;
    float endTime() const;
    // The time at which samplers are read for scene time t (wrapped when loop, else t itself).
    float localTime(double t) const;
};

glm::quat toQuat(const glm::vec4& xyzw);
glm::vec4 toVec4(const glm::quat& q);

} // namespace vitrine::scene
