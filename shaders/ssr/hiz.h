#ifndef SSR_HIZ_H
#define SSR_HIZ_H
#include "../common/shared.h"

#ifdef __cplusplus
namespace vitrine::gpu_types {
#endif

#define SSR_VELOCITY 1u // reproject hits by the velocity buffer into last frame's colour pyramid

// Uniforms of ssr.hiz (per frame, from the camera and the params).
struct SsrUniforms {
    mat4 viewProj;    // jittered, as the G-buffer was rasterised
    mat4 invViewProj;
    vec4 cameraPos;   // xyz world; w: near plane distance (m)
    vec4 cameraFwd;   // xyz unit view direction; w: proj[1][1] (pixels per unit of tan at the image's height / 2)
    vec4 depthParams; // proj[2][2], proj[3][2], proj[2][3], proj[3][3]: view depth <-> reverse-Z depth
    vec4 params;      // x: thickness (m), y: max distance (m), z: edge fade (fraction of the screen), w: max roughness
    ivec4 size;       // xy: depth (level 0) size; z: Hi-Z levels; w: colour pyramid levels
    uvec4 config;     // x: max taps per ray, y: max rays per pixel, z: flags (SSR_*), w: frame index
    vec4 cone;        // x: cone_scale (the footprint that picks the colour pyramid's level, x the lobe's); yzw unused
};

#ifdef __cplusplus
static_assert(sizeof(SsrUniforms) == 2 * 64 + 7 * 16);
}
#endif
#endif
