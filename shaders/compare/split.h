#ifndef COMPARE_SPLIT_H
#define COMPARE_SPLIT_H
#include "../common/shared.h"

#ifdef __cplusplus
namespace vitrine::gpu_types {
#endif
VITRINE_PUSH_BEGIN(SplitPush)
    vec4 lineColor;   // linear RGBA of the dividing line; alpha blends it over the images
    vec2 origin;      // a point on the line, in pixels
    vec2 normal;      // unit normal of the line: pixels with dot(centre - origin, normal) < 0 show a
    ivec2 labelA;     // top-left pixel of the "A" marker's box
    ivec2 labelB;     // top-left pixel of the "B" marker's box
    float halfWidth;  // half the line width in pixels (0: no line)
    uint labels;      // 1: draw the markers
    uint glyphScale;  // image pixels per glyph pixel
    uint pad;
VITRINE_PUSH_END(pc)
#ifdef __cplusplus
static_assert(sizeof(SplitPush) == 64);
}
#endif
#endif
