#version 460
#extension GL_GOOGLE_include_directive : require
#include "post/motion_blur_common.glsl"

// Pass 3: the reconstruction gather of McGuire et al. 2012 ("A reconstruction filter for plausible motion blur"):
// S taps along the neighbourhood's dominant half-velocity vN, each classified by a soft depth test. Written from
// the paper's description, with its weights normalised by coverage so that the filter is exact in the two cases it
// can be checked against:
//   - occluders: a tap Y in front of X whose own blur (half-length |V_Y|) reaches X covers X for the share of the
//     shutter one tap's footprint (2|vN|/S pixels) spread over 2|V_Y| pixels; their summed coverage c (<= 1) hides
//     X's own layer;
//   - X's own layer: taps at X's depth or behind it within X's own blur (cylinder of |V_X|), averaged. In a region
//     of constant velocity this is the box filter of length 2|V|: a step edge becomes the exact linear ramp.
//   out = c * occluders + (1 - c) * own layer.
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0) uniform sampler2D in_color;
layout(binding = 1) uniform sampler2D in_velocity;
layout(binding = 2) uniform sampler2D in_depth;
layout(binding = 3, rg16f) uniform image2D out_neighbor_max;
layout(binding = 4) writeonly uniform image2D out_color;

// Linear view depth (gbuffer.normal's z); 0 marks no geometry, which is farther than anything.
float depthAt(ivec2 p) {
    float z = texelFetch(in_depth, p, 0).z;
    return z > 0.0 ? z : 1e30;
}

// McGuire12's cylinder: 1 inside radius h, 0 outside, a 10% soft edge.
float cylinder(float r, float h) { return 1.0 - smoothstep(0.95 * h, 1.05 * h, r); }

float hash(uvec3 v) {
    uint h = v.x * 0x8da6b343u ^ v.y * 0xd8163841u ^ v.z * 0xcb1ab31fu;
    h ^= h >> 16;
    h *= 0x7feb352du;
    h ^= h >> 15;
    return float(h >> 8) / 16777216.0;
}

void main() {
    ivec2 x = ivec2(gl_GlobalInvocationID.xy);
    ivec2 size = imageSize(out_color);
    if (any(greaterThanEqual(x, size))) return;
    vec4 cx = texelFetch(in_color, x, 0);
    vec2 vN = imageLoad(out_neighbor_max, x / pc.tileSize).xy;
    float hN = length(vN);
    if (hN <= 0.5) { // nothing in reach moves by more than half a pixel
        imageStore(out_color, x, cx);
        return;
    }
    float dx = depthAt(x);
    float hx = max(length(halfVelocity(texelFetch(in_velocity, x, 0).xy)), 0.5);
    float jitter = pc.dither * (hash(uvec3(x, pc.frame)) - 0.5);
    float footprint = 2.0 * hN / float(pc.samples);

    vec4 occSum = vec4(0.0), ownSum = cx * 1e-4;
    float occW = 0.0, ownW = 1e-4;
    for (uint i = 0u; i < pc.samples; ++i) {
        float t = -1.0 + (float(i) + 0.5 + jitter) * 2.0 / float(pc.samples);
        ivec2 y = clamp(ivec2(floor(vec2(x) + 0.5 + vN * t)), ivec2(0), size - 1);
        float r = length(vec2(y - x));
        float dy = depthAt(y);
        float hy = max(length(halfVelocity(texelFetch(in_velocity, y, 0).xy)), 0.5);
        vec4 cy = texelFetch(in_color, y, 0);
        float front = clamp((dx - dy) / pc.softZ, 0.0, 1.0);
        float wOcc = front * cylinder(r, hy) * footprint / (2.0 * hy);
        float wOwn = (1.0 - front) * cylinder(r, hx);
        occSum += wOcc * cy;
        occW += wOcc;
        ownSum += wOwn * cy;
        ownW += wOwn;
    }
    float c = min(occW, 1.0);
    vec4 occ = occW > 0.0 ? occSum / occW : cx;
    imageStore(out_color, x, mix(ownSum / ownW, occ, c));
}
