#ifndef SSR_COMPOSITE_H
#define SSR_COMPOSITE_H
#include "../common/shared.h"

#ifdef __cplusplus
namespace vitrine::gpu_types {
#endif

struct SsrCompositeUniforms {
    mat4 invViewProj; // jittered, as the G-buffer was rasterised
    vec4 cameraPos;   // xyz world
    uvec4 config;     // x: 1 = brdf_lut connected (E from it), 0 = Karis' fit (ambient.glsl); yzw unused
};

#ifdef __cplusplus
static_assert(sizeof(SsrCompositeUniforms) == 96);
}
#endif
#endif
