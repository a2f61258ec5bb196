#include "core/scene/animation.hpp"

#include <algorithm>
#include <cmath>

namespace vitrine::scene {

glm::quat toQuat(const glm::vec4& xyzw) {
    return glm::quat(xyzw.w, xyzw.x, xyzw.y, xyzw.z);
}

glm::vec4 toVec4(const glm::quat& q) {
    return glm::vec4(q.x, q.y, q.z, q.w);
}

namespace {

glm::vec4 keyValue(const AnimationSampler& s, size_t key) {
    return s.interpolation == Interpolation::CubicSpline ? s.values[key * 3 + 1] : s.values[key];
}

glm::vec4 normalizeRotation(glm::vec4 q) {
    float len = glm::length(q);
    return len > 0.0f ? q / len : glm::vec4(0.0f, 0.0f, 0.0f, 1.0f);
}

} // namespace

glm::vec4 AnimationSampler::sample(float t, AnimationPath path) const {
    if (times.empty()) return path == AnimationPath::Rotation ? glm::vec4(0, 0, 0, 1) : glm::vec4(0.0f);
    bool rotation = path == AnimationPath::Rotation;
    if (t <= times.front()) return keyValue(*this, 0);
    if (t >= times.back()) return keyValue(*this, times.size() - 1);

    // First key strictly after t; the segment is [k, k + 1].
    size_t next = static_cast<size_t>(std::upper_bound(times.begin(), times.end(), t) - times.begin());
    size_t k = next - 1;
    float td = times[next] - times[k];
    if (interpolation == Interpolation::Step || td <= 0.0f) return keyValue(*this, k);
    float s = (t - times[k]) / td;

    if (interpolation == Interpolation::Linear) {
        glm::vec4 a = values[k], b = values[next];
        if (rotation) return toVec4(glm::slerp(toQuat(a), toQuat(b), s));
        return a + (b - a) * s;
    }

    // Cubic Hermite spline as the glTF specification writes it (appendix C).
    float s2 = s * s, s3 = s2 * s;
    glm::vec4 v0 = values[k * 3 + 1], b0 = values[k * 3 + 2];
    glm::vec4 a1 = values[next * 3 + 0], v1 = values[next * 3 + 1];
    glm::vec4 p =
        (2 * s3 - 3 * s2 + 1) * v0 + td * (s3 - 2 * s2 + s) * b0 + (-2 * s3 + 3 * s2) * v1 + td * (s3 - s2) * a1;
    return rotation ? normalizeRotation(p) : p;
}

std::vector<float> AnimationSampler::sampleWeights(float t) const {
    std::vector<float> out(width, 0.0f);
    if (times.empty()) return out;
    bool cubic = interpolation == Interpolation::CubicSpline;
    size_t per = cubic ? 3 * size_t(width) : width; // elements per key
    size_t valueAt = cubic ? width : 0;             // the value's offset inside a key
    auto value = [&](size_t key, size_t i) { return values[key * per + valueAt + i].x; };
    size_t last = times.size() - 1;
    if (t <= times.front() || t >= times.back()) {
        size_t key = t <= times.front() ? 0 : last;
        for (size_t i = 0; i < width; ++i)
            out[i] = value(key, i);
        return out;
    }
    size_t next = static_cast<size_t>(std::upper_bound(times.begin(), times.end(), t) - times.begin());
    size_t k = next - 1;
    float td = times[next] - times[k];
    float s = td > 0.0f ? (t - times[k]) / td : 0.0f;
    for (size_t i = 0; i < width; ++i) {
        float v0 = value(k, i), v1 = value(next, i);
        if (interpolation == Interpolation::Step || td <= 0.0f) {
            out[i] = v0;
        } else if (interpolation == Interpolation::Linear) {
            out[i] = v0 + (v1 - v0) * s;
        } else {
            float b0 = values[k * per + 2 * width + i].x, a1 = values[next * per + i].x;
            float s2 = s * s, s3 = s2 * s;
            out[i] = (2 * s3 - 3 * s2 + 1) * v0 + td * (s3 - 2 * s2 + s) * b0 + (-2 * s3 + 3 * s2) * v1 +
                     td * (s3 - s2) * a1;
        }
    }
    return out;
}

float Animation::startTime() const {
    float start = 0.0f;
    bool first = true;
    for (const AnimationSampler& s : samplers) {
        if (s.times.empty()) continue;
        start = first ? s.times.front() : std::min(start, s.times.front());
        first = false;
    }
    return start;
}

float Animation::endTime() const {
    float end = 0.0f;
    for (const AnimationSampler& s : samplers) {
        if (!s.times.empty()) end = std::max(end, s.times.back());
    }
    return end;
}

float Animation::localTime(double t) const {
    if (!loop) return static_cast<float>(t);
    double start = startTime(), length = endTime() - start;
    if (length <= 0.0) return static_cast<float>(start);
    double wrapped = std::fmod(t - start, length);
    if (wrapped < 0.0) wrapped += length;
    return static_cast<float>(start + wrapped);
}

} // namespace vitrine::scene
