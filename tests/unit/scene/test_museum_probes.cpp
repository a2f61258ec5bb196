// The museum's reflection probes: as many as the demo's order of magnitude, covering every room, alcove and
// doorway, nested volumes outranking their room, capture points inside their own volume and clear of every
// triangle of the building. The floor plan used here is written out from MUSEUM_SPEC's hall and the museum's
// documented layout (museum.hpp), not taken from the builder.

#include "core/scene/museum.hpp"
#include "core/scene/probes.hpp"

#include "test_util.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <memory>
#include <set>

namespace vitrine::scene {
namespace {

class MuseumProbes : public ::testing::Test {
protected:
    static void SetUpTestSuite() {
        MuseumOptions options;
        options.textureSize = 16; // textures do not matter here
        sMuseum = std::make_unique<Scene>(buildMuseum(options));
    }
    static void TearDownTestSuite() { sMuseum.reset(); }
    static const Scene& museum() { return *sMuseum; }

    static inline std::unique_ptr<Scene> sMuseum;
};

float weight(const ReflectionProbe& p, const glm::vec3& x) {
    return fadeWeight(p, x) * std::pow(16.0f, float(p.priority));
}

float volume(const ReflectionProbe& p) {
    return p.shape == ProbeShape::Sphere ? 4.18879f * std::pow(p.halfExtents.x, 3.0f)
                                         : 8.0f * p.halfExtents.x * p.halfExtents.y * p.halfExtents.z;
}

// The doorways between the hall and the galleries: 3 m wide, 3.8 m high, through the 0.4 m wall and the
// gallery's 0.4 m lining in front of it.
const Aabb kDoorways[] = {Aabb{{-16.8f, 0.0f, -1.45f}, {-15.95f, 3.75f, 1.45f}},
                          Aabb{{15.95f, 0.0f, -1.45f}, {16.8f, 3.75f, 1.45f}},
                          Aabb{{-1.45f, 0.0f, 6.95f}, {1.45f, 3.75f, 7.8f}}};

// The hall's aisle bays: between the arcades' columns (x = −14 + 4k, z = ±4.6) and the side walls (z = ±7).
std::vector<glm::vec3> bayCentres() {
    std::vector<glm::vec3> c;
    for (int k = 0; k < 7; ++k) {
        for (float z : {5.8f, -5.8f})
            c.push_back({-12.0f + 4.0f * k, 1.5f, z});
    }
    return c;
}

TEST_F(MuseumProbes, AsManyAsTheDemoOrderOfMagnitudeWithUniqueNames) {
    const Scene& s = museum();
    EXPECT_GE(s.probes.size(), 30u);
    EXPECT_LE(s.probes.size(), 90u);
    std::set<std::string> names;
    std::map<std::string, int> perRoom;
    for (const ReflectionProbe& p : s.probes) {
        names.insert(p.name);
        perRoom[p.name.substr(0, p.name.rfind('_'))]++;
    }
    EXPECT_EQ(names.size(), s.probes.size());
    std::string breakdown;
    for (const auto& [room, n] : perRoom)
        breakdown += " " + room + ": " + std::to_string(n);
    std::printf("museum probes: %zu,%s\n", s.probes.size(), breakdown.c_str());
    // One or more per room and per alcove: every room of Scene::rooms holds capture points.
    for (const Room& r : s.rooms) {
        EXPECT_TRUE(std::any_of(s.probes.begin(), s.probes.end(),
                                [&](const ReflectionProbe& p) { return r.bounds.contains(p.position); }))
            << r.name;
    }
}

TEST_F(MuseumProbes, EveryRoomAlcoveAndDoorwayIsCovered) {
    const Scene& s = museum();
    // Every point of every room and doorway (0.5 m grid, 2 cm inside the walls, floor to ceiling) has a positive
    // total weight: no indoor pixel falls back to the sky.
    std::vector<Aabb> spaces;
    for (const Room& r : s.rooms)
        spaces.push_back(r.bounds);
    spaces.insert(spaces.end(), std::begin(kDoorways), std::end(kDoorways));
    size_t points = 0, floorPoints = 0;
    double overlaps = 0.0, floorOverlaps = 0.0;
    for (const Aabb& space : spaces) {
        glm::vec3 lo = space.min + 0.02f, hi = space.max - 0.02f;
        glm::ivec3 n = glm::max(glm::ivec3((hi - lo) / 0.5f), glm::ivec3(1));
        for (int i = 0; i <= n.x; ++i) {
            for (int j = 0; j <= n.y; ++j) {
                for (int k = 0; k <= n.z; ++k) {
                    glm::vec3 x = lo + (hi - lo) * glm::vec3(i, j, k) / glm::vec3(n);
                    float total = 0.0f;
                    int inside = 0;
                    for (const ReflectionProbe& p : s.probes) {
                        total += weight(p, x);
                        inside += insideInfluence(p, x) ? 1 : 0;
                    }
                    ASSERT_GT(total, 0.0f) << "(" << x.x << ", " << x.y << ", " << x.z << ") has no probe";
                    ++points;
                    overlaps += inside;
                    if (j == 0) ++floorPoints, floorOverlaps += inside;
                }
            }
        }
    }
    // The demo aimed at ~1.5 probes per shaded pixel: overlaps are bands, not whole rooms.
    double mean = overlaps / points, floorMean = floorOverlaps / floorPoints;
    std::printf("volumes containing a point: %.2f on average over %zu points of the rooms, %.2f on the floors\n", mean,
                points, floorMean);
    EXPECT_LT(mean, 2.0);
    EXPECT_LT(floorMean, 2.0);

    // Room and alcove centres: inside a volume, and an alcove's own (small, higher priority) probe dominates there.
    for (const Room& r : s.rooms) {
        EXPECT_TRUE(std::any_of(s.probes.begin(), s.probes.end(),
                                [&](const ReflectionProbe& p) { return insideInfluence(p, r.bounds.center()); }))
            << r.name;
    }
    for (const glm::vec3& c : bayCentres()) {
        const ReflectionProbe* best = nullptr;
        float total = 0.0f;
        for (const ReflectionProbe& p : s.probes) {
            total += weight(p, c);
            if (!best || weight(p, c) > weight(*best, c)) best = &p;
        }
        ASSERT_NE(best, nullptr);
        EXPECT_LT(volume(*best), 200.0f) << best->name << " at the bay centre " << c.x << ", " << c.z;
        EXPECT_GT(weight(*best, c), 0.9f * total) << best->name;
        EXPECT_LT(glm::distance(glm::vec2(best->position.x, best->position.z), glm::vec2(c.x, c.z)), 1.0f)
            << best->name << " captures its own bay";
    }
    for (const Aabb& door : kDoorways) {
        const ReflectionProbe* best = nullptr;
        for (const ReflectionProbe& p : s.probes)
            if (!best || weight(p, door.center()) > weight(*best, door.center())) best = &p;
        EXPECT_TRUE(door.contains(best->position)) << best->name << ": a doorway's own probe dominates it";
    }
}

// Where a small volume (an aisle bay, a doorway) overlaps a much larger one (a slice of the nave, a gallery's
// quarter, the bay a door opens into), the small one has the higher priority and so wins inside its own fade.
TEST_F(MuseumProbes, SmallVolumesOutrankTheLargerOnesTheyOverlap) {
    const Scene& s = museum();
    auto overlap = [](const ReflectionProbe& a, const ReflectionProbe& b) {
        const int n = 8;
        for (int i = 0; i < n; ++i) {
            for (int j = 0; j < n; ++j) {
                for (int k = 0; k < n; ++k) {
                    glm::vec3 local = (glm::vec3(i, j, k) + 0.5f) / float(n) * 2.0f - 1.0f;
                    glm::vec3 x = a.center + a.rotation * (local * a.halfExtents);
                    if (influenceDepth(b, x) > 0.0f) return true;
                }
            }
        }
        return false;
    };
    int nested = 0;
    for (const ReflectionProbe& a : s.probes) {
        ASSERT_EQ(a.shape, ProbeShape::Box) << a.name;
        for (const ReflectionProbe& b : s.probes) {
            if (&a == &b || volume(a) > 0.5f * volume(b) || !overlap(a, b)) continue;
            ++nested;
            EXPECT_GT(a.priority, b.priority) << a.name << " overlaps the larger " << b.name;
        }
        EXPECT_GE(a.fade, 0.3f) << a.name;
        EXPECT_LE(a.fade, 1.0f) << a.name;
    }
    EXPECT_GE(nested, 18) << "each aisle bay overlaps at least one slice of the nave";
}

float pointTriangleDistance(const glm::vec3& p, const glm::vec3& a, const glm::vec3& b, const glm::vec3& c) {
    // Ericson, Real-Time Collision Detection 5.1.5: the closest point by Voronoi region.
    glm::vec3 ab = b - a, ac = c - a, ap = p - a;
    float d1 = glm::dot(ab, ap), d2 = glm::dot(ac, ap);
    if (d1 <= 0.0f && d2 <= 0.0f) return glm::distance(p, a);
    glm::vec3 bp = p - b;
    float d3 = glm::dot(ab, bp), d4 = glm::dot(ac, bp);
    if (d3 >= 0.0f && d4 <= d3) return glm::distance(p, b);
    float vc = d1 * d4 - d3 * d2;
    if (vc <= 0.0f && d1 >= 0.0f && d3 <= 0.0f) return glm::distance(p, a + ab * (d1 / (d1 - d3)));
    glm::vec3 cp = p - c;
    float d5 = glm::dot(ab, cp), d6 = glm::dot(ac, cp);
    if (d6 >= 0.0f && d5 <= d6) return glm::distance(p, c);
    float vb = d5 * d2 - d1 * d6;
    if (vb <= 0.0f && d2 >= 0.0f && d6 <= 0.0f) return glm::distance(p, a + ac * (d2 / (d2 - d6)));
    float va = d3 * d6 - d5 * d4;
    if (va <= 0.0f && d4 - d3 >= 0.0f && d5 - d6 >= 0.0f)
        return glm::distance(p, b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6))));
    float denom = 1.0f / (va + vb + vc);
    return glm::distance(p, a + ab * (vb * denom) + ac * (vc * denom));
}

TEST_F(MuseumProbes, CapturePointsAreInsideTheirVolumeIndoorsAndClearOfGeometry) {
    const Scene& s = museum();
    const float clearance = 0.3f; // metres to the nearest triangle: not in a wall, column, pedestal or glass case
    ScenePose pose = s.evaluate(0.0);
    for (const ReflectionProbe& p : s.probes) {
        EXPECT_TRUE(insideInfluence(p, p.position)) << p.name;
        EXPECT_GT(influenceDepth(p, p.position), 0.1f) << p.name << ": well inside, not on the border";
        bool indoors = std::any_of(s.rooms.begin(), s.rooms.end(),
                                   [&](const Room& r) { return r.bounds.contains(p.position); }) ||
                       std::any_of(std::begin(kDoorways), std::end(kDoorways),
                                   [&](const Aabb& d) { return d.contains(p.position); });
        EXPECT_TRUE(indoors) << p.name;
        float nearest = 1e30f;
        std::string what;
        for (size_t i = 0; i < s.instances.size(); ++i) {
            const Mesh& mesh = s.meshes[s.instances[i].mesh];
            const glm::mat4& w = pose.instanceWorld[i];
            for (uint32_t k = 0; k < mesh.primitiveCount; ++k) {
                const Primitive& prim = s.primitives[mesh.firstPrimitive + k];
                Aabb b = prim.bounds.transformed(w);
                glm::vec3 gap = glm::max(glm::max(b.min - p.position, p.position - b.max), glm::vec3(0.0f));
                if (glm::length(gap) >= nearest) continue;
                for (uint32_t t = 0; t < prim.indexCount; t += 3) {
                    glm::vec3 v[3];
                    for (int j = 0; j < 3; ++j) {
                        const Vertex& x = s.vertices[prim.vertexOffset + s.indices[prim.firstIndex + t + j]];
                        v[j] = glm::vec3(w * glm::vec4(x.position, 1.0f));
                    }
                    float d = pointTriangleDistance(p.position, v[0], v[1], v[2]);
                    if (d < nearest) nearest = d, what = mesh.name;
                }
            }
        }
        EXPECT_GT(nearest, clearance) << p.name << " is " << nearest << " m from " << what;
    }
}

TEST_F(MuseumProbes, PointTriangleDistanceMatchesHandComputedCases) {
    const glm::vec3 a(0, 0, 0), b(2, 0, 0), c(0, 2, 0);
    EXPECT_NEAR(pointTriangleDistance({0.5f, 0.5f, 3.0f}, a, b, c), 3.0f, 1e-6f); // over the face
    EXPECT_NEAR(pointTriangleDistance({-1.0f, -1.0f, 0.0f}, a, b, c), std::sqrt(2.0f), 1e-6f); // vertex a
    EXPECT_NEAR(pointTriangleDistance({1.0f, -2.0f, 0.0f}, a, b, c), 2.0f, 1e-6f);  // edge ab
    EXPECT_NEAR(pointTriangleDistance({2.0f, 2.0f, 0.0f}, a, b, c), std::sqrt(2.0f), 1e-6f); // edge bc
}

} // namespace
} // namespace vitrine::scene
