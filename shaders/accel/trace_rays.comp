#version 460
// Traces a buffer of rays against the BVH (core/accel/ray_batch.cpp): closest hit, or any hit.
#extension GL_GOOGLE_include_directive : require
#define VITRINE_BVH_SET 1
#include "accel/bvh.glsl"
#include "accel/trace_rays.h"

layout(local_size_x = 64) in;

layout(set = 0, binding = 0, std430) readonly buffer Rays { GpuRay rays[]; };
layout(set = 0, binding = 1, std430) writeonly buffer Hits { GpuRayHit hits[]; };

void main() {
    uint index = gl_GlobalInvocationID.x + gl_GlobalInvocationID.y * push.rowWidth;
    if (index >= push.rayCount) return;
    GpuRay ray = rays[index];
    GpuRayHit h;
    if (push.anyHit != 0u) {
        bool occluded = bvhTraceAny(ray.origin.xyz, ray.direction.xyz, ray.origin.w, ray.direction.w);
        h.hit = vec4(occluded ? 0.0 : uintBitsToFloat(0x7f800000u), 0.0, 0.0, 0.0);
        h.id = uvec4(occluded ? 0u : VITRINE_BVH_NONE, VITRINE_BVH_NONE, 0u, 0u);
    } else {
        BvhHit hit;
        bool found = bvhTraceClosest(ray.origin.xyz, ray.direction.xyz, ray.origin.w, ray.direction.w, hit);
        h.hit = vec4(found ? hit.t : uintBitsToFloat(0x7f800000u), hit.barycentrics, 0.0);
        h.id = uvec4(hit.triangle, hit.instance, 0u, 0u);
    }
    hits[index] = h;
}
