#ifndef FORWARD_TRANSPARENT_H
#define FORWARD_TRANSPARENT_H
#include "../common/shared.h"
#include "../lighting/lights.h"
#include "../shadow/cascades.h"

#ifdef __cplusplus
namespace vitrine::gpu_types {
#endif

// Uniforms of forward.transparent (set 1, binding 0), filled per frame; the same parameters as lighting.deferred.
struct TransparentUniforms {
    vec4 params; // x: sky ambient scale, y: shadows on (1/0), z: sun intensity scale, w: emissive scale
    vec4 volumeOrigin;  // bake.lightmap's irradiance volume: xyz probe (0, 0, 0), w spacing (m)
    uvec4 volumeCounts; // xyz probes per axis (0: no volume connected); w: 1 with a brdf_lut
    uvec4 background;   // x: 1 with a background (color.pyramid), yz its level-0 size, w its levels
    ShadowCascades shadow;
    PunctualLights lights;
};

#ifdef __cplusplus
static_assert(sizeof(TransparentUniforms) == 64 + sizeof(ShadowCascades) + sizeof(PunctualLights));
}
#endif
#endif
