// Sun shadow cascades: written by shadow.directional (CPU side), read by lighting nodes as uniforms.
#ifndef SHADOW_CASCADES_H
#define SHADOW_CASCADES_H
#include "../common/shared.h"

#ifdef __cplusplus
namespace vitrine::gpu_types {
#endif

#define VITRINE_MAX_CASCADES 4

// Cascade c occupies tile (c % 2, c / 2) of a 2x2 atlas; its matrix maps world space to the tile's
// [0,1]^2 atlas coordinates (xy) and light depth (z, 0 near .. 1 far).
struct ShadowCascades {
    mat4 worldToShadow[VITRINE_MAX_CASCADES];
    vec4 splits;     // far view depth (m) of each cascade
    vec4 texelWorld; // world size of one shadow texel per cascade (normal offset, filter radius)
    vec4 params;     // x: cascade count, y: atlas size (texels), z: depth bias, w: normal offset (texels)
    vec4 lightDir;   // xyz: direction toward the sun, w: PCF radius (texels)
};

#ifdef __cplusplus
static_assert(sizeof(ShadowCascades) == 4 * 64 + 4 * 16);
}
#endif
#endif
