#pragma once

// The BVH-against-brute-force comparison shared by the CPU (tests/unit/accel) and GPU (tests/gpu) tests.

#include "tests/unit/accel/accel_scenes.hpp"

#include <gtest/gtest.h>

namespace vitrine::accel::test {

inline constexpr float kRelT = 1e-5f;

inline bool closeT(float a, float b) {
    return std::abs(a - b) <= kRelT * std::max(std::abs(a), std::abs(b));
}

// Expects each BVH hit (bvhHits[i] for rays[i]) to be brute force's: the same triangle, by (instance,
// primitive, triangle), at the same t (kRelT relative). A different triangle at the same t counts as a tie
// (a shared edge, a coplanar overlap) when brute force's own test also hits the BVH's triangle at that t
// or the two share a vertex; ties must stay below 1 % of the rays. Stops after 10 failures.
inline void expectSameHits(const SceneBvh& bvh, const WorldTriangles& w, const std::vector<Ray>& rays,
                           const std::vector<Hit>& bvhHits, size_t& hits, size_t& ties) {
    ASSERT_EQ(rays.size(), bvhHits.size());
    std::map<std::tuple<uint32_t, uint32_t, uint32_t>, uint32_t> indexOf;
    for (uint32_t i = 0; i < w.refs.size(); ++i)
        indexOf[{w.refs[i].instance, w.refs[i].primitive, w.refs[i].triangle}] = i;
    size_t failures = 0;
    hits = ties = 0;
    for (size_t i = 0; i < rays.size() && failures < 10; ++i) {
        const Ray& r = rays[i];
        const Hit& h = bvhHits[i];
        BruteHit b = bruteForce(w, r);
        if (h.valid() != b.valid()) {
            ++failures;
            ADD_FAILURE() << "ray " << i << ": BVH " << (h.valid() ? "hit" : "missed") << " (t " << h.t
                          << "), brute force " << (b.valid() ? "hit" : "missed") << " (t " << b.t << ")";
            continue;
        }
        if (!b.valid()) continue;
        ++hits;
        ASSERT_LT(h.triangle, bvh.arrays().refs.size()) << "ray " << i;
        GpuBvhTriangleRef ref = bvh.arrays().refs[h.triangle];
        ref.instance = h.instance;
        const bool sameT = closeT(h.t, b.t);
        if (sameT && sameSource(ref, w.refs[b.index])) continue;
        auto it = indexOf.find({ref.instance, ref.primitive, ref.triangle});
        bool tie = false;
        if (sameT && it != indexOf.end()) {
            const glm::vec3* tb = &w.v[3 * b.index];
            const glm::vec3* th = &w.v[3 * it->second];
            bool sharesVertex = false;
            for (int x = 0; x < 3; ++x)
                for (int y = 0; y < 3; ++y)
                    sharesVertex = sharesVertex || tb[x] == th[y];
            TraversalRay tr(r.origin, r.direction);
            float t;
            glm::vec2 uv;
            const bool alsoHit =
                tr.intersectTriangle(th[0], th[1], th[2], r.tmin, std::numeric_limits<float>::infinity(), t, uv) &&
                closeT(t, b.t);
            tie = alsoHit || sharesVertex;
        }
        if (tie) {
            ++ties;
        } else {
            ++failures;
            ADD_FAILURE() << "ray " << i << ": BVH hit instance " << ref.instance << " primitive " << ref.primitive
                          << " triangle " << ref.triangle << " at t " << h.t << "; brute force instance "
                          << w.refs[b.index].instance << " primitive " << w.refs[b.index].primitive << " triangle "
                          << w.refs[b.index].triangle << " at t " << b.t;
        }
    }
    EXPECT_LE(ties, rays.size() / 100) << "too many ties";
}

} // namespace vitrine::accel::test
