#ifndef LIGHTING_DEFERRED_H
#define LIGHTING_DEFERRED_H
#include "../common/shared.h"
#include "../shadow/cascades.h"
#include "lights.h"

#ifdef __cplusplus
namespace vitrine::gpu_types {
#endif

// Uniforms of lighting.deferred (filled per frame from the camera and the shadow cascades).
struct DeferredUniforms {
    mat4 invViewProj;  // jittered, as the G-buffer was rasterised
    vec4 cameraPos;    // world
    vec4 params;       // x: sky ambient scale, y: shadows on (1/0), z: sun intensity scale, w: emissive scale
    vec4 volumeOrigin; // bake.lightmap's irradiance volume: xyz probe (0, 0, 0), w spacing (m)
    uvec4 volumeCounts; // xyz probes per axis (0: no volume connected); w: bits 0 ibl_specular, 1 ibl_diffuse, 2 ao, 3 brdf_lut connected
    ShadowCascades shadow;
    PunctualLights lights; // the scene's point and spot lights (none without a scene input)
};

#ifdef __cplusplus
static_assert(sizeof(DeferredUniforms) == 64 + 64 + sizeof(ShadowCascades) + sizeof(PunctualLights));
}
#endif
#endif
