// The lightmap atlas plan (core/bake/lightmap_atlas): region sizes from world area and texel density worked
// out by hand on quads, which instances are skipped and why, and on the museum: every static lightmapped
// instance has a region, regions and their gutters never overlap and stay inside the atlas, and the plan is
// the same every time, and its charts lie at least three texels apart at 2, 4 and 8 texels per metre.
#include "core/bake/lightmap_atlas.hpp"

#include "core/bake/lightmap_bake.hpp"
#include "core/base/error.hpp"
#include "core/scene/museum.hpp"
#include "core/scene/scene.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <numeric>

namespace vitrine::bake {
namespace {

namespace sc = vitrine::scene;

// A side x side square in the XZ plane whose uv1 spans [0, uvExtent]², as one primitive of its own mesh.
uint32_t quadMesh(sc::Scene& s, float side, float uvExtent, bool lightmapUvs) {
    sc::Primitive p;
    p.firstIndex = static_cast<uint32_t>(s.indices.size());
    p.vertexOffset = static_cast<uint32_t>(s.vertices.size());
    const glm::vec2 corners[4] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
    for (glm::vec2 c : corners) {
        sc::Vertex v;
        v.position = glm::vec3(c.x * side, 0.0f, -c.y * side);
        v.normal = {0, 1, 0};
        v.tangent = {1, 0, 0, 1};
        v.uv1 = c * uvExtent;
        s.vertices.push_back(v);
    }
    for (uint32_t i : {0u, 1u, 2u, 0u, 2u, 3u}) s.indices.push_back(i);
    p.indexCount = 6;
    p.vertexCount = 4;
    p.material = 0;
    p.lightmapUvs = lightmapUvs;
    s.primitives.push_back(p);
    sc::Mesh m;
    m.name = "quad" + std::to_string(s.meshes.size());
    m.firstPrimitive = static_cast<uint32_t>(s.primitives.size() - 1);
    m.primitiveCount = 1;
    s.meshes.push_back(m);
    return static_cast<uint32_t>(s.meshes.size() - 1);
}

void place(sc::Scene& s, uint32_t mesh, glm::vec3 at, float scale = 1.0f) {
    sc::Node n;
    n.name = "n" + std::to_string(s.nodes.size());
    n.mesh = static_cast<int32_t>(mesh);
    n.local.translation = at;
    n.local.scale = glm::vec3(scale);
    s.nodes.push_back(n);
    s.roots.push_back(static_cast<uint32_t>(s.nodes.size() - 1));
}

sc::Scene quads() {
    sc::Scene s;
    s.name = "quads";
    s.materials.push_back(sc::Material{});
    place(s, quadMesh(s, 2.0f, 1.0f, true), {0, 0, 0});        // 4 m² over the whole uv square
    place(s, quadMesh(s, 4.0f, 1.0f, true), {5, 0, 0});        // 16 m²
    place(s, quadMesh(s, 1.0f, 0.5f, true), {10, 0, 0});       // 1 m² over a quarter of the uv square
    place(s, quadMesh(s, 2.0f, 1.0f, false), {15, 0, 0});      // no lightmap UVs
    place(s, quadMesh(s, 1.0f, 1.0f, true), {20, 0, 0}, 3.0f); // scaled by 3: 9 m²
    place(s, quadMesh(s, 1.0f, 1.0f, true), {25, 0, 0});       // lightmap UVs, but animated (below)
    // A mesh of two primitives, only the first with lightmap UVs: the second's 16 m² do not count.
    const uint32_t mixed = quadMesh(s, 2.0f, 1.0f, true);
    quadMesh(s, 4.0f, 1.0f, false);
    s.meshes[mixed].primitiveCount = 2;
    s.meshes.pop_back();
    place(s, mixed, {30, 0, 0});
    s.finalize();
    s.instances[5].dynamic = true; // as if an animation moved it: probes, not a lightmap
    return s;
}

TEST(LightmapAtlas, RegionSizeFollowsWorldAreaAndTexelDensity) {
    const sc::Scene s = quads();
    LightmapAtlasOptions o;
    o.texelsPerMeter = 8.0f;
    o.gutter = 2;
    o.maxSize = 64;
    o.atlasWidth = 128;
    const LightmapAtlas a = planLightmapAtlas(s, o);
    ASSERT_EQ(a.regionOfInstance.size(), 7u);
    auto sizeOf = [&](uint32_t instance) {
        const int32_t r = a.regionOfInstance[instance];
        return r < 0 ? 0u : a.regions[r].size;
    };
    // The uv square spans the quad's side: side * 8 texels. The third quad's uv covers a quarter of the square,
    // so the square stands for 2 m: 16 texels. The scaled quad is 3 m wide: 24.
    EXPECT_EQ(sizeOf(0), 16u);
    EXPECT_EQ(sizeOf(1), 32u);
    EXPECT_EQ(sizeOf(2), 16u);
    EXPECT_EQ(sizeOf(3), 0u);
    EXPECT_EQ(sizeOf(4), 24u);
    EXPECT_EQ(sizeOf(5), 0u);
    EXPECT_EQ(sizeOf(6), 16u); // the lightmapped primitive's 2 m side only
    ASSERT_EQ(a.skipped.size(), 2u);
    EXPECT_EQ(a.skipped[0].first, 3u);
    EXPECT_NE(a.skipped[0].second.find("TEXCOORD_1"), std::string::npos);
    EXPECT_EQ(a.skipped[1].first, 5u);
    EXPECT_EQ(a.skipped[1].second, "dynamic");

    // The mapping of uv1 corners lands on the region's corner texels.
    for (const LightmapRegion& r : a.regions) {
        const glm::vec2 lo = glm::vec2(r.scaleOffset.z, r.scaleOffset.w) * glm::vec2(a.width, a.height);
        const glm::vec2 hi = (glm::vec2(1.0f) * glm::vec2(r.scaleOffset) + glm::vec2(r.scaleOffset.z, r.scaleOffset.w)) *
                             glm::vec2(a.width, a.height);
        EXPECT_NEAR(lo.x, float(r.x), 1e-3f);
        EXPECT_NEAR(lo.y, float(r.y), 1e-3f);
        EXPECT_NEAR(hi.x, float(r.x + r.size), 1e-3f);
        EXPECT_NEAR(hi.y, float(r.y + r.size), 1e-3f);
    }
    // Clamps: a low maximum caps the big quad, a high minimum raises the small ones.
    o.maxSize = 20;
    o.minSize = 18;
    const LightmapAtlas clamped = planLightmapAtlas(s, o);
    for (const LightmapRegion& r : clamped.regions) {
        EXPECT_GE(r.size, 18u);
        EXPECT_LE(r.size, 20u);
    }
}

TEST(LightmapAtlas, MuseumRegionsDoNotOverlapAndCoverEveryStaticLightmappedInstance) {
    sc::MuseumOptions mo;
    mo.textureSize = 16;
    const sc::Scene s = sc::buildMuseum(mo);
    LightmapAtlasOptions o;
    const LightmapAtlas a = planLightmapAtlas(s, o);
    std::printf("museum lightmap atlas: %zu regions, %ux%u, coverage %.2f, %zu instances skipped\n", a.regions.size(),
                a.width, a.height, a.coverage(), a.skipped.size());
    ASSERT_GE(a.regions.size(), 15u); // the static architecture and exhibits (26 instances, 7 of them the robot)
    EXPECT_EQ(a.regions.size() + a.skipped.size(), s.instances.size());
    size_t dynamicSkipped = 0;
    for (uint32_t i = 0; i < s.instances.size(); ++i) {
        const bool lightmapped = a.regionOfInstance[i] >= 0;
        if (s.instances[i].dynamic) {
            EXPECT_FALSE(lightmapped) << "dynamic instance " << i;
            ++dynamicSkipped;
        }
    }
    EXPECT_GT(dynamicSkipped, 0u); // the robot
    for (size_t i = 0; i < a.regions.size(); ++i) {
        const LightmapRegion& r = a.regions[i];
        EXPECT_GE(r.x, o.gutter);
        EXPECT_GE(r.y, o.gutter);
        EXPECT_LE(r.x + r.size + o.gutter, a.width);
        EXPECT_LE(r.y + r.size + o.gutter, a.height);
        for (size_t j = i + 1; j < a.regions.size(); ++j) {
            const LightmapRegion& q = a.regions[j];
            // Regions grown by one gutter each must stay apart: two gutters between any two regions.
            const bool apart = r.x + r.size + 2 * o.gutter <= q.x || q.x + q.size + 2 * o.gutter <= r.x ||
                               r.y + r.size + 2 * o.gutter <= q.y || q.y + q.size + 2 * o.gutter <= r.y;
            EXPECT_TRUE(apart) << "regions of instances " << r.instance << " and " << q.instance << " overlap";
        }
    }
    EXPECT_GT(a.coverage(), 0.3);
    EXPECT_LE(a.coverage(), 1.0);
    // Deterministic: the bake cache key and the G-buffer rely on it.
    const LightmapAtlas again = planLightmapAtlas(s, o);
    ASSERT_EQ(again.regions.size(), a.regions.size());
    for (size_t i = 0; i < a.regions.size(); ++i) {
        EXPECT_EQ(again.regions[i].x, a.regions[i].x);
        EXPECT_EQ(again.regions[i].y, a.regions[i].y);
        EXPECT_EQ(again.regions[i].size, a.regions[i].size);
    }
}

TEST(LightmapAtlas, AKnownChartGapRaisesTheRegionUntilItSpansMinChartGapTexels) {
    sc::Scene s = quads();
    s.meshes[s.instances[0].mesh].lightmapChartGap = 0.1f; // 16 texels by density: a 1.6-texel gap
    s.meshes[s.instances[1].mesh].lightmapChartGap = 0.5f; // 32 texels by density: 16 texels apart already
    LightmapAtlasOptions o;
    o.texelsPerMeter = 8.0f;
    o.maxSize = 64;
    o.atlasWidth = 256;
    o.minChartGap = 3.0f;
    const LightmapAtlas a = planLightmapAtlas(s, o);
    EXPECT_EQ(a.regions[a.regionOfInstance[0]].size, 30u); // 3 / 0.1 texels per side
    EXPECT_EQ(a.regions[a.regionOfInstance[1]].size, 32u); // unchanged
    EXPECT_EQ(a.regions[a.regionOfInstance[2]].size, 16u); // no gap known: density alone
    EXPECT_TRUE(a.narrowChartGaps.empty());

    // Capped by maxSize: the region stays at the cap and the plan says how narrow its gaps are.
    s.meshes[s.instances[0].mesh].lightmapChartGap = 0.01f; // would need 300 texels
    const LightmapAtlas capped = planLightmapAtlas(s, o);
    EXPECT_EQ(capped.regions[capped.regionOfInstance[0]].size, 64u);
    ASSERT_EQ(capped.narrowChartGaps.size(), 1u);
    EXPECT_EQ(capped.narrowChartGaps[0].first, 0u);
    EXPECT_NEAR(capped.narrowChartGaps[0].second, 0.64f, 1e-4f);
}

// The charts of a mesh's lightmap UVs, found from the triangles themselves: triangles sharing a vertex are one
// chart, and pieces whose uv bounding boxes overlap or touch are merged (a chart may be several patches). Returns
// each chart's uv1 bounding box.
std::vector<std::pair<glm::vec2, glm::vec2>> uvCharts(const sc::Scene& s, const sc::Mesh& mesh) {
    std::vector<std::pair<glm::vec2, glm::vec2>> boxes;
    for (uint32_t k = 0; k < mesh.primitiveCount; ++k) {
        const sc::Primitive& p = s.primitives[mesh.firstPrimitive + k];
        if (!p.lightmapUvs) continue;
        std::vector<uint32_t> parent(p.vertexCount);
        std::iota(parent.begin(), parent.end(), 0u);
        auto root = [&](uint32_t v) {
            while (parent[v] != v)
                v = parent[v] = parent[parent[v]];
            return v;
        };
        for (uint32_t t = 0; t + 2 < p.indexCount; t += 3)
            for (uint32_t e = 1; e < 3; ++e)
                parent[root(s.indices[p.firstIndex + t + e])] = root(s.indices[p.firstIndex + t]);
        std::vector<int> boxOf(p.vertexCount, -1);
        for (uint32_t v = 0; v < p.vertexCount; ++v) {
            const glm::vec2 uv = s.vertices[p.vertexOffset + v].uv1;
            int& b = boxOf[root(v)];
            if (b < 0) {
                b = static_cast<int>(boxes.size());
                boxes.emplace_back(uv, uv);
            }
            boxes[b].first = glm::min(boxes[b].first, uv);
            boxes[b].second = glm::max(boxes[b].second, uv);
        }
    }
    // Sweep along x: a box only meets the boxes that start before it ends. Repeat until nothing merges.
    constexpr float kTouch = 1e-5f; // duplicated vertices along a chart's inner edges
    for (bool merged = true; merged;) {
        merged = false;
        std::sort(boxes.begin(), boxes.end(), [](const auto& a, const auto& b) { return a.first.x < b.first.x; });
        std::vector<bool> gone(boxes.size(), false);
        for (size_t i = 0; i < boxes.size(); ++i) {
            if (gone[i]) continue;
            for (size_t j = i + 1; j < boxes.size() && boxes[j].first.x <= boxes[i].second.x + kTouch; ++j) {
                if (gone[j] || boxes[j].first.y > boxes[i].second.y + kTouch ||
                    boxes[i].first.y > boxes[j].second.y + kTouch)
                    continue;
                boxes[i] = {glm::min(boxes[i].first, boxes[j].first), glm::max(boxes[i].second, boxes[j].second)};
                gone[j] = merged = true;
            }
        }
        size_t kept = 0;
        for (size_t i = 0; i < boxes.size(); ++i)
            if (!gone[i]) boxes[kept++] = boxes[i];
        boxes.resize(kept);
    }
    return boxes;
}

TEST(LightmapAtlas, MuseumChartsLieAtLeastThreeTexelsApart) {
    // Bilinear filtering at a chart's border reads the texel beyond it, which dilation fills from the nearest chart:
    // charts closer than about three texels take their neighbours' light (the doorway's jamb beside the museum's
    // camera took the sunlit wall's, up to 4x its own, at 8 texels per metre).
    sc::MuseumOptions mo;
    mo.textureSize = 16;
    const sc::Scene s = sc::buildMuseum(mo);
    for (float density : {2.0f, 4.0f, 8.0f}) { // 2: the gap alone decides the size
        LightmapAtlasOptions o;
        o.texelsPerMeter = density;
        const LightmapAtlas a = planLightmapAtlas(s, o);
        EXPECT_TRUE(a.narrowChartGaps.empty()) << density << " texels/m";
        for (const LightmapRegion& r : a.regions) {
            const sc::Mesh& mesh = s.meshes[s.instances[r.instance].mesh];
            const auto charts = uvCharts(s, mesh);
            float closest = 1e9f;
            for (size_t i = 0; i < charts.size(); ++i)
                for (size_t j = i + 1; j < charts.size(); ++j) {
                    const auto &p = charts[i], &q = charts[j];
                    const float dx = std::max(p.first.x - q.second.x, q.first.x - p.second.x);
                    const float dy = std::max(p.first.y - q.second.y, q.first.y - p.second.y);
                    closest = std::min(closest, std::max(dx, dy) * float(r.size));
                }
            EXPECT_GE(closest, 2.99f) << mesh.name << " at " << density << " texels/m: " << charts.size()
                                      << " charts in " << r.size << "² texels";
        }
    }
}

TEST(LightmapAtlas, TheBakeKeyFollowsTheLightmapUvsAndTheChartGap) {
    // Re-packed charts must re-bake: the lightmap's key hashes uv1 (which references' keys leave out).
    sc::Scene s = quads();
    const LightmapBakeSettings settings;
    const uint64_t key = lightmapCacheKey(s, settings, 1).hash;
    s.vertices[1].uv1.x *= 0.5f;
    const uint64_t moved = lightmapCacheKey(s, settings, 1).hash;
    EXPECT_NE(moved, key);
    s.meshes[0].lightmapChartGap = 0.05f;
    EXPECT_NE(lightmapCacheKey(s, settings, 1).hash, moved);
    LightmapBakeSettings wider = settings;
    wider.atlas.minChartGap = 4.0f;
    EXPECT_NE(lightmapCacheKey(s, wider, 1).hash, lightmapCacheKey(s, settings, 1).hash);
}

TEST(LightmapAtlas, BadOptionsAreUserErrors) {
    const sc::Scene s = quads();
    LightmapAtlasOptions o;
    o.texelsPerMeter = 0.0f;
    EXPECT_THROW(planLightmapAtlas(s, o), UserError);
    o = {};
    o.minSize = 64;
    o.maxSize = 32;
    EXPECT_THROW(planLightmapAtlas(s, o), UserError);
    o = {};
    o.atlasWidth = 100;
    o.maxSize = 512;
    EXPECT_THROW(planLightmapAtlas(s, o), UserError);
}

} // namespace
} // namespace vitrine::bake
