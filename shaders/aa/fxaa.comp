#version 460
#extension GL_GOOGLE_include_directive : require
#include "aa/fxaa.h"
#include "common/color.glsl"

// FXAA 3.11 "quality" (Lottes 2011), written from the whitepaper's description: local contrast
// test, sub-pixel blend from the 3x3 low-pass, edge orientation from second differences, a
// search along the edge for both ends, and a bilinear re-sample across the edge by the
// distance to the nearer end.
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0) uniform sampler2D in_color;
layout(binding = 1) writeonly uniform image2D out_color;

vec2 gInvSize;

// FXAA wants perceptual luma; the input is linear, and sqrt is close to a display curve.
float lumaAt(vec2 uv) { return sqrt(max(luminance(textureLod(in_color, uv, 0.0).rgb), 0.0)); }
float lumaOff(vec2 uv, vec2 off) { return lumaAt(uv + off * gInvSize); }

const float kSteps[12] = float[](1.0, 1.0, 1.0, 1.0, 1.0, 1.5, 2.0, 2.0, 2.0, 2.0, 4.0, 8.0);

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = imageSize(out_color);
    if (any(greaterThanEqual(p, size))) return;
    gInvSize = 1.0 / vec2(size);
    vec2 uv = (vec2(p) + 0.5) * gInvSize;
    vec4 centre = textureLod(in_color, uv, 0.0);

    float lumaM = sqrt(max(luminance(centre.rgb), 0.0));
    float lumaN = lumaOff(uv, vec2(0, -1));
    float lumaS = lumaOff(uv, vec2(0, 1));
    float lumaW = lumaOff(uv, vec2(-1, 0));
    float lumaE = lumaOff(uv, vec2(1, 0));
    float rangeMax = max(max(max(lumaN, lumaS), max(lumaW, lumaE)), lumaM);
    float rangeMin = min(min(min(lumaN, lumaS), min(lumaW, lumaE)), lumaM);
    float range = rangeMax - rangeMin;
    if (range < max(pc.edgeThresholdMin, rangeMax * pc.edgeThreshold)) {
        imageStore(out_color, p, centre);
        return;
    }

    float lumaNW = lumaOff(uv, vec2(-1, -1));
    float lumaNE = lumaOff(uv, vec2(1, -1));
    float lumaSW = lumaOff(uv, vec2(-1, 1));
    float lumaSE = lumaOff(uv, vec2(1, 1));

    // Sub-pixel aliasing: how far the centre stands out of its 3x3 neighbourhood average.
    float lumaL = (2.0 * (lumaN + lumaS + lumaW + lumaE) + (lumaNW + lumaNE + lumaSW + lumaSE)) / 12.0;
    float subA = clamp(abs(lumaL - lumaM) / range, 0.0, 1.0);
    float subB = (-2.0 * subA + 3.0) * subA * subA;
    float subpixBlend = subB * subB * pc.subpix;

    float edgeVert = abs(0.25 * lumaNW - 0.5 * lumaW + 0.25 * lumaSW) + abs(0.5 * lumaN - lumaM + 0.5 * lumaS) +
                     abs(0.25 * lumaNE - 0.5 * lumaE + 0.25 * lumaSE);
    float edgeHorz = abs(0.25 * lumaNW - 0.5 * lumaN + 0.25 * lumaNE) + abs(0.5 * lumaW - lumaM + 0.5 * lumaE) +
                     abs(0.25 * lumaSW - 0.5 * lumaS + 0.25 * lumaSE);
    bool horizontal = edgeHorz >= edgeVert;

    // The edge runs between M and the neighbour (across it) with the steeper gradient.
    float luma1 = horizontal ? lumaN : lumaW;
    float luma2 = horizontal ? lumaS : lumaE;
    float gradient1 = abs(luma1 - lumaM);
    float gradient2 = abs(luma2 - lumaM);
    float stepLength = horizontal ? gInvSize.y : gInvSize.x;
    float lumaLocal;
    if (gradient1 >= gradient2) {
        stepLength = -stepLength;
        lumaLocal = 0.5 * (luma1 + lumaM);
    } else {
        lumaLocal = 0.5 * (luma2 + lumaM);
    }
    float gradientScaled = 0.25 * max(gradient1, gradient2);

    vec2 edgeUv = uv;
    if (horizontal) edgeUv.y += 0.5 * stepLength;
    else edgeUv.x += 0.5 * stepLength;
    vec2 along = horizontal ? vec2(gInvSize.x, 0.0) : vec2(0.0, gInvSize.y);

    vec2 uvN = edgeUv - along * kSteps[0];
    vec2 uvP = edgeUv + along * kSteps[0];
    float endN = lumaAt(uvN) - lumaLocal;
    float endP = lumaAt(uvP) - lumaLocal;
    bool doneN = abs(endN) >= gradientScaled;
    bool doneP = abs(endP) >= gradientScaled;
    uint steps = min(pc.searchSteps, 12u);
    for (uint i = 1u; i < steps && !(doneN && doneP); ++i) {
        if (!doneN) {
            uvN -= along * kSteps[i];
            endN = lumaAt(uvN) - lumaLocal;
            doneN = abs(endN) >= gradientScaled;
        }
        if (!doneP) {
            uvP += along * kSteps[i];
            endP = lumaAt(uvP) - lumaLocal;
            doneP = abs(endP) >= gradientScaled;
        }
    }

    float distN = horizontal ? uv.x - uvN.x : uv.y - uvN.y;
    float distP = horizontal ? uvP.x - uv.x : uvP.y - uv.y;
    bool nearerN = distN < distP;
    float dist = min(distN, distP);
    float spanLength = distN + distP;
    // Only blend when the nearer end's luma moves the other way from the centre: then the
    // centre is on the side of the edge that the staircase cut into.
    bool centreSmaller = lumaM < lumaLocal;
    bool correctVariation = ((nearerN ? endN : endP) < 0.0) != centreSmaller;
    float edgeBlend = correctVariation ? 0.5 - dist / spanLength : 0.0;
    float blend = max(edgeBlend, subpixBlend);

    vec2 finalUv = uv;
    if (horizontal) finalUv.y += blend * stepLength;
    else finalUv.x += blend * stepLength;
    imageStore(out_color, p, vec4(textureLod(in_color, finalUv, 0.0).rgb, centre.a));
}
