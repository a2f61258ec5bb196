#version 460
#extension GL_GOOGLE_include_directive : require
#include "compare/flip.h"
#include "common/magma.glsl"

// LDR-FLIP (Andersson et al., HPG 2020) per pixel, the same pipeline as core/compare/flip.cpp: inputs clamped to
// [0,1] (display-referred linear RGB) -> YCxCz -> CSF filter -> linear RGB, clamped -> Hunt-adjusted L*a*b* ->
// HyAB^0.7 colour difference, redistributed; edge and point features of Y / Y_white; error = dC^(1 - dF).
//
// Everything happens in one dispatch (nodes issue no barriers between dispatches), so the separable filters of the
// CPU version become 2D loops over (2r+1)^2 taps: O(r^2) per pixel, r = 10 at the default 67 pixels per degree.
// Same result (clamp-to-edge per axis), cost is fine at test and preview sizes, slow for 1080p on lavapipe.
//
// Defines from nodes/compare/flip.cpp (the kernels of vitrine::compare::detail::makeKernels):
//   FLIP_CSF_RADIUS, FLIP_FEATURE_RADIUS and float[] kernels FLIP_KERNEL_Y, _CX, _CZ0, _CZ1 (2 * CSF radius + 1
//   taps), FLIP_KERNEL_GAUSS, _EDGE, _POINT (2 * feature radius + 1 taps).
#ifndef FLIP_CSF_RADIUS
// Only when the shader is compiled on its own (tests/gpu/shader_test.cpp compiles every shipped shader): radius-0
// placeholders keep it valid GLSL. compare.flip always passes the real kernels.
#define FLIP_CSF_RADIUS 0
#define FLIP_FEATURE_RADIUS 0
#define FLIP_KERNEL_Y float[](1.0)
#define FLIP_KERNEL_CX float[](1.0)
#define FLIP_KERNEL_CZ0 float[](1.0)
#define FLIP_KERNEL_CZ1 float[](1.0)
#define FLIP_KERNEL_GAUSS float[](1.0)
#define FLIP_KERNEL_EDGE float[](0.0)
#define FLIP_KERNEL_POINT float[](0.0)
#endif

layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0) uniform sampler2D in_reference;
layout(binding = 1) uniform sampler2D in_test;
layout(binding = 2) writeonly uniform image2D out_error;
layout(binding = 3) writeonly uniform image2D out_color;

const int kR = FLIP_CSF_RADIUS;
const int kF = FLIP_FEATURE_RADIUS;
const float kY[2 * kR + 1] = FLIP_KERNEL_Y;
const float kCx[2 * kR + 1] = FLIP_KERNEL_CX;
const float kCz0[2 * kR + 1] = FLIP_KERNEL_CZ0;
const float kCz1[2 * kR + 1] = FLIP_KERNEL_CZ1;
const float kGauss[2 * kF + 1] = FLIP_KERNEL_GAUSS;
const float kEdge[2 * kF + 1] = FLIP_KERNEL_EDGE;
const float kPoint[2 * kF + 1] = FLIP_KERNEL_POINT;

// Linear sRGB (Rec.709, D65) to XYZ, rows, as the exact fractions of the sRGB definition.
const vec3 kToX = vec3(10135552.0 / 24577794.0, 8788810.0 / 24577794.0, 4435075.0 / 24577794.0);
const vec3 kToY = vec3(2613072.0 / 12288897.0, 8788810.0 / 12288897.0, 887015.0 / 12288897.0);
const vec3 kToZ = vec3(1425312.0 / 73733382.0, 8788810.0 / 73733382.0, 70074185.0 / 73733382.0);
// XYZ of RGB (1,1,1): the white both YCxCz and L*a*b* normalise by.
const vec3 kWhite = vec3(kToX.x + kToX.y + kToX.z, kToY.x + kToY.y + kToY.z, kToZ.x + kToZ.y + kToZ.z);

const float kQc = 0.7;
const float kPc = 0.4;
const float kPt = 0.95;
const float kQf = 0.5;

vec3 rgbToXyz(vec3 c) { return vec3(dot(kToX, c), dot(kToY, c), dot(kToZ, c)); }

vec3 rgbToYcxcz(vec3 c) {
    vec3 n = rgbToXyz(c) / kWhite;
    return vec3(116.0 * n.y - 16.0, 500.0 * (n.x - n.y), 200.0 * (n.y - n.z));
}

vec3 ycxczToXyz(vec3 v) {
    float y = (v.x + 16.0) / 116.0;
    return vec3(y + v.y / 500.0, y, y - v.z / 200.0) * kWhite;
}

float labF(float t) {
    const float kDelta = 6.0 / 29.0;
    return t > kDelta * kDelta * kDelta ? pow(t, 1.0 / 3.0) : t / (3.0 * kDelta * kDelta) + 4.0 / 29.0;
}

// CIE L*a*b* with the Hunt adjustment (chroma scaled by 0.01 L*).
vec3 huntLab(vec3 rgb) {
    vec3 n = rgbToXyz(rgb) / kWhite;
    float fx = labF(n.x), fy = labF(n.y), fz = labF(n.z);
    float l = 116.0 * fy - 16.0;
    return vec3(l, 0.01 * l * 500.0 * (fx - fy), 0.01 * l * 200.0 * (fy - fz));
}

float hyab(vec3 a, vec3 b) { return abs(a.x - b.x) + length(a.yz - b.yz); }

vec3 fetchClamped(sampler2D tex, ivec2 q) {
    vec3 c = texelFetch(tex, q, 0).rgb;
    return vec3(isnan(c.r) ? 0.0 : clamp(c.r, 0.0, 1.0), isnan(c.g) ? 0.0 : clamp(c.g, 0.0, 1.0),
                isnan(c.b) ? 0.0 : clamp(c.b, 0.0, 1.0));
}

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = imageSize(out_error);
    if (any(greaterThanEqual(p, size))) return;
    ivec2 testSize = textureSize(in_test, 0);
    mat3 xyzToRgb = inverse(transpose(mat3(kToX, kToY, kToZ)));

    vec3 csfR = vec3(0.0), csfT = vec3(0.0);
    // Feature filters of Y / Y_white: (edge x gauss, gauss x edge, point x gauss, gauss x point) per image.
    vec4 featR = vec4(0.0), featT = vec4(0.0);
    for (int dy = -kR; dy <= kR; ++dy) {
        int sy = clamp(p.y + dy, 0, size.y - 1);
        vec4 wy = vec4(kY[dy + kR], kCx[dy + kR], kCz0[dy + kR], kCz1[dy + kR]) * pc.csfWeights;
        bool featureRow = abs(dy) <= kF;
        vec3 fy = featureRow ? vec3(kGauss[dy + kF], kEdge[dy + kF], kPoint[dy + kF]) : vec3(0.0);
        for (int dx = -kR; dx <= kR; ++dx) {
            ivec2 q = ivec2(clamp(p.x + dx, 0, size.x - 1), sy);
            ivec2 qt = testSize == size ? q : min(ivec2((vec2(q) + 0.5) * vec2(testSize) / vec2(size)), testSize - 1);
            vec3 r = rgbToYcxcz(fetchClamped(in_reference, q));
            vec3 t = rgbToYcxcz(fetchClamped(in_test, qt));
            int i = dx + kR;
            vec3 w = vec3(kY[i] * wy.x, kCx[i] * wy.y, kCz0[i] * wy.z + kCz1[i] * wy.w);
            csfR += w * r;
            csfT += w * t;
            if (featureRow && abs(dx) <= kF) {
                int j = dx + kF;
                vec4 fw = vec4(kEdge[j] * fy.x, kGauss[j] * fy.y, kPoint[j] * fy.x, kGauss[j] * fy.z);
                featR += fw * ((r.x + 16.0) / 116.0);
                featT += fw * ((t.x + 16.0) / 116.0);
            }
        }
    }

    // Filtering can leave the RGB cube; clamp back into it before measuring colour, as the paper does.
    vec3 labR = huntLab(clamp(xyzToRgb * ycxczToXyz(csfR), 0.0, 1.0));
    vec3 labT = huntLab(clamp(xyzToRgb * ycxczToXyz(csfT), 0.0, 1.0));
    float cmax = pow(hyab(huntLab(vec3(0.0, 1.0, 0.0)), huntLab(vec3(0.0, 0.0, 1.0))), kQc);
    float pccmax = kPc * cmax;
    float colour = pow(hyab(labR, labT), kQc);
    float deltaC = colour < pccmax ? kPt / pccmax * colour : kPt + (colour - pccmax) / (cmax - pccmax) * (1.0 - kPt);

    float feature = max(abs(length(featR.xy) - length(featT.xy)), abs(length(featR.zw) - length(featT.zw)));
    float deltaF = pow(feature / sqrt(2.0), kQf);
    float exponent = 1.0 - deltaF;
    // pow(0, 0) is undefined in GLSL; the CPU's std::pow gives 1.
    float e = exponent <= 0.0 ? 1.0 : (deltaC <= 0.0 ? 0.0 : pow(deltaC, exponent));
    e = clamp(e, 0.0, 1.0);
    imageStore(out_error, p, vec4(vec3(e), 1.0));
    imageStore(out_color, p, vec4(magma(e), 1.0));
}
