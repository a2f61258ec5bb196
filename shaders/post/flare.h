// post.flare's push constants, shared by nodes/post/flare.cpp and shaders/post/flare*.comp.
#ifndef POST_FLARE_H
#define POST_FLARE_H
#include "../common/shared.h"

#ifdef __cplusplus
namespace vitrine::gpu_types {
#endif
VITRINE_PUSH_BEGIN(FlarePush)
    vec4 scalesA;        // ghost scales 0..3: ghost i of a source at q lies at c + s_i (q - c); 0: no ghost
    vec4 scalesB;        // ghost scales 4..7
    vec2 centre;         // the optical centre c in bright-pass pixels
    float halfDiagonal;  // of the bright-pass image, pixels
    float exposure;      // linear scale from HDR radiance to display-referred (2^EV or camera_state's)
    float threshold;     // display-referred luminance above which light flares
    int factor;          // bright-pass downsampling
    float ghostIntensity; // each ghost's energy / the source's bright energy (times its tint)
    float haloRadius;    // ring ghost radius, fraction of the half-diagonal
    float haloIntensity; // the ring's energy / the source's bright energy
    uint haloTaps;       // taps on the ring
    float pad0;
    float pad1;
VITRINE_PUSH_END(pc)
#ifdef __cplusplus
static_assert(sizeof(FlarePush) == 80);
}
#endif
#endif
