// The lightmap atlas plan (core/bake/lightmap_atlas): region sizes from world area and texel density worked
// out by hand on quads, which instances are skipped and why, and on the museum: every static lightmapped
// instance has a region, regions and their gutters never overlap and stay inside the atlas, and the plan is
// the same every time.
#include "core/bake/lightmap_atlas.hpp"

#include "core/base/error.hpp"
#include "core/scene/museum.hpp"
#include "core/scene/scene.hpp"

#include <gtest/gtest.h>

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
