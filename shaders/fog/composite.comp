#version 460
#extension GL_GOOGLE_include_directive : require
#include "fog/composite.h"

// fog.composite: applies fog.volumetric's low-resolution march to the full-resolution colour,
//   out = colour * T + in-scattering,
// upsampled by a joint bilateral filter on distance: the 2x2 low-resolution taps around the pixel are weighted
// bilinearly times exp(-(relative distance difference / depthSigma)^2 / 2), so a tap across a depth edge (a
// statue against the far wall) contributes nothing; where all four lie across an edge (thin features) the tap
// nearest in distance is taken alone.
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0) uniform sampler2D in_color;
layout(binding = 1) uniform sampler2D in_depth;
layout(binding = 2) uniform sampler2D in_scatter;
layout(binding = 3) uniform sampler2D in_distance;
layout(binding = 4) writeonly uniform image2D out_color;

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = imageSize(out_color);
    if (any(greaterThanEqual(p, size))) return;
    vec2 uv = (vec2(p) + 0.5) / vec2(size);
    float z = texelFetch(in_depth, p, 0).r;
    vec4 wh = pc.invViewProj * vec4(uv * 2.0 - 1.0, max(z, 1e-7), 1.0);
    float dist = z > 0.0 ? length(wh.xyz / wh.w - pc.cameraPos.xyz) : FOG_SKY_DISTANCE;

    ivec2 lowSize = textureSize(in_scatter, 0);
    vec2 lowPos = uv * vec2(lowSize) - 0.5;
    ivec2 base = ivec2(floor(lowPos));
    vec2 f = lowPos - vec2(base);
    vec4 sum = vec4(0.0);
    float weightSum = 0.0;
    vec4 nearest = vec4(0.0, 0.0, 0.0, 1.0);
    float nearestDiff = 1e30;
    for (int i = 0; i < 4; ++i) {
        ivec2 o = ivec2(i & 1, i >> 1);
        ivec2 t = clamp(base + o, ivec2(0), lowSize - 1);
        vec4 s = texelFetch(in_scatter, t, 0);
        float rel = abs(texelFetch(in_distance, t, 0).r - dist) / max(dist, 1e-3);
        float bilinear = (o.x == 1 ? f.x : 1.0 - f.x) * (o.y == 1 ? f.y : 1.0 - f.y);
        float x = rel / pc.depthSigma;
        float w = bilinear * exp(-0.5 * x * x);
        sum += s * w;
        weightSum += w;
        if (rel < nearestDiff) {
            nearestDiff = rel;
            nearest = s;
        }
    }
    vec4 fog = weightSum > 1e-3 ? sum / weightSum : nearest;
    vec4 c = texelFetch(in_color, p, 0);
    imageStore(out_color, p, vec4(c.rgb * fog.a + fog.rgb, c.a));
}
