// fog.volumetric (the low-resolution march): uniforms shared by nodes/fog/volumetric.cpp and the shader.
#ifndef FOG_VOLUMETRIC_H
#define FOG_VOLUMETRIC_H
#include "../common/shared.h"
#include "../shadow/cascades.h"

// fog.volumetric's `distance` where the G-buffer is empty (sky): far from any surface's, so fog.composite never
// blends sky and geometry (the march itself stops at cameraPos.w).
#define FOG_SKY_DISTANCE 1.0e6

#ifdef __cplusplus
namespace vitrine::gpu_types {
#endif

// Uniforms of fog.volumetric, filled per frame from the camera, the cascades and the params.
struct FogMarchUniforms {
    mat4 invViewProj;  // jittered, as the G-buffer was rasterised
    vec4 cameraPos;    // xyz world, w: max march distance (m) where the G-buffer is empty (sky)
    vec4 cameraFwd;    // xyz unit view direction (linear view depth = dot(p - cameraPos, fwd)), w: unused
    vec4 medium;       // x: density sigma (1/m at height y = medium.z), y: height falloff (1/m), z: reference height, w: HG g
    vec4 lighting;     // x: sun scale, y: ambient scale, z: shadows on (1/0), w: march start offset in [0, 1) (-1: per pixel)
    uvec4 march;       // x: steps, y: full-resolution width, z: full-resolution height, w: frame index
    ShadowCascades shadow;
};

#ifdef __cplusplus
static_assert(sizeof(FogMarchUniforms) == 64 + 4 * 16 + 16 + sizeof(ShadowCascades));
}
#endif
#endif
