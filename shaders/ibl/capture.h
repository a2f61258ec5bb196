#ifndef IBL_CAPTURE_H
#define IBL_CAPTURE_H
#include "../common/shared.h"

#ifdef __cplusplus
namespace vitrine::gpu_types {
#endif
#if defined(__cplusplus) || !defined(IBL_BRDF_LUT_SHADER)
// One mip of the prefiltered cube-map array (prefilter.comp) or of a cached one (copy_mip.comp): the dispatch
// covers size x (size * layers), layer = y / size.
VITRINE_PUSH_BEGIN(IblPrefilterPush)
    uint size;       // face size of this mip
    uint layers;     // 6 * probes
    uint samples;    // GGX samples per texel
    uint sourceSize; // face size of the source's mip 0 (filtered importance sampling's texel solid angle)
    float roughness; // perceptual roughness of this mip (ibl_common.glsl)
    float sourceMips; // mip levels of the source
    float pad0, pad1;
VITRINE_PUSH_END(pc)
#endif

#if defined(__cplusplus) || defined(IBL_BRDF_LUT_SHADER)
VITRINE_PUSH_BEGIN(IblBrdfLutPush)
    uint size;    // the LUT is size x size
    uint samples; // GGX samples per texel
    uint pad0, pad1;
VITRINE_PUSH_END(lut)
#endif
#ifdef __cplusplus
static_assert(sizeof(IblPrefilterPush) == 32);
static_assert(sizeof(IblBrdfLutPush) == 16);
}
#endif
#endif
