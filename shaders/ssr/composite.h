#ifndef SSR_COMPOSITE_H
#define SSR_COMPOSITE_H
#include "../common/shared.h"

#ifdef __cplusplus
namespace vitrine::gpu_types {
#endif

struct SsrCompositeUniforms {
    mat4 invViewProj; // jittered, as the G-buffer was rasterised
    vec4 cameraPos;   // xyz world
};

#ifdef __cplusplus
static_assert(sizeof(SsrCompositeUniforms) == 80);
}
#endif
#endif
