// ao.alchemy's push constants and sample pattern, shared by nodes/ao/alchemy.cpp, shaders/ao/alchemy.comp and the CPU
// reference of tests/gpu/ao_test.cpp.
#ifndef AO_ALCHEMY_H
#define AO_ALCHEMY_H
#include "../common/shared.h"

#define ALCHEMY_SPIRAL_TURNS 7.0 // turns of the sample spiral (coprime with typical sample counts)
#define ALCHEMY_EPSILON 1e-4     // m^2 in the estimator's denominator (McGuire et al.: epsilon)
#define ALCHEMY_MAX_RADIUS_PX 96.0 // the projected radius is capped (near the camera it would cover the screen)

#ifdef __cplusplus
namespace vitrine::gpu_types {
#endif
VITRINE_PUSH_BEGIN(AlchemyPush)
    mat4 invViewProj; // jittered, as the G-buffer was rasterised
    vec4 cameraPos;   // xyz world; w: pixels per metre at view depth 1 (G-buffer height / 2 x proj[1][1])
    vec4 forward;     // xyz: unit view direction (world); w: 0
    vec4 params;      // x: radius (m), y: intensity sigma, z: bias beta (m per m of depth), w: contrast k
    uint samples;     // s
    uint frame;       // rotates the pattern every frame (0: the same pattern every frame)
    uint pad0;
    uint pad1;
VITRINE_PUSH_END(pc)
#ifdef __cplusplus
static_assert(sizeof(AlchemyPush) == 128);
#define ALCHEMY_INLINE inline
#else
#define ALCHEMY_INLINE
#endif

// Rotation of pixel (x, y)'s spiral in turns, [0, 1): a PCG hash of the pixel and the frame.
ALCHEMY_INLINE float alchemyRotation(uint x, uint y, uint frame) {
    uint v = x * 1973u + y * 9277u + frame * 26699u;
    uint state = v * 747796405u + 2891336453u;
    uint word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    word = (word >> 22u) ^ word;
    return float(word >> 8u) * (1.0f / 16777216.0f);
}
#ifdef __cplusplus
}
#endif
#endif
