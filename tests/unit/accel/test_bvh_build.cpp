// core/accel: the binned-SAH build. Structural invariants that traversal relies on, checked on a random
// soup, the museum (static level and the robot's parts) and inputs that defeat SAH.
#include "tests/unit/accel/accel_scenes.hpp"

#include "core/scene/deformation.hpp"
#include "core/scene/museum.hpp"

#include <gtest/gtest.h>

#include <functional>
#include <set>

namespace vitrine::accel {
namespace {

using namespace test;

// Walks one bottom level from its root and checks: every node of the level reached exactly once; each
// inner child's two boxes inside the box its parent stores for it; each leaf's box holding its triangles;
// every triangle of the level in exactly one leaf; depth within the traversal stack; an absent child only
// at the root of a level that is a single leaf.
void checkLevel(const BvhArrays& a, const BvhBottomLevel& level) {
    std::vector<int> nodeSeen(level.nodeCount, 0), triSeen(level.triangleCount, 0);
    struct Item {
        uint32_t node;
        BvhBox box; // what the parent stores for this node
        uint32_t depth;
    };
    std::vector<Item> stack{{level.root, level.bounds, 1}};
    uint32_t maxDepth = 0;
    while (!stack.empty()) {
        Item it = stack.back();
        stack.pop_back();
        ASSERT_GE(it.node, level.firstNode);
        ASSERT_LT(it.node, level.firstNode + level.nodeCount);
        ++nodeSeen[it.node - level.firstNode];
        maxDepth = std::max(maxDepth, it.depth);
        for (int c = 0; c < 2; ++c) {
            BvhChild child = childOf(a.nodes[it.node], c);
            if (child.absent()) {
                // Only a level that is one leaf (or nothing) has a root with an empty slot.
                EXPECT_EQ(it.node, level.root) << "an absent child below the root";
                BvhChild other = childOf(a.nodes[it.node], 1 - c);
                EXPECT_TRUE(other.absent() ? level.triangleCount == 0 : other.count == level.triangleCount);
                continue;
            }
            EXPECT_TRUE(it.box.contains(child.box))
                << "node " << it.node << " child " << c << " sticks out of its parent";
            if (child.leaf()) {
                ASSERT_GE(child.link, level.firstTriangle);
                ASSERT_LE(uint64_t(child.link) + child.count, uint64_t(level.firstTriangle) + level.triangleCount);
                for (uint32_t t = child.link; t < child.link + child.count; ++t) {
                    ++triSeen[t - level.firstTriangle];
                    for (const glm::vec4& v : {a.triangles[t].v0, a.triangles[t].v1, a.triangles[t].v2})
                        EXPECT_TRUE(child.box.contains(BvhBox{glm::vec3(v), glm::vec3(v)}))
                            << "triangle " << t << " outside its leaf";
                }
            } else {
                stack.push_back({child.link, child.box, it.depth + 1});
            }
        }
    }
    EXPECT_EQ(maxDepth, level.depth);
    EXPECT_LE(level.depth, kMaxDepth);
    for (uint32_t i = 0; i < level.nodeCount; ++i)
        EXPECT_EQ(nodeSeen[i], 1) << "node " << level.firstNode + i;
    for (uint32_t i = 0; i < level.triangleCount; ++i)
        EXPECT_EQ(triSeen[i], 1) << "triangle " << level.firstTriangle + i;
}

// Every level's invariants, and the refs: each scene triangle exactly once, in the static level (static
// instances, world space) or in its mesh's level (object space: animated or deforming instances), with the vertices
// it names (the BVH as built, before a refit).
void checkSceneBvh(const scene::Scene& s, const SceneBvh& bvh) {
    const scene::Deformation deformation(s);
    auto ownLevel = [&](const scene::MeshInstance& inst) { return inst.dynamic || deformation.meshDeforms(inst.mesh); };
    const BvhArrays& a = bvh.arrays();
    ASSERT_EQ(a.triangles.size(), a.refs.size());
    uint32_t nodes = 0, triangles = 0;
    for (const BvhBottomLevel& level : bvh.levels()) {
        checkLevel(a, level);
        EXPECT_EQ(level.firstNode, nodes);
        EXPECT_EQ(level.firstTriangle, triangles);
        nodes += level.nodeCount;
        triangles += level.triangleCount;
    }
    EXPECT_EQ(nodes, a.nodes.size());
    EXPECT_EQ(triangles, a.triangles.size());
    ASSERT_EQ(bvh.primitives().size(), s.primitives.size());

    std::set<std::tuple<uint32_t, uint32_t, uint32_t>> seen;
    for (uint32_t t = 0; t < bvh.levels()[0].triangleCount; ++t) {
        const GpuBvhTriangleRef& r = a.refs[t];
        ASSERT_LT(r.instance, s.instances.size());
        EXPECT_FALSE(ownLevel(s.instances[r.instance]));
        EXPECT_TRUE(seen.insert({r.instance, r.primitive, r.triangle}).second) << "twice: triangle " << t;
        const scene::Primitive& p = s.primitives[r.primitive];
        ASSERT_LT(r.triangle, p.indexCount / 3);
        EXPECT_EQ(r.material, p.material);
        const glm::vec4* v = &a.triangles[t].v0;
        for (uint32_t k = 0; k < 3; ++k) {
            glm::vec3 expected =
                transformPoint(s.instances[r.instance].world,
                               s.vertices[p.vertexOffset + s.indices[p.firstIndex + 3 * r.triangle + k]].position);
            EXPECT_EQ(glm::vec3(v[k]), expected) << "triangle " << t << " vertex " << k;
        }
    }
    size_t staticTriangles = 0;
    for (const scene::MeshInstance& inst : s.instances) {
        if (ownLevel(inst)) continue;
        const scene::Mesh& m = s.meshes[inst.mesh];
        for (uint32_t p = m.firstPrimitive; p < m.firstPrimitive + m.primitiveCount; ++p)
            if (!s.materials[s.primitives[p].material].transparent()) staticTriangles += s.primitives[p].indexCount / 3;
    }
    EXPECT_EQ(seen.size(), staticTriangles);

    for (const BvhDynamicInstance& d : bvh.dynamicInstances()) {
        ASSERT_LT(d.instance, s.instances.size());
        EXPECT_TRUE(ownLevel(s.instances[d.instance]));
        const BvhBottomLevel& level = bvh.levels()[d.level];
        const scene::Mesh& m = s.meshes[s.instances[d.instance].mesh];
        std::set<std::pair<uint32_t, uint32_t>> mine;
        for (uint32_t t = level.firstTriangle; t < level.firstTriangle + level.triangleCount; ++t) {
            const GpuBvhTriangleRef& r = a.refs[t];
            EXPECT_EQ(r.instance, kNone);
            EXPECT_GE(r.primitive, m.firstPrimitive);
            EXPECT_LT(r.primitive, m.firstPrimitive + m.primitiveCount);
            EXPECT_TRUE(mine.insert({r.primitive, r.triangle}).second);
            const scene::Primitive& p = s.primitives[r.primitive];
            EXPECT_EQ(glm::vec3(a.triangles[t].v1),
                      s.vertices[p.vertexOffset + s.indices[p.firstIndex + 3 * r.triangle + 1]].position);
        }
        size_t expected = 0;
        for (uint32_t p = m.firstPrimitive; p < m.firstPrimitive + m.primitiveCount; ++p)
            if (!s.materials[s.primitives[p].material].transparent()) expected += s.primitives[p].indexCount / 3;
        EXPECT_EQ(mine.size(), expected);
    }
}

TEST(BvhBuild, RandomSoupInvariants) {
    scene::Scene s = randomSoup(6000, 1);
    SceneBvh bvh = SceneBvh::build(s);
    checkSceneBvh(s, bvh);
    EXPECT_EQ(bvh.levels().size(), 1u);
    EXPECT_EQ(bvh.arrays().triangles.size(), 6000u);
}

TEST(BvhBuild, MuseumInvariants) {
    scene::MuseumOptions o;
    o.textureSize = 16;
    scene::Scene s = scene::buildMuseum(o);
    SceneBvh bvh = SceneBvh::build(s);
    checkSceneBvh(s, bvh);
    // The robot's seven rigid parts are dynamic instances with their own object-space levels.
    EXPECT_GE(bvh.dynamicInstances().size(), 7u);
    EXPECT_EQ(bvh.levels().size(), 1 + bvh.dynamicInstances().size());
    const BvhBottomLevel& st = bvh.levels()[0];
    std::printf(
        "museum: %zu triangles, static level %u triangles, %u nodes, depth %u, SAH cost %.1f; all levels %zu nodes, "
        "%.1f MiB; build %.0f ms\n",
        s.triangleCount(), st.triangleCount, st.nodeCount, st.depth, st.sahCost, bvh.arrays().nodes.size(),
        bvh.gpuBytes() / 1048576.0, bvh.buildMs());
}

TEST(BvhBuild, InputsThatDefeatSahStayWithinTheStack) {
    // 5000 copies of one triangle: no plane separates them.
    IndexedMesh same;
    for (uint32_t i = 0; i < 5000; ++i) {
        for (glm::vec3 p : {glm::vec3(0, 0, 0), glm::vec3(1, 0, 0), glm::vec3(0, 1, 0)})
            same.positions.push_back(p);
        for (uint32_t k = 0; k < 3; ++k)
            same.indices.push_back(3 * i + k);
    }
    // Triangles at geometrically growing distances: most centroids fall into one bin at every level.
    IndexedMesh chain;
    for (uint32_t i = 0; i < 300; ++i) {
        float x = std::pow(1.2f, static_cast<float>(i));
        for (glm::vec3 p : {glm::vec3(x, 0, 0), glm::vec3(x, 1e-3f * x, 0), glm::vec3(x, 0, 1e-3f * x)})
            chain.positions.push_back(p);
        for (uint32_t k = 0; k < 3; ++k)
            chain.indices.push_back(3 * i + k);
    }
    // Zero-area triangles (points and segments) mixed with real ones.
    IndexedMesh degenerate = icosphere(2);
    for (uint32_t i = 0; i < 200; ++i) {
        degenerate.indices.insert(degenerate.indices.end(), {i, i, i, i, i + 1, i + 1});
    }
    for (const IndexedMesh* m : {&same, &chain, &degenerate}) {
        scene::Scene s;
        addRootNode(s, "m", addMesh(s, "m", *m));
        s.finalize();
        SceneBvh bvh = SceneBvh::build(s);
        checkSceneBvh(s, bvh);
        EXPECT_LE(bvh.levels()[0].depth, kMaxDepth);
    }
}

TEST(BvhBuild, DepthLimitSwitchesToMedianSplits) {
    // Real scenes never come near the traversal stack's 64 levels (binned SAH keeps even the inputs above
    // under 30), so the limit is exercised with a low one: 6000 triangles in at most 9 levels.
    scene::Scene s = randomSoup(6000, 5);
    BvhBuildOptions shallow;
    shallow.maxDepth = 9;
    SceneBvh bvh = SceneBvh::build(s, shallow);
    checkSceneBvh(s, bvh);
    EXPECT_LE(bvh.levels()[0].depth, 9u);
    EXPECT_GT(SceneBvh::build(s).levels()[0].depth, 9u);
}

// A refit (what a deforming mesh's level gets every frame) keeps the tree and moves its boxes. After every triangle of
// the soup moved (movedTriangle: a twist and a shift of up to 0.4 per axis), the level keeps its invariants
// (checkLevel) and its links, its triangles are the moved ones, and every box is tight: the union of the corners
// below it, no larger than a fresh build's box over the same triangles would be.
TEST(BvhBuild, RefitMovesEveryBoxToTheCornersBelowIt) {
    scene::Scene s = randomSoup(3000, 5);
    SceneBvh bvh = SceneBvh::build(s);
    const BvhArrays& built = bvh.arrays();
    BvhArrays a = built;
    BvhBottomLevel level = bvh.levels()[0];
    refitBottomLevel(level, a, [&](const GpuBvhTriangleRef& r, glm::vec3(&v)[3]) { movedTriangle(s, r, v); });
    checkLevel(a, level);
    ASSERT_EQ(a.triangles.size(), built.triangles.size());
    size_t moved = 0;
    for (size_t t = 0; t < a.triangles.size(); ++t) {
        glm::vec3 v[3];
        movedTriangle(s, a.refs[t], v);
        EXPECT_EQ(glm::vec3(a.triangles[t].v0), v[0]) << "triangle " << t;
        EXPECT_EQ(glm::vec3(a.triangles[t].v1), v[1]) << "triangle " << t;
        EXPECT_EQ(glm::vec3(a.triangles[t].v2), v[2]) << "triangle " << t;
        moved += glm::vec3(built.triangles[t].v2) != v[2];
    }
    EXPECT_GT(moved, a.triangles.size() * 9 / 10);
    // The corners below a child, walked from the links alone.
    std::function<BvhBox(const BvhChild&)> below = [&](const BvhChild& c) {
        BvhBox box;
        if (c.leaf()) {
            for (uint32_t t = c.link; t < c.link + c.count; ++t)
                for (const glm::vec4& v : {a.triangles[t].v0, a.triangles[t].v1, a.triangles[t].v2})
                    box.expand(glm::vec3(v));
        } else {
            for (int k = 0; k < 2; ++k)
                if (BvhChild g = childOf(a.nodes[c.link], k); !g.absent()) box.expand(below(g));
        }
        return box;
    };
    BvhBox all;
    for (uint32_t n = level.firstNode; n < level.firstNode + level.nodeCount; ++n) {
        for (int k = 0; k < 2; ++k) {
            const BvhChild c = childOf(a.nodes[n], k), b = childOf(built.nodes[n], k);
            EXPECT_EQ(c.link, b.link) << "node " << n;
            EXPECT_EQ(c.count, b.count) << "node " << n;
            if (c.absent()) continue;
            const BvhBox want = below(c);
            EXPECT_EQ(c.box.min, want.min) << "node " << n << " child " << k;
            EXPECT_EQ(c.box.max, want.max) << "node " << n << " child " << k;
        }
    }
    for (const GpuBvhTriangle& t : a.triangles)
        for (const glm::vec4& v : {t.v0, t.v1, t.v2})
            all.expand(glm::vec3(v));
    EXPECT_EQ(level.bounds.min, all.min);
    EXPECT_EQ(level.bounds.max, all.max);
}

TEST(BvhBuild, TinyInputs) {
    for (uint32_t n : {0u, 1u, 2u, 3u, 5u}) {
        IndexedMesh m;
        for (uint32_t i = 0; i < n; ++i) {
            for (glm::vec3 p : {glm::vec3(i, 0, 0), glm::vec3(i + 0.5f, 0, 0), glm::vec3(i, 1, 0)})
                m.positions.push_back(p);
            for (uint32_t k = 0; k < 3; ++k)
                m.indices.push_back(3 * i + k);
        }
        scene::Scene s;
        if (n > 0) addRootNode(s, "m", addMesh(s, "m", m));
        s.finalize();
        SceneBvh bvh = SceneBvh::build(s);
        checkSceneBvh(s, bvh);
        EXPECT_EQ(bvh.arrays().triangles.size(), n);
        // A ray down -z through every triangle's corner region hits when there is something to hit.
        for (uint32_t i = 0; i < n; ++i) {
            Ray r;
            r.origin = glm::vec3(i + 0.1f, 0.1f, 1.0f);
            Hit h = traceClosest(bvh.arrays(), bvh.topLevel({}), r);
            ASSERT_TRUE(h.valid()) << n << " triangles, triangle " << i;
            EXPECT_FLOAT_EQ(h.t, 1.0f);
            EXPECT_EQ(bvh.arrays().refs[h.triangle].triangle, i);
        }
        Ray miss;
        miss.origin = glm::vec3(-5.0f, 0.0f, 1.0f);
        EXPECT_FALSE(traceClosest(bvh.arrays(), bvh.topLevel({}), miss).valid());
    }
}

// Transparent primitives (alpha BLEND, transmission: glass) are left out: a ray through a pane reaches what is behind.
TEST(BvhBuild, TransparentPrimitivesAreLeftOut) {
    IndexedMesh tri;
    tri.positions = {glm::vec3(0, 0, 0), glm::vec3(1, 0, 0), glm::vec3(0, 1, 0)};
    tri.indices = {0, 1, 2};
    scene::Scene s;
    addRootNode(s, "wall", addMesh(s, "wall", tri));
    uint32_t pane = addMesh(s, "pane", tri);
    scene::Material glass = s.materials[0];
    glass.name = "glass";
    glass.transmission = 1.0f;
    s.materials.push_back(glass);
    scene::Material film = s.materials[0];
    film.name = "film";
    film.alphaMode = scene::AlphaMode::Blend;
    s.materials.push_back(film);
    s.primitives[s.meshes[pane].firstPrimitive].material = 1;
    addRootNode(s, "pane", pane, transform({0.0f, 0.0f, 0.5f}));
    uint32_t filmMesh = addMesh(s, "film", tri);
    s.primitives[s.meshes[filmMesh].firstPrimitive].material = 2;
    addRootNode(s, "film", filmMesh, transform({0.0f, 0.0f, 0.7f}));
    s.finalize();
    SceneBvh bvh = SceneBvh::build(s);
    checkSceneBvh(s, bvh);
    EXPECT_EQ(bvh.arrays().triangles.size(), 1u);
    Ray r;
    r.origin = glm::vec3(0.1f, 0.1f, 1.0f);
    Hit h = traceClosest(bvh.arrays(), bvh.topLevel({}), r);
    ASSERT_TRUE(h.valid());
    EXPECT_FLOAT_EQ(h.t, 1.0f); // the wall at z = 0, through the glass at 0.5 and the film at 0.7
}

TEST(BvhBuild, SahBeatsSpatialMedian) {
    // The SAH cost of the build must be below that of splitting the centroid box in the middle (two bins:
    // one candidate plane per axis); a broken cost sweep shows here.
    scene::Scene s = randomSoup(6000, 3);
    SceneBvh sah = SceneBvh::build(s);
    BvhBuildOptions coarse;
    coarse.bins = 2;
    SceneBvh mid = SceneBvh::build(s, coarse);
    EXPECT_LT(sah.levels()[0].sahCost, 0.9f * mid.levels()[0].sahCost)
        << sah.levels()[0].sahCost << " vs " << mid.levels()[0].sahCost;
}

} // namespace
} // namespace vitrine::accel
