// bake.lightmap's push constants, shared by nodes/bake/lightmap.cpp and shaders/bake/lightmap.comp.
#ifndef BAKE_LIGHTMAP_H
#define BAKE_LIGHTMAP_H
#include "../common/shared.h"

#ifdef __cplusplus
namespace vitrine::gpu_types {
#endif

VITRINE_PUSH_BEGIN(LightmapBakePush)
    vec4 scales;  // x: sun, y: sky, z: emissive, w: caustic footprint (metres; 0: exact)
    uvec4 counts; // x: jobs, y: paths per job in this dispatch, z: seed of this dispatch, w: max bounces
    uvec4 grid;   // x: jobs per dispatch row, y: flags (LIGHTMAP_BAKE_*), zw: 0
VITRINE_PUSH_END(push)

#define LIGHTMAP_BAKE_FIRST 1u // the first dispatch: overwrite the sums instead of adding to them

// Paths per job and dispatch: lavapipe ends every loop of an invocation after 65535 loop iterations in all
// (see shaders/render/pathtrace.h), so the bake's samples are spread over many short dispatches.
#define LIGHTMAP_BAKE_PATHS_PER_DISPATCH 2u

#ifdef __cplusplus
static_assert(sizeof(LightmapBakePush) == 48);
}
#endif
#endif
