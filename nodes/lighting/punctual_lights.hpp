#pragma once
// The scene's KHR_lights_punctual point and spot lights as the lighting nodes' uniforms (shaders/lighting/lights.h),
// posed every frame: shared by lighting.deferred and forward.transparent.
#include "core/base/log.hpp"
#include "core/scene/gpu_scene.hpp"
#include "shaders/lighting/lights.h"

#include <algorithm>
#include <cmath>
#include <string>

namespace vitrine {

// The lights at the scene object's current pose. A scene with more than VITRINE_MAX_PUNCTUAL_LIGHTS keeps the
// first ones (warned once, at setup, by warnLightCount()).
inline gpu_types::PunctualLights packPunctualLights(const SceneObject& object) {
    const scene::Scene& s = object.scene();
    gpu_types::PunctualLights out{};
    uint32_t n = std::min<uint32_t>(static_cast<uint32_t>(s.lights.size()), VITRINE_MAX_PUNCTUAL_LIGHTS);
    out.count.x = n;
    for (uint32_t i = 0; i < n; ++i) {
        const scene::PunctualLight& l = s.lights[i];
        glm::mat4 world = l.node < object.pose.nodeWorld.size() ? object.pose.nodeWorld[l.node] : glm::mat4(1.0f);
        gpu_types::PunctualLightGpu& g = out.lights[i];
        float invRange2 = l.range > 0.0f ? 1.0f / (l.range * l.range) : 0.0f;
        g.position = glm::vec4(glm::vec3(world[3]), invRange2);
        glm::vec3 dir = glm::vec3(world * glm::vec4(0.0f, 0.0f, -1.0f, 0.0f)); // glTF lights shine down −Z
        float len = glm::length(dir);
        g.direction = glm::vec4(len > 0.0f ? dir / len : glm::vec3(0.0f, 0.0f, -1.0f),
                                l.type == scene::LightType::Spot ? 1.0f : 0.0f);
        g.intensity = glm::vec4(l.color * l.intensity, 0.0f);
        float cosOuter = std::cos(l.outerConeAngle), cosInner = std::cos(l.innerConeAngle);
        float scale = 1.0f / std::max(1e-3f, cosInner - cosOuter);
        g.cone = glm::vec4(scale, -cosOuter * scale, 0.0f, 0.0f);
    }
    return out;
}

inline void warnLightCount(const scene::Scene& s, const std::string& node) {
    if (s.lights.size() > VITRINE_MAX_PUNCTUAL_LIGHTS) {
        logWarning(node + ": the scene has " + std::to_string(s.lights.size()) + " point/spot lights; only the first " +
                   std::to_string(VITRINE_MAX_PUNCTUAL_LIGHTS) + " are lit");
    }
}

} // namespace vitrine
