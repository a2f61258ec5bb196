// Ray traversal of the scene's BVH (core/accel/gpu_bvh.hpp; layouts in accel/bvh.h). Include after
// #version; define VITRINE_BVH_SET (default 1: the scene's set is 0) before including. Opaque geometry:
// every triangle counts as a hit, whatever its material's alpha.
//
//   bool bvhTraceClosest(vec3 origin, vec3 direction, float tmin, float tmax, out BvhHit hit);
//   bool bvhTraceAny(vec3 origin, vec3 direction, float tmin, float tmax);   // shadow rays
//
// Hits have t in (tmin, tmax), in units of |direction| (it need not be normalised). The CPU mirror,
// line for line, is core/accel/traverse.cpp.
#ifndef ACCEL_BVH_GLSL
#define ACCEL_BVH_GLSL
#extension GL_GOOGLE_include_directive : require
#include "accel/bvh.h"

#ifndef VITRINE_BVH_SET
#define VITRINE_BVH_SET 1
#endif

layout(set = VITRINE_BVH_SET, binding = 0, std430) readonly buffer BvhNodes { GpuBvhNode bvhNodes[]; };
layout(set = VITRINE_BVH_SET, binding = 1, std430) readonly buffer BvhTriangles { GpuBvhTriangle bvhTriangles[]; };
layout(set = VITRINE_BVH_SET, binding = 2, std430) readonly buffer BvhRefs { GpuBvhTriangleRef bvhRefs[]; };
layout(set = VITRINE_BVH_SET, binding = 3, std430) readonly buffer BvhPrimitives { GpuBvhPrimitive bvhPrimitives[]; };
layout(set = VITRINE_BVH_SET, binding = 4, std430) readonly buffer BvhTop {
    uvec4 bvhTopInfo; // x: number of entries
    GpuBvhInstance bvhInstances[];
};

struct BvhHit {
    float t;
    vec2 barycentrics; // of v1 and v2: p = (1 - x - y) v0 + x v1 + y v2 (bvhTriangles[triangle], object space)
    uint triangle;     // into bvhTriangles / bvhRefs; VITRINE_BVH_NONE: no hit
    uint instance;     // scene instance (the scene's instance buffer: world and normal matrices)
};

// A ray prepared for one space (world, or a dynamic instance's object space).
struct BvhRay {
    vec3 origin;
    vec3 invDirection; // for the box test; zero components replaced by tiny ones
    ivec3 k;           // watertight test: the axis permutation, z = the direction's largest axis
    vec3 shear;        // Sx, Sy, Sz
};

// 1 + 2 gamma(3) (Ize 2013): widening the exit distance by this covers the rounding of the slab test.
const float kBvhRobustExit = 1.0000004;

BvhRay bvhMakeRay(vec3 origin, vec3 direction) {
    BvhRay r;
    r.origin = origin;
    vec3 d = mix(direction, mix(vec3(1e-30), vec3(-1e-30), lessThan(direction, vec3(0.0))), lessThan(abs(direction), vec3(1e-30)));
    r.invDirection = 1.0 / d;
    // The axis where the direction is largest becomes z; x and y are swapped when it points down z, which
    // keeps the triangles' winding (the sign of U, V, W) unchanged.
    vec3 ad = abs(direction);
    int kz = ad.x > ad.y ? (ad.x > ad.z ? 0 : 2) : (ad.y > ad.z ? 1 : 2);
    int kx = (kz + 1) % 3;
    int ky = (kx + 1) % 3;
    if (direction[kz] < 0.0) {
        int s = kx;
        kx = ky;
        ky = s;
    }
    r.k = ivec3(kx, ky, kz);
    r.shear = vec3(direction[kx] / direction[kz], direction[ky] / direction[kz], 1.0 / direction[kz]);
    return r;
}

// Woop, Benthin and Wald 2013, "Watertight ray/triangle intersection" (JCGT 2(1)), double sided.
bool bvhIntersectTriangle(BvhRay r, vec3 v0, vec3 v1, vec3 v2, float tmin, float tmax, out float t, out vec2 barycentrics) {
    vec3 a = v0 - r.origin, b = v1 - r.origin, c = v2 - r.origin;
    // Shear and scale so the ray runs along +z from the origin; each vertex on its own, so a vertex shared
    // by two triangles lands on the same point in both.
    float ax = a[r.k.x] - r.shear.x * a[r.k.z], ay = a[r.k.y] - r.shear.y * a[r.k.z];
    float bx = b[r.k.x] - r.shear.x * b[r.k.z], by = b[r.k.y] - r.shear.y * b[r.k.z];
    float cx = c[r.k.x] - r.shear.x * c[r.k.z], cy = c[r.k.y] - r.shear.y * c[r.k.z];
    // 2D edge functions. An edge shared with a neighbour has exactly the negation of the neighbour's value
    // (the same two products, swapped): `precise` forbids fusing one product into an FMA, which would
    // round the two triangles' values differently and open cracks.
    precise float u = cx * by - cy * bx;
    precise float v = ax * cy - ay * cx;
    precise float w = bx * ay - by * ax;
    t = 0.0;
    barycentrics = vec2(0.0);
    if ((u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0)) return false;
    float det = u + v + w;
    if (det == 0.0) return false;
    float az = r.shear.z * a[r.k.z], bz = r.shear.z * b[r.k.z], cz = r.shear.z * c[r.k.z];
    float inv = 1.0 / det;
    float tt = (u * az + v * bz + w * cz) * inv;
    if (!(tt > tmin && tt < tmax)) return false;
    t = tt;
    barycentrics = vec2(v * inv, w * inv);
    return true;
}

// Whether the ray meets the box within [tmin, tmax], erring toward a hit (Ize 2013); tEntry: where.
bool bvhIntersectBox(BvhRay r, vec3 lo, vec3 hi, float tmin, float tmax, out float tEntry) {
    vec3 t0 = (lo - r.origin) * r.invDirection, t1 = (hi - r.origin) * r.invDirection;
    vec3 tn = min(t0, t1), tf = max(t0, t1);
    float enter = max(max(tn.x, tn.y), max(tn.z, tmin));
    float exit = min(min(min(tf.x, tf.y), tf.z) * kBvhRobustExit, tmax);
    tEntry = enter;
    return enter <= exit;
}

// One bottom level from root; hit.t is the closest distance so far and shrinks as hits are found.
bool bvhTraverseBottom(uint root, BvhRay r, float tmin, bool anyHit, inout BvhHit hit) {
    uint stack[VITRINE_BVH_STACK_SIZE];
    float stackT[VITRINE_BVH_STACK_SIZE];
    int sp = 0;
    uint node = root;
    bool found = false;
    while (true) {
        GpuBvhNode n = bvhNodes[node];
        uint linkA = floatBitsToUint(n.aMin.w), countA = floatBitsToUint(n.aMax.w);
        uint linkB = floatBitsToUint(n.bMin.w), countB = floatBitsToUint(n.bMax.w);
        float ta = 0.0, tb = 0.0;
        bool hitA = linkA != VITRINE_BVH_NONE && bvhIntersectBox(r, n.aMin.xyz, n.aMax.xyz, tmin, hit.t, ta);
        bool hitB = linkB != VITRINE_BVH_NONE && bvhIntersectBox(r, n.bMin.xyz, n.bMax.xyz, tmin, hit.t, tb);
        for (int side = 0; side < 2; ++side) {
            bool leafHit = side == 0 ? hitA && countA > 0u : hitB && countB > 0u;
            if (!leafHit) continue;
            uint first = side == 0 ? linkA : linkB, count = side == 0 ? countA : countB;
            for (uint i = first; i < first + count; ++i) {
                GpuBvhTriangle tri = bvhTriangles[i];
                float t;
                vec2 uv;
                if (bvhIntersectTriangle(r, tri.v0.xyz, tri.v1.xyz, tri.v2.xyz, tmin, hit.t, t, uv)) {
                    hit.t = t;
                    hit.barycentrics = uv;
                    hit.triangle = i;
                    found = true;
                    if (anyHit) return true;
                }
            }
            if (side == 0) hitA = false;
            else hitB = false;
        }
        if (hitA && hitB) {
            bool aFirst = ta <= tb;
            stack[sp] = aFirst ? linkB : linkA;
            stackT[sp] = aFirst ? tb : ta;
            ++sp;
            node = aFirst ? linkA : linkB;
        } else if (hitA) {
            node = linkA;
        } else if (hitB) {
            node = linkB;
        } else {
            // Pop the nearest pending subtree that may still hold something closer than the best hit.
            do {
                if (sp == 0) return found;
                --sp;
            } while (stackT[sp] > hit.t);
            node = stack[sp];
        }
    }
    return found;
}

vec3 bvhToObject(GpuBvhInstance m, vec4 h) {
    return vec3(dot(m.worldToObject0, h), dot(m.worldToObject1, h), dot(m.worldToObject2, h));
}

bool bvhTrace(vec3 origin, vec3 direction, float tmin, float tmax, bool anyHit, out BvhHit hit) {
    hit.t = tmax;
    hit.barycentrics = vec2(0.0);
    hit.triangle = VITRINE_BVH_NONE;
    hit.instance = VITRINE_BVH_NONE;
    BvhRay world = bvhMakeRay(origin, direction);
    uint count = bvhTopInfo.x;
    for (uint e = 0u; e < count; ++e) {
        GpuBvhInstance inst = bvhInstances[e];
        float entry;
        if (!bvhIntersectBox(world, inst.boundsMin.xyz, inst.boundsMax.xyz, tmin, hit.t, entry)) continue;
        BvhRay local = bvhMakeRay(bvhToObject(inst, vec4(origin, 1.0)), bvhToObject(inst, vec4(direction, 0.0)));
        if (bvhTraverseBottom(inst.info.x, local, tmin, anyHit, hit)) {
            hit.instance = inst.info.y != VITRINE_BVH_NONE ? inst.info.y : bvhRefs[hit.triangle].instance;
            if (anyHit) break;
        }
    }
    return hit.triangle != VITRINE_BVH_NONE;
}

// The closest hit with t in (tmin, tmax).
bool bvhTraceClosest(vec3 origin, vec3 direction, float tmin, float tmax, out BvhHit hit) {
    return bvhTrace(origin, direction, tmin, tmax, false, hit);
}

// Whether anything is hit with t in (tmin, tmax).
bool bvhTraceAny(vec3 origin, vec3 direction, float tmin, float tmax) {
    BvhHit hit;
    return bvhTrace(origin, direction, tmin, tmax, true, hit);
}

#endif
