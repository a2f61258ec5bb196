#version 460
#extension GL_GOOGLE_include_directive : require
#include "debug/view.h"
#include "common/color.glsl"

layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0) uniform sampler2D in_texture;
layout(binding = 1) writeonly uniform image2D out_color;

// Perceptually ordered ramp, dark blue -> cyan -> green -> yellow -> red, linear RGB.
vec3 ramp(float t) {
    const vec3 stops[5] = vec3[](vec3(0.02, 0.02, 0.25), vec3(0.0, 0.45, 0.75), vec3(0.1, 0.7, 0.15),
                                 vec3(0.95, 0.85, 0.05), vec3(0.8, 0.05, 0.02));
    float x = clamp(t, 0.0, 1.0) * 4.0;
    int i = min(int(x), 3);
    return mix(stops[i], stops[i + 1], x - float(i));
}

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = imageSize(out_color);
    if (any(greaterThanEqual(p, size))) return;
    // Nearest texel of the input, whatever its size relative to the output.
    ivec2 inSize = textureSize(in_texture, 0);
    ivec2 q = min(ivec2((vec2(p) + 0.5) * vec2(inSize) / vec2(size)), inSize - 1);
    vec4 v = texelFetch(in_texture, q, 0);
    float scale = 1.0 / max(pc.rangeMax - pc.rangeMin, 1e-20);
    vec4 n = (v - pc.rangeMin) * scale;
    vec4 outColor;
    float s = 0.0;
    bool single = true;
    if (pc.channel == VIEW_R) s = n.r;
    else if (pc.channel == VIEW_G) s = n.g;
    else if (pc.channel == VIEW_B) s = n.b;
    else if (pc.channel == VIEW_A) s = n.a;
    else if (pc.channel == VIEW_LUMA) s = (luminance(v.rgb) - pc.rangeMin) * scale;
    else single = false;
    if (single) outColor = vec4(pc.falseColor != 0u ? ramp(s) : vec3(clamp(s, 0.0, 1.0)), 1.0);
    else if (pc.channel == VIEW_RGB) outColor = vec4(n.rgb, 1.0);
    else outColor = n;
    imageStore(out_color, p, outColor);
}
