#ifndef IBL_LOCALIZED_H
#define IBL_LOCALIZED_H
#include "../common/shared.h"

#define IBL_LOCALIZED_MAX_PROBES 128

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
};

// Uniforms of every pass of ibl.localized.
struct LocalizedUniforms {
    mat4 viewProj;    // jittered, as the G-buffer was rasterised
    mat4 invViewProj; // its inverse
    vec4 cameraPos;   // xyz: world; w: number of probes
    vec4 params;      // x: blend (0 "a", 1 "b"); y: parallax (1/0); z: sky fallback scale; w: unused
    LocalizedProbe probes[IBL_LOCALIZED_MAX_PROBES];
};

#ifdef __cplusplus
static_assert(sizeof(LocalizedProbe) == 96);
static_assert(sizeof(LocalizedUniforms) == 160 + 96 * IBL_LOCALIZED_MAX_PROBES);
}
#endif
#endif
