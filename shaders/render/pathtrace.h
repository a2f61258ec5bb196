// render.pathtrace's push constants, shared by nodes/render/pathtrace.cpp and shaders/render/pathtrace.comp.
#ifndef RENDER_PATHTRACE_H
#define RENDER_PATHTRACE_H
#include "../common/shared.h"

#ifdef __cplusplus
namespace vitrine::gpu_types {
#endif

VITRINE_PUSH_BEGIN(PathtracePush)
    mat4 invViewProj; // the camera's unjittered view-projection, inverted (reverse Z)
    vec4 cameraPos;   // xyz world; w: 0
    vec4 scales;      // x: sun, y: environment, z: emissive, w: 0
    uvec4 counts;     // x: samples per pixel in this dispatch, y: max bounces, z: seed of this dispatch, w: flags (PATHTRACE_*)
VITRINE_PUSH_END(push)

#define PATHTRACE_RESET 1u      // ignore the history: the camera or the scene moved, or the first frame
#define PATHTRACE_ENV_CDF 2u    // sky.env_cdf is connected: sample the environment as a light (with MIS)
#define PATHTRACE_ANTIALIAS 4u  // jitter the primary rays over the pixel (off: through the pixel centre)
#define PATHTRACE_CONTINUE 8u   // a later dispatch of the frame: add to the outputs (not to the history)
#define PATHTRACE_SEE_THROUGH 16u // `transparent` and the BVH holds surfaces that let light pass (mask, blend, transmission)
#define PATHTRACE_ORTHOGRAPHIC 32u // an orthographic camera: primary rays start on the near plane (else at cameraPos)

// Surfaces a path or a shadow ray passes through at most (alpha-cut, uncovered or transmitting), counted apart from
// the bounces; a shadow ray with more is taken as blocked, a path with more ends.
#define PATHTRACE_MAX_PASSES 16u

// Samples per dispatch. Lavapipe (gallivm) stops every loop of an invocation once the invocation has run
// 65535 loop iterations in all (LP_MAX_TGSI_LOOP_ITERATIONS, a guard against infinite loops): BVH traversal,
// bounces and the texture walk of a path in the Museum take thousands, so a frame's samples are split into
// dispatches of a few samples each.
#define PATHTRACE_SAMPLES_PER_DISPATCH 2u

#ifdef __cplusplus
static_assert(sizeof(PathtracePush) == 112);
}
#endif
#endif
