// fog.composite (the depth-aware upsample onto the colour): push constants shared by nodes/fog/composite.cpp and
// the shader.
#ifndef FOG_COMPOSITE_H
#define FOG_COMPOSITE_H
#include "../common/shared.h"
#include "volumetric.h"

#ifdef __cplusplus
namespace vitrine::gpu_types {
#endif

// fog.composite: out = colour * T + in-scattering, the low-resolution march upsampled by depth.
VITRINE_PUSH_BEGIN(FogCompositePush)
    mat4 invViewProj;  // as the G-buffer was rasterised (jittered)
    vec4 cameraPos;    // xyz world, w: unused
    float depthSigma;  // relative depth difference at which a low-resolution tap's weight falls to exp(-1/2)
    float pad0, pad1, pad2;
VITRINE_PUSH_END(pc)

#ifdef __cplusplus
static_assert(sizeof(FogCompositePush) == 64 + 16 + 16);
}
#endif
#endif
