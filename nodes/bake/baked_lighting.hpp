#pragma once
// What bake.lightmap hands to gbuffer.layered and lighting.deferred on its `layout` port (a Buffer-kind
// object): where each instance's lightmap lives in the atlas, and the irradiance volume's grid. Known at
// setup (the atlas plan and the grid are deterministic); the texels themselves travel on texture ports.
#include "core/graph/node.hpp"

#include <glm/glm.hpp>

#include <vector>

namespace vitrine {

class BakedLightingObject final : public PortObject {
public:
    // Per Scene::instances: atlas uv = uv1 * xy + zw; all zero for an instance without a lightmap.
    std::vector<glm::vec4> lightmapScaleOffset;
    // Irradiance volume: probe (x, y, z) at origin + spacing * (x, y, z); counts zero when there is none.
    glm::vec3 volumeOrigin{0.0f};
    float volumeSpacing = 1.0f;
    glm::uvec3 volumeCounts{0u};

    bool hasLightmap(uint32_t instance) const {
        return instance < lightmapScaleOffset.size() && lightmapScaleOffset[instance].x != 0.0f;
    }
};

} // namespace vitrine
