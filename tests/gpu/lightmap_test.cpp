// The lightmap texel G-buffer (core/bake/lightmap_raster): quads whose lightmap UVs are known are drawn into
// their atlas regions on the GPU; every texel centre inside a region must carry the world position the
// analytic uv -> surface map gives (within 1e-4 m) and the instance's normal, and texels outside every region
// stay uncovered.
#include "tests/gpu/gpu_test.hpp"

#include "core/bake/lightmap_atlas.hpp"
#include "core/bake/lightmap_raster.hpp"
#include "core/scene/gpu_scene.hpp"
#include "core/scene/scene.hpp"
#include "core/shader/compiler.hpp"

#include <glm/gtc/quaternion.hpp>

namespace vitrine::test {
namespace {

namespace sc = vitrine::scene;

struct Quad {
    glm::vec3 at;
    glm::quat rotation;
    float side;
    float uvExtent;
};

// A side x side square in its XZ plane (normal +Y) whose uv1 spans [0, uvExtent]²: uv1 (u, v) is the point
// (u / uvExtent * side, 0, -v / uvExtent * side) of the quad.
sc::Scene quadScene(const std::vector<Quad>& quads) {
    sc::Scene s;
    s.name = "lightmap_quads";
    sc::Material m;
    m.name = "grey";
    m.layers.push_back(sc::MaterialLayer{});
    s.materials.push_back(m);
    for (const Quad& q : quads) {
        sc::Primitive p;
        p.firstIndex = static_cast<uint32_t>(s.indices.size());
        p.vertexOffset = static_cast<uint32_t>(s.vertices.size());
        const glm::vec2 corners[4] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
        for (glm::vec2 c : corners) {
            sc::Vertex v;
            v.position = glm::vec3(c.x * q.side, 0.0f, -c.y * q.side);
            v.normal = {0, 1, 0};
            v.tangent = {1, 0, 0, 1};
            v.uv1 = c * q.uvExtent;
            s.vertices.push_back(v);
        }
        for (uint32_t i : {0u, 1u, 2u, 0u, 2u, 3u}) s.indices.push_back(i);
        p.indexCount = 6;
        p.vertexCount = 4;
        p.lightmapUvs = true;
        s.primitives.push_back(p);
        sc::Mesh m;
        m.name = "quad" + std::to_string(s.meshes.size());
        m.firstPrimitive = static_cast<uint32_t>(s.primitives.size() - 1);
        m.primitiveCount = 1;
        s.meshes.push_back(m);
        sc::Node n;
        n.name = m.name;
        n.mesh = static_cast<int32_t>(s.meshes.size() - 1);
        n.local.translation = q.at;
        n.local.rotation = q.rotation;
        s.nodes.push_back(n);
        s.roots.push_back(static_cast<uint32_t>(s.nodes.size() - 1));
    }
    s.finalize();
    s.validate();
    return s;
}

class LightmapTexelsTest : public GpuTest {};

TEST_F(LightmapTexelsTest, TexelsCarryTheSurfacePointOfTheirLightmapUv) {
    const std::vector<Quad> quads = {
        {{0, 0, 0}, glm::quat(1, 0, 0, 0), 2.0f, 1.0f},
        {{5, 1, -2}, glm::angleAxis(0.7f, glm::normalize(glm::vec3(1, 0.3f, 0.2f))), 3.0f, 1.0f},
        {{-4, 2, 3}, glm::angleAxis(2.0f, glm::vec3(0, 0, 1)), 1.0f, 0.5f}, // uv covers a quarter of the square
    };
    const sc::Scene s = quadScene(quads);
    bake::LightmapAtlasOptions o;
    o.texelsPerMeter = 10.0f;
    o.atlasWidth = 128;
    o.maxSize = 64;
    const bake::LightmapAtlas atlas = bake::planLightmapAtlas(s, o);
    ASSERT_EQ(atlas.regions.size(), 3u);

    ShaderCompiler shaders;
    GpuScene gpuScene(gpu(), shaders, s);
    const sc::ScenePose pose = s.evaluate(0.0);
    CameraFrame camera;
    gpuScene.update(pose, pose, camera);
    const bake::LightmapTexels t = bake::rasterizeLightmapTexels(gpu(), shaders, gpuScene, s, atlas);
    ASSERT_EQ(t.width, atlas.width);
    ASSERT_EQ(t.height, atlas.height);
    size_t covered = 0, inRegions = 0, strays = 0;
    double worstPosition = 0.0, worstNormal = 0.0;
    for (uint32_t y = 0; y < t.height; ++y)
        for (uint32_t x = 0; x < t.width; ++x) {
            const size_t i = t.index(x, y);
            int32_t owner = -1;
            for (size_t r = 0; r < atlas.regions.size(); ++r) {
                const bake::LightmapRegion& g = atlas.regions[r];
                if (x >= g.x && x < g.x + g.size && y >= g.y && y < g.y + g.size) owner = int32_t(r);
            }
            if (t.region[i] >= 0) ++covered;
            if (owner < 0) {
                strays += t.region[i] >= 0 ? 1 : 0;
                continue;
            }
            const bake::LightmapRegion& g = atlas.regions[owner];
            const Quad& q = quads[g.instance];
            // The texel centre's uv1, then the quad's point there, then the instance transform.
            const glm::dvec2 uv((x + 0.5 - g.x) / g.size, (y + 0.5 - g.y) / g.size);
            if (uv.x > q.uvExtent || uv.y > q.uvExtent) {
                EXPECT_EQ(t.region[i], -1) << "texel " << x << "," << y << " outside the quad's uv";
                continue;
            }
            // A centre on the quad's edge in uv may go either way (the rasteriser's tie-breaking rule).
            if (std::abs(uv.x - q.uvExtent) < 1e-6 || std::abs(uv.y - q.uvExtent) < 1e-6) continue;
            ++inRegions;
            ASSERT_EQ(t.region[i], owner) << "texel " << x << "," << y;
            const glm::dvec3 local(uv.x / q.uvExtent * q.side, 0.0, -uv.y / q.uvExtent * q.side);
            const glm::dvec3 world = glm::dvec3(q.at) + glm::dquat(q.rotation) * local;
            worstPosition = std::max(worstPosition, glm::length(glm::dvec3(t.position[i]) - world));
            const glm::dvec3 n = glm::dquat(q.rotation) * glm::dvec3(0, 1, 0);
            worstNormal = std::max(worstNormal, glm::length(glm::dvec3(t.normal[i]) - n));
        }
    std::printf("lightmap texels: %zu covered, %zu in regions, %zu outside; position error %.2e m, normal %.2e\n",
                covered, inRegions, strays, worstPosition, worstNormal);
    // Each quad's uv spans its whole region (the third's quarter square is a quarter of its region's area).
    const size_t expected = size_t(atlas.regions[0].size) * atlas.regions[0].size +
                            size_t(atlas.regions[1].size) * atlas.regions[1].size +
                            size_t(atlas.regions[2].size) * atlas.regions[2].size / 4;
    EXPECT_EQ(covered, expected);
    EXPECT_EQ(strays, 0u);
    EXPECT_LT(worstPosition, 1e-4);
    EXPECT_LT(worstNormal, 1e-5);
}

} // namespace
} // namespace vitrine::test
