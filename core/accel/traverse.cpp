#include "core/accel/traverse.hpp"

#include <algorithm>
#include <cmath>

namespace vitrine::accel {

namespace {

// 1 + 2 gamma(3) (Ize 2013): widening the exit distance by this covers the rounding of the slab test.
constexpr float kRobustExit = 1.0000004f;

// A bottom level from root; hit.t is the current closest distance and shrinks as hits are found.
bool traverseBottom(const BvhArrays& bvh, uint32_t root, const TraversalRay& ray, float tmin, bool anyHit, Hit& hit) {
    uint32_t stack[kMaxDepth];
    float stackT[kMaxDepth];
    int sp = 0;
    uint32_t node = root;
    bool found = false;
    auto leaf = [&](const BvhChild& c) {
        for (uint32_t i = c.link; i < c.link + c.count; ++i) {
            const GpuBvhTriangle& tri = bvh.triangles[i];
            float t;
            glm::vec2 uv;
            if (ray.intersectTriangle(glm::vec3(tri.v0), glm::vec3(tri.v1), glm::vec3(tri.v2), tmin, hit.t, t, uv)) {
                hit.t = t;
                hit.barycentrics = uv;
                hit.triangle = i;
                found = true;
                if (anyHit) return true;
            }
        }
        return false;
    };
    while (true) {
        const GpuBvhNode& n = bvh.nodes[node];
        const BvhChild a = childOf(n, 0), b = childOf(n, 1);
        float ta = 0.0f, tb = 0.0f;
        bool hitA = !a.absent() && ray.intersectBox(a.box.min, a.box.max, tmin, hit.t, ta);
        bool hitB = !b.absent() && ray.intersectBox(b.box.min, b.box.max, tmin, hit.t, tb);
        if (hitA && a.leaf()) {
            if (leaf(a)) return true;
            hitA = false;
        }
        if (hitB && b.leaf()) {
            if (leaf(b)) return true;
            hitB = false;
        }
        if (hitA && hitB) {
            const bool aFirst = ta <= tb;
            stack[sp] = aFirst ? b.link : a.link;
            stackT[sp] = aFirst ? tb : ta;
            ++sp;
            node = aFirst ? a.link : b.link;
        } else if (hitA) {
            node = a.link;
        } else if (hitB) {
            node = b.link;
        } else {
            // Pop the nearest pending subtree that may still hold something closer than the best hit.
            do {
                if (sp == 0) return found;
                --sp;
            } while (stackT[sp] > hit.t);
            node = stack[sp];
        }
    }
}

Hit trace(const BvhArrays& bvh, std::span<const GpuBvhInstance> top, const Ray& ray, bool anyHit) {
    Hit hit;
    hit.t = ray.tmax;
    const TraversalRay world(ray.origin, ray.direction);
    for (const GpuBvhInstance& instance : top) {
        float entry;
        if (!world.intersectBox(glm::vec3(instance.boundsMin), glm::vec3(instance.boundsMax), ray.tmin, hit.t, entry))
            continue;
        const TraversalRay local(toObjectPoint(instance, ray.origin), toObjectVector(instance, ray.direction));
        if (traverseBottom(bvh, instance.info.x, local, ray.tmin, anyHit, hit)) {
            hit.instance = instance.info.y != kNone ? instance.info.y : bvh.refs[hit.triangle].instance;
            if (anyHit) break;
        }
    }
    if (!hit.valid()) hit.t = std::numeric_limits<float>::infinity();
    return hit;
}

} // namespace

TraversalRay::TraversalRay(const glm::vec3& origin, const glm::vec3& direction)
    : mOrigin(origin), mDirection(direction) {
    for (int i = 0; i < 3; ++i) {
        // A zero component would make 0 * inf = NaN in the slab test; a tiny one gives huge, finite distances.
        float d = std::abs(direction[i]) < 1e-30f ? (direction[i] >= 0.0f ? 1e-30f : -1e-30f) : direction[i];
        mInvDirection[i] = 1.0f / d;
    }
    // The axis where the direction is largest becomes z; x and y are swapped when it points down z, which
    // keeps the triangles' winding (the sign of U, V, W) unchanged.
    glm::vec3 ad = glm::abs(direction);
    mKz = ad.x > ad.y ? (ad.x > ad.z ? 0 : 2) : (ad.y > ad.z ? 1 : 2);
    mKx = (mKz + 1) % 3;
    mKy = (mKx + 1) % 3;
    if (direction[mKz] < 0.0f) std::swap(mKx, mKy);
    mShear = glm::vec3(direction[mKx] / direction[mKz], direction[mKy] / direction[mKz], 1.0f / direction[mKz]);
}

bool TraversalRay::intersectTriangle(const glm::vec3& v0, const glm::vec3& v1, const glm::vec3& v2, float tmin,
                                     float tmax, float& t, glm::vec2& barycentrics) const {
    const glm::vec3 a = v0 - mOrigin, b = v1 - mOrigin, c = v2 - mOrigin;
    // Shear and scale so the ray runs along +z from the origin; each vertex is transformed on its own, so
    // a vertex shared by two triangles lands on the same point in both.
    const float ax = a[mKx] - mShear.x * a[mKz], ay = a[mKy] - mShear.y * a[mKz];
    const float bx = b[mKx] - mShear.x * b[mKz], by = b[mKy] - mShear.y * b[mKz];
    const float cx = c[mKx] - mShear.x * c[mKz], cy = c[mKy] - mShear.y * c[mKz];
    // 2D edge functions: the one of an edge shared with a neighbour is exactly the negation of the
    // neighbour's (same products, swapped), so no ray through the edge can be rejected by both.
    const float u = cx * by - cy * bx;
    const float v = ax * cy - ay * cx;
    const float w = bx * ay - by * ax;
    if ((u < 0.0f || v < 0.0f || w < 0.0f) && (u > 0.0f || v > 0.0f || w > 0.0f)) return false;
    const float det = u + v + w;
    if (det == 0.0f) return false;
    const float az = mShear.z * a[mKz], bz = mShear.z * b[mKz], cz = mShear.z * c[mKz];
    const float inv = 1.0f / det;
    const float tt = (u * az + v * bz + w * cz) * inv;
    if (!(tt > tmin && tt < tmax)) return false;
    t = tt;
    barycentrics = glm::vec2(v * inv, w * inv);
    return true;
}

bool TraversalRay::intersectBox(const glm::vec3& lo, const glm::vec3& hi, float tmin, float tmax, float& tEntry) const {
    const glm::vec3 t0 = (lo - mOrigin) * mInvDirection, t1 = (hi - mOrigin) * mInvDirection;
    const glm::vec3 tn = glm::min(t0, t1), tf = glm::max(t0, t1);
    const float enter = std::max(std::max(tn.x, tn.y), std::max(tn.z, tmin));
    const float exit = std::min(std::min(std::min(tf.x, tf.y), tf.z) * kRobustExit, tmax);
    tEntry = enter;
    return enter <= exit;
}

glm::vec3 toObjectPoint(const GpuBvhInstance& m, const glm::vec3& p) {
    const glm::vec4 h(p, 1.0f);
    return {glm::dot(m.worldToObject0, h), glm::dot(m.worldToObject1, h), glm::dot(m.worldToObject2, h)};
}

glm::vec3 toObjectVector(const GpuBvhInstance& m, const glm::vec3& v) {
    const glm::vec4 h(v, 0.0f);
    return {glm::dot(m.worldToObject0, h), glm::dot(m.worldToObject1, h), glm::dot(m.worldToObject2, h)};
}

Hit traceClosest(const BvhArrays& bvh, std::span<const GpuBvhInstance> top, const Ray& ray) {
    return trace(bvh, top, ray, false);
}

bool traceAny(const BvhArrays& bvh, std::span<const GpuBvhInstance> top, const Ray& ray) {
    return trace(bvh, top, ray, true).valid();
}

} // namespace vitrine::accel
