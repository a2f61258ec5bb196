#pragma once

// Ray traversal on the CPU: the mirror of shaders/accel/bvh.glsl, line for line, so tests can check the
// GPU against it and CPU bakers can trace the same structure. Watertight ray/triangle test of Woop,
// Benthin and Wald (2013, "Watertight ray/triangle intersection", JCGT 2(1)), double sided; robust box
// test of Ize (2013, "Robust BVH ray traversal", JCGT 2(2)).

#include "core/accel/bvh.hpp"
#include "shaders/accel/bvh.h"

#include <limits>
#include <span>

namespace vitrine::accel {

using gpu_types::GpuBvhInstance;

struct Ray {
    glm::vec3 origin{0.0f};
    float tmin = 0.0f;
    glm::vec3 direction{0.0f, 0.0f, -1.0f}; // need not be unit length: t is in its units
    float tmax = std::numeric_limits<float>::infinity();
};

struct Hit {
    float t = std::numeric_limits<float>::infinity();
    glm::vec2 barycentrics{0.0f}; // of v1 and v2: p = (1 - x - y) v0 + x v1 + y v2
    uint32_t triangle = kNone;    // index into the BVH's triangle (and ref) arrays
    uint32_t instance = kNone;    // scene instance
    bool valid() const { return triangle != kNone; }
};

// A ray prepared for one space (world, or a dynamic instance's object space): the permutation and shear
// of the watertight test and the reciprocal direction of the box test.
class TraversalRay {
public:
    TraversalRay(const glm::vec3& origin, const glm::vec3& direction);

    // t in (tmin, tmax) of the hit with triangle (v0, v1, v2), either side. Edges shared by two triangles
    // (the same vertex values) are never missed by both.
    bool intersectTriangle(const glm::vec3& v0, const glm::vec3& v1, const glm::vec3& v2, float tmin, float tmax,
                           float& t, glm::vec2& barycentrics) const;
    // Whether the ray meets the box within [tmin, tmax] (conservatively: float rounding errs toward a hit);
    // tEntry: where it enters.
    bool intersectBox(const glm::vec3& lo, const glm::vec3& hi, float tmin, float tmax, float& tEntry) const;

    const glm::vec3& origin() const { return mOrigin; }
    const glm::vec3& direction() const { return mDirection; }

private:
    glm::vec3 mOrigin, mDirection, mInvDirection;
    int mKx, mKy, mKz;
    glm::vec3 mShear; // Sx, Sy, Sz
};

// The ray's origin and direction in a top-level entry's object space (the static level: unchanged).
glm::vec3 toObjectPoint(const GpuBvhInstance& instance, const glm::vec3& p);
glm::vec3 toObjectVector(const GpuBvhInstance& instance, const glm::vec3& v);

// The closest hit over all entries of top (SceneBvh::topLevel) with t in (ray.tmin, ray.tmax).
Hit traceClosest(const BvhArrays& bvh, std::span<const GpuBvhInstance> top, const Ray& ray);
// Whether anything is hit with t in (ray.tmin, ray.tmax): shadow rays.
bool traceAny(const BvhArrays& bvh, std::span<const GpuBvhInstance> top, const Ray& ray);

} // namespace vitrine::accel
