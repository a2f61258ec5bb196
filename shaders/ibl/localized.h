#ifndef IBL_LOCALIZED_H
#define IBL_LOCALIZED_H
#include "../common/shared.h"

// 160 + 128 x 120 bytes: within the 16 KiB every Vulkan device allows a uniform buffer.
#define IBL_LOCALIZED_MAX_PROBES 120

#ifdef __cplusplus
namespace vitrine::gpu_types {
#endif

// One scene::ReflectionProbe as ibl.localized draws it. Probe i reads cube i of the cube-map array (layers 6i..6i+5).
struct LocalizedProbe {
    vec4 center;  // xyz: influence volume centre (world); w: shape (0 box, 1 sphere)
    vec4 axisX;   // xyz: the box's local x axis in world space; w: half extent along it (sphere: the radius)
    vec4 axisY;   // xyz: local y; w: half extent
    vec4 axisZ;   // xyz: local z; w: half extent
    vec4 capture; // xyz: capture point (world); w: fade distance (m)
    vec4 weight;  // x: the node's weight scale (see nodes/ibl/localized.cpp); y: priority minus the highest; zw unused
    vec4 proxyCenter; // xyz: the parallax proxy's centre (world): the projection box's, else the volume's; w unused
    vec4 proxyHalf;   // xyz: its half extents along axisX/Y/Z (sphere: x the radius); w unused
};

// Uniforms of every pass of ibl.localized.
struct LocalizedUniforms {
    mat4 viewProj;    // jittered, as the G-buffer was rasterised
    mat4 invViewProj; // its inverse
    vec4 cameraPos;   // xyz: world; w: number of probes
    vec4 params;      // x: blend (0 "a", 1 "b"); y: parallax (1/0); z: sky fallback scale; w: dominant direction (1/0)
    LocalizedProbe probes[IBL_LOCALIZED_MAX_PROBES];
};

#ifdef __cplusplus
static_assert(sizeof(LocalizedProbe) == 128);
static_assert(sizeof(LocalizedUniforms) == 160 + 128 * IBL_LOCALIZED_MAX_PROBES);
static_assert(sizeof(LocalizedUniforms) <= 16384);
}
#endif
#endif
