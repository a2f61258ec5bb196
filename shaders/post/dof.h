// post.dof (optics-based bokeh depth of field): push constants and limits shared by nodes/post/dof.cpp and the
// shaders/post/dof_*.comp passes.
#ifndef POST_DOF_H
#define POST_DOF_H
#include "../common/shared.h"

#define DOF_MAX_LAYERS 15
#define DOF_TILE 16
#define DOF_MAX_SPRITES 4096

#ifdef __cplusplus
namespace vitrine::gpu_types {
#endif

// One push block for the three passes (coc, classify, gather).
VITRINE_PUSH_BEGIN(DofPush)
    // Thin lens: CoC diameter in pixels c = cocScale / (zf - f) * (z - zf) / z, cocScale = f^2 / N / sensorHeight
    // * imageHeight (lengths in metres), zf the focus distance, z the view depth.
    float cocScale;
    float focalLength;   // f, metres
    float focusDistance; // zf, metres (unless autofocus)
    float maxCoc;        // largest |CoC| diameter in pixels
    float depthA;        // reverse-Z depth d of view depth z: d = depthB / z - depthA, so z = depthB / (d + depthA)
    float depthB;
    vec2 autofocus;      // pixel whose depth is the focus distance; x < 0: off
    // Aperture (shaders/post/aperture.glsl): blades (0 circle), roundness, rotation (radians, y up), area of the
    // unit-circumradius shape.
    uint blades;
    float roundness;
    float rotation;
    float apertureArea;
    uint layers;         // 3..DOF_MAX_LAYERS over the frame's CoC range (shaders/post/dof_layers.glsl)
    uint maxSprites;     // cap of the scatter list
    float scatterRatio;  // a pixel scatters when its luminance exceeds the 8 neighbours' mean by this factor ...
    float scatterMinCoc; // ... and its |CoC| is at least this (pixels)
    float historyWeight; // weight of the reprojected CoC history (0: none, the raw CoC)
    uint hasVelocity;
    uint tilesX;
    uint pad;            // 0 (dof_clear.comp stores it)
VITRINE_PUSH_END(pc)

#ifdef __cplusplus
static_assert(sizeof(DofPush) == 80);
}
#endif
#endif
