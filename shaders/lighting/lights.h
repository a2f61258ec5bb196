// Punctual lights (KHR_lights_punctual point and spot lights) as the lighting nodes read them, packed per
// frame from the scene's pose (nodes/lighting/punctual_lights.hpp). Shared by C++ and GLSL.
#ifndef LIGHTING_LIGHTS_H
#define LIGHTING_LIGHTS_H
#include "../common/shared.h"

#ifdef __cplusplus
namespace vitrine::gpu_types {
#endif

#define VITRINE_MAX_PUNCTUAL_LIGHTS 16

struct PunctualLightGpu {
    vec4 position;  // xyz: world position, w: 1 / range² (0: infinite range)
    vec4 direction; // xyz: unit direction the spot shines along (world), w: 1 spot, 0 point
    vec4 intensity; // rgb: colour × intensity (candela)
    vec4 cone;      // x: 1 / max(1e-3, cos inner − cos outer), y: −cos outer × x (glTF's angular attenuation)
};

struct PunctualLights {
    uvec4 count; // x: lights in use
    PunctualLightGpu lights[VITRINE_MAX_PUNCTUAL_LIGHTS];
};

#ifdef __cplusplus
static_assert(sizeof(PunctualLightGpu) == 64);
static_assert(sizeof(PunctualLights) == 16 + 64 * VITRINE_MAX_PUNCTUAL_LIGHTS);
}
#endif
#endif
