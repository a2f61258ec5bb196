#version 460
#extension GL_GOOGLE_include_directive : require
#include "ao/alchemy.h"
#include "common/octahedral.glsl"

// Alchemy screen-space ambient obscurance (McGuire, Osman, Bukowski, Hennessy 2011), MUSEUM_SPEC §5. For the surface
// point P with normal n at view depth z, s points Q_i are read from the depth buffer on a spiral of world radius r
// around P (projected to the screen, rotated per pixel and per frame so temporal.accumulate averages the patterns):
//   A = max(0, 1 - (2 sigma / s) sum_i r max(0, v_i . n - beta z) / (v_i . v_i + epsilon))^k,   v_i = Q_i - P,
// where only samples with |v_i| < r count (farther geometry does not occlude), and empty or off-screen samples count
// as unoccluded. The sum is scaled by r so sigma is dimensionless (the paper's sigma has units of length). A plane
// does not occlude itself: v . n = 0 there, and the bias beta z absorbs the depth's half-float rounding.
// Output: ao at this target's size (full or half of the G-buffer); each pixel reads the G-buffer texel under its
// centre and samples in G-buffer pixels.
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0) uniform sampler2D in_normal;
layout(binding = 1) writeonly uniform image2D out_ao;

const float kTwoPi = 6.28318530718;

ivec2 gFullSize;

// World position of G-buffer texel q at view depth d (the ray through its centre, scaled to depth d).
vec3 positionAt(ivec2 q, float d) {
    vec2 ndc = (vec2(q) + 0.5) / vec2(gFullSize) * 2.0 - 1.0;
    vec4 h = pc.invViewProj * vec4(ndc, 0.5, 1.0);
    vec3 dir = h.xyz / h.w - pc.cameraPos.xyz;
    return pc.cameraPos.xyz + dir * (d / dot(dir, pc.forward.xyz));
}

void main() {
    ivec2 p = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = imageSize(out_ao);
    if (any(greaterThanEqual(p, size))) return;
    gFullSize = textureSize(in_normal, 0);
    ivec2 c = min(ivec2((vec2(p) + 0.5) * vec2(gFullSize) / vec2(size)), gFullSize - 1);
    vec4 g = texelFetch(in_normal, c, 0);
    if (g.z <= 0.0) {
        imageStore(out_ao, p, vec4(1.0)); // nothing drawn
        return;
    }
    float z = g.z;
    vec3 n = octDecode(g.xy);
    vec3 P = positionAt(c, z);
    float radius = pc.params.x;
    float radiusPx = min(radius * pc.cameraPos.w / z, ALCHEMY_MAX_RADIUS_PX);
    float rotation = alchemyRotation(uint(c.x), uint(c.y), pc.frame);
    float sum = 0.0;
    for (uint i = 0u; i < pc.samples; ++i) {
        float a = (float(i) + 0.5) / float(pc.samples);
        float angle = kTwoPi * (a * ALCHEMY_SPIRAL_TURNS + rotation);
        vec2 offset = a * radiusPx * vec2(cos(angle), sin(angle));
        ivec2 q = ivec2(floor(vec2(c) + 0.5 + offset));
        if (any(lessThan(q, ivec2(0))) || any(greaterThanEqual(q, gFullSize))) continue;
        float dq = texelFetch(in_normal, q, 0).z;
        if (dq <= 0.0) continue;
        vec3 v = positionAt(q, dq) - P;
        float vv = dot(v, v);
        if (vv >= radius * radius) continue;
        sum += radius * max(0.0, dot(v, n) - pc.params.z * z) / (vv + ALCHEMY_EPSILON);
    }
    float ao = pow(max(0.0, 1.0 - 2.0 * pc.params.y / float(pc.samples) * sum), pc.params.w);
    imageStore(out_ao, p, vec4(ao, 0.0, 0.0, 1.0));
}
