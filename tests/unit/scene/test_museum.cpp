// scene.museum: deterministic, complete, and built so that the renderer's features have something to do.

#include "core/scene/museum.hpp"
#include "core/scene/museum/context.hpp"

#include "test_util.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <memory>
#include <set>

#include <gtest/gtest.h>

namespace vitrine::scene {
namespace {

class Museum : public ::testing::Test {
protected:
    // One default museum for all the content checks: building it takes about a second.
    static void SetUpTestSuite() { sMuseum = std::make_unique<Scene>(buildMuseum()); }
    static void TearDownTestSuite() { sMuseum.reset(); }
    static const Scene& museum() { return *sMuseum; }

    static inline std::unique_ptr<Scene> sMuseum;
};

TEST_F(Museum, IsDeterministicFromTheSeed) {
    EXPECT_EQ(buildMuseum().contentHash(), museum().contentHash());
    MuseumOptions other;
    other.seed = 2;
    EXPECT_NE(buildMuseum(other).contentHash(), museum().contentHash());
}

// buildMuseum reserves the default museum's geometry up front (a warm start's scene build): the hint must hold it
// (else the vectors grow as before) without reserving much more than it uses.
TEST_F(Museum, GeometryFitsTheReservedHint) {
    EXPECT_LE(museum().vertices.size(), kMuseumVertexReserve);
    EXPECT_GT(museum().vertices.size(), kMuseumVertexReserve * 9 / 10);
    EXPECT_LE(museum().indices.size(), kMuseumIndexReserve);
    EXPECT_GT(museum().indices.size(), kMuseumIndexReserve * 9 / 10);
    EXPECT_EQ(museum().vertices.capacity(), kMuseumVertexReserve) << "the vertices outgrew the reserve";
    EXPECT_EQ(museum().indices.capacity(), kMuseumIndexReserve) << "the indices outgrew the reserve";
}

// The texture store (what scene.museum wires to the bake cache): the first build stores its textures under a key,
// a build that loads them is the same scene (every other random draw unchanged), a payload that does not fit is
// ignored (generated and stored again), and the key follows the seed and the size.
TEST_F(Museum, TexturesLoadedFromTheStoreBuildTheSameScene) {
    std::map<uint64_t, std::vector<TextureImage>> store;
    int loads = 0, hits = 0, stores = 0;
    auto withStore = [&](uint64_t seed, uint32_t size, bool corrupt = false) {
        MuseumOptions o;
        o.seed = seed;
        o.textureSize = size;
        o.loadTextures = [&, corrupt](uint64_t key) -> std::optional<std::vector<TextureImage>> {
            ++loads;
            auto it = store.find(key);
            if (it == store.end()) return std::nullopt;
            ++hits;
            std::vector<TextureImage> images = it->second;
            if (corrupt) images.pop_back();
            return images;
        };
        o.storeTextures = [&](uint64_t key, const std::vector<TextureImage>& images) {
            ++stores;
            store[key] = images;
        };
        return buildMuseum(o);
    };
    MuseumOptions plain;
    plain.textureSize = 32;
    const uint64_t expected = buildMuseum(plain).contentHash();
    EXPECT_EQ(withStore(1, 32).contentHash(), expected);
    EXPECT_EQ(stores, 1);
    EXPECT_EQ(hits, 0);
    ASSERT_EQ(store.size(), 1u);
    EXPECT_EQ(store.begin()->second.size(), buildMuseum(plain).images.size());
    // Loaded: no store, the same content (textures, and every placement drawn after them).
    EXPECT_EQ(withStore(1, 32).contentHash(), expected);
    EXPECT_EQ(hits, 1);
    EXPECT_EQ(stores, 1);
    // Loaded images that are not what the museum needs (one missing): generated and stored again.
    EXPECT_EQ(withStore(1, 32, true).contentHash(), expected);
    EXPECT_EQ(stores, 2);
    // Another seed or size: another key.
    withStore(2, 32);
    withStore(1, 16);
    EXPECT_EQ(store.size(), 3u);
    EXPECT_EQ(loads, 5);
    EXPECT_NE(museumTextureSourceHash(), 0u);
}

// The geometry store (what scene.museum wires to the bake cache, kind museum_geometry): the first build stores its
// geometry under a key of the seed and the generator's sources, a build that loads it is the same scene (the content
// hash covers vertices, indices, primitives, meshes, nodes and animations; the bounds and instances finalize() makes
// from them are compared too), a payload that does not parse is ignored (built and stored again), the key follows the
// seed and not the texture size.
TEST_F(Museum, GeometryLoadedFromTheStoreBuildsTheSameScene) {
    std::map<uint64_t, std::vector<uint8_t>> store;
    int hits = 0, stores = 0;
    auto withStore = [&](uint64_t seed, uint32_t size, size_t cut = 0) {
        MuseumOptions o;
        o.seed = seed;
        o.textureSize = size;
        o.loadGeometry = [&, cut](uint64_t key) -> std::optional<StoredBytes> {
            auto it = store.find(key);
            if (it == store.end()) return std::nullopt;
            ++hits;
            auto bytes = std::make_shared<std::vector<uint8_t>>(it->second);
            bytes->resize(bytes->size() - cut);
            return StoredBytes{*bytes, bytes};
        };
        o.storeGeometry = [&](uint64_t key, const std::vector<uint8_t>& bytes) {
            ++stores;
            store[key] = bytes;
        };
        return buildMuseum(o);
    };
    MuseumOptions plain;
    plain.textureSize = 32;
    const Scene expected = buildMuseum(plain);
    auto same = [&](const Scene& s) {
        EXPECT_EQ(s.contentHash(), expected.contentHash());
        EXPECT_EQ(s.lightmapHash(), expected.lightmapHash());
        ASSERT_EQ(s.instances.size(), expected.instances.size());
        for (size_t i = 0; i < s.instances.size(); ++i) {
            EXPECT_EQ(s.instances[i].mesh, expected.instances[i].mesh);
            EXPECT_EQ(s.instances[i].dynamic, expected.instances[i].dynamic) << i;
            EXPECT_EQ(s.instances[i].world, expected.instances[i].world) << i;
        }
        ASSERT_EQ(s.primitives.size(), expected.primitives.size());
        for (size_t i = 0; i < s.primitives.size(); ++i) {
            EXPECT_EQ(s.primitives[i].lightmapUvs, expected.primitives[i].lightmapUvs) << i;
            EXPECT_EQ(s.primitives[i].bounds.min, expected.primitives[i].bounds.min) << i;
        }
        ASSERT_EQ(s.meshes.size(), expected.meshes.size());
        for (size_t i = 0; i < s.meshes.size(); ++i)
            EXPECT_EQ(s.meshes[i].lightmapChartGap, expected.meshes[i].lightmapChartGap) << i;
        EXPECT_EQ(s.bounds.max, expected.bounds.max);
    };
    same(withStore(1, 32));
    EXPECT_EQ(stores, 1);
    EXPECT_EQ(hits, 0);
    ASSERT_EQ(store.size(), 1u);
    EXPECT_EQ(store.begin()->first, museumGeometryKey(1));
    // Loaded: no store, the same scene.
    same(withStore(1, 32));
    EXPECT_EQ(hits, 1);
    EXPECT_EQ(stores, 1);
    // Truncated (by one byte, and by half): built and stored again, the same scene.
    same(withStore(1, 32, 1));
    EXPECT_EQ(stores, 2);
    same(withStore(1, 32, store.begin()->second.size() / 2));
    EXPECT_EQ(stores, 3);
    // The texture size does not change the geometry: the same entry. Another seed: another.
    withStore(1, 16);
    EXPECT_EQ(store.size(), 1u);
    EXPECT_EQ(stores, 3);
    withStore(2, 32);
    EXPECT_EQ(store.size(), 2u);
    EXPECT_NE(museumGeometryKey(1), museumGeometryKey(2));
    EXPECT_NE(museumGeometrySourceHash(), museumTextureSourceHash());
}

// scene.museum hands over the loaded textures as views of the mapped cache file (PixelBuffer): the build must read
// them where they lie. A build that wrote to them, or took a non-const reference, would copy each into fresh memory
// (the cost the views remove from a warm start) and let go of the mapping.
TEST_F(Museum, LoadedTexturesStayViewsOfTheStore) {
    std::vector<TextureImage> stored;
    MuseumOptions o;
    o.textureSize = 32;
    o.storeTextures = [&](uint64_t, const std::vector<TextureImage>& images) { stored = images; };
    const uint64_t expected = buildMuseum(o).contentHash();
    ASSERT_FALSE(stored.empty());
    auto mapped = std::make_shared<std::vector<std::vector<uint8_t>>>();
    for (const TextureImage& image : stored) mapped->push_back(image.pixels.toVector());
    std::weak_ptr<const void> alive = mapped;
    o.storeTextures = nullptr;
    o.loadTextures = [&](uint64_t) -> std::optional<std::vector<TextureImage>> {
        std::vector<TextureImage> images = stored;
        for (size_t i = 0; i < images.size(); ++i) images[i].pixels = PixelBuffer::view((*mapped)[i], mapped);
        return images;
    };
    {
        const Scene loaded = buildMuseum(o);
        EXPECT_EQ(loaded.contentHash(), expected);
        ASSERT_EQ(loaded.images.size(), stored.size());
        for (size_t i = 0; i < stored.size(); ++i) {
            EXPECT_TRUE(loaded.images[i].pixels.isView()) << loaded.images[i].name << " was copied by the build";
            EXPECT_EQ(loaded.images[i].pixels.data(), (*mapped)[i].data()) << loaded.images[i].name;
        }
        mapped.reset();
        EXPECT_FALSE(alive.expired()) << "the scene's images keep the store's memory alive";
    }
    EXPECT_TRUE(alive.expired()) << "the scene gone, the store's memory is let go";
}

TEST_F(Museum, RejectsBadOptions) {
    MuseumOptions bad;
    bad.textureSize = 1000;
    test::expectUserError([&] { buildMuseum(bad); }, {"scene.museum", "textureSize 1000", "power of two"});
}

TEST_F(Museum, HasTheRequiredElements) {
    const Scene& s = museum();
    EXPECT_NO_THROW(s.validate());
    ASSERT_GE(s.rooms.size(), 3u);
    std::set<std::string> names;
    for (const Room& r : s.rooms) {
        names.insert(r.name);
        EXPECT_FALSE(r.bounds.empty()) << r.name;
        EXPECT_GT(r.bounds.extent().x * r.bounds.extent().z, 50.0f) << r.name; // rooms, not closets
    }
    EXPECT_EQ(names.size(), s.rooms.size()) << "room names must be unique";
    for (const char* path : {"walkthrough", "dolly", "static"})
        EXPECT_NE(s.findCameraPath(path), nullptr) << path;
    EXPECT_GT(s.findCameraPath("walkthrough")->duration(), 30.0f);
    EXPECT_TRUE(s.hasSun);
    EXPECT_GT(s.sun.toSun.y, 0.3f);

    // Plausible size: 100k–300k triangles, metres.
    EXPECT_GE(s.triangleCount(), 100000u);
    EXPECT_LE(s.triangleCount(), 300000u);
    EXPECT_GT(s.bounds.extent().x, 30.0f);
    EXPECT_LT(s.bounds.extent().x, 100.0f);
    EXPECT_NEAR(s.bounds.min.y, 0.0f, 0.01f);

    for (const TextureImage& image : s.images) {
        EXPECT_GE(image.width, 1024u) << image.name;
        EXPECT_GE(image.height, 1024u) << image.name;
    }
    size_t masked = 0;
    for (const Material& m : s.materials) {
        if (m.layers.size() >= 2 && m.layers[1].mask.texture.valid()) ++masked;
    }
    EXPECT_GE(masked, 3u) << "layered materials with texture masks";
}

TEST_F(Museum, RobotIsDynamicAndMoves) {
    const Scene& s = museum();
    ASSERT_FALSE(s.animations.empty());
    std::vector<size_t> dynamic;
    for (size_t i = 0; i < s.instances.size(); ++i) {
        if (s.instances[i].dynamic) dynamic.push_back(i);
    }
    EXPECT_GE(dynamic.size(), 5u) << "a robot of several parts";
    ScenePose a = s.evaluate(0.0), b = s.evaluate(1.0);
    for (size_t i : dynamic)
        EXPECT_NE(a.instanceWorld[i], b.instanceWorld[i]) << s.meshes[s.instances[i].mesh].name;
    for (size_t i = 0; i < s.instances.size(); ++i) {
        if (!s.instances[i].dynamic) {
            EXPECT_EQ(a.instanceWorld[i], b.instanceWorld[i]);
        }
    }
    // It loops: one lap later it is where it was.
    float lap = s.animations[0].endTime() - s.animations[0].startTime();
    ScenePose c = s.evaluate(1.0 + lap);
    for (size_t i : dynamic) {
        EXPECT_NEAR(glm::distance(glm::vec3(b.instanceWorld[i][3]), glm::vec3(c.instanceWorld[i][3])), 0.0f, 1e-3f);
    }
}

TEST_F(Museum, VerticesAreWellFormed) {
    const Scene& s = museum();
    std::vector<bool> lightmapped(s.meshes.size(), false);
    for (const MeshInstance& in : s.instances)
        lightmapped[in.mesh] = !in.dynamic;
    for (size_t m = 0; m < s.meshes.size(); ++m) {
        const Mesh& mesh = s.meshes[m];
        for (uint32_t p = 0; p < mesh.primitiveCount; ++p) {
            const Primitive& prim = s.primitives[mesh.firstPrimitive + p];
            for (uint32_t v = 0; v < prim.vertexCount; ++v) {
                const Vertex& x = s.vertices[prim.vertexOffset + v];
                ASSERT_NEAR(glm::length(x.normal), 1.0f, 1e-3f) << mesh.name;
                ASSERT_NEAR(glm::length(glm::vec3(x.tangent)), 1.0f, 1e-3f) << mesh.name;
                ASSERT_NEAR(glm::dot(glm::vec3(x.tangent), x.normal), 0.0f, 1e-3f) << mesh.name;
                ASSERT_TRUE(x.color.a > 0.0f && x.color.a <= 1.0f) << mesh.name;
                if (lightmapped[m]) {
                    ASSERT_TRUE(x.uv1.x >= 0.0f && x.uv1.x <= 1.0f && x.uv1.y >= 0.0f && x.uv1.y <= 1.0f) << mesh.name;
                }
            }
        }
    }
}

// The camera paths stay inside the building: every sample lies in a room or a doorway.
TEST_F(Museum, CameraPathsStayIndoors) {
    const Scene& s = museum();
    std::vector<Aabb> spaces;
    for (const Room& r : s.rooms) {
        Aabb inner = r.bounds;
        inner.min += glm::vec3(0.2f, 0.0f, 0.2f);
        inner.max -= glm::vec3(0.2f, 0.0f, 0.2f);
        spaces.push_back(inner);
    }
    // Doorways between the hall and the galleries (1.5 m either side of an axis, 0.4 m walls).
    spaces.push_back(Aabb{{-16.6f, 0.0f, -1.3f}, {-15.8f, 3.5f, 1.3f}});
    spaces.push_back(Aabb{{15.8f, 0.0f, -1.3f}, {16.6f, 3.5f, 1.3f}});
    spaces.push_back(Aabb{{-1.3f, 0.0f, 6.8f}, {1.3f, 3.5f, 7.6f}});
    for (const CameraPath& path : s.cameraPaths) {
        for (float t = path.keys.front().time; t <= path.keys.back().time; t += 0.1f) {
            glm::vec3 p = s.cameraAt(path.name, t).position;
            bool inside = std::any_of(spaces.begin(), spaces.end(), [&](const Aabb& b) { return b.contains(p); });
            EXPECT_TRUE(inside) << path.name << " at " << t << " s: (" << p.x << ", " << p.y << ", " << p.z << ")";
        }
    }
}

// Where along o + t d (t > 1e-4) the ray meets the triangle, either side; -1 if it does not.
float rayTriangleT(const glm::vec3& o, const glm::vec3& d, const glm::vec3& a, const glm::vec3& b, const glm::vec3& c) {
    glm::vec3 e1 = b - a, e2 = c - a, p = glm::cross(d, e2);
    float det = glm::dot(e1, p);
    if (std::abs(det) < 1e-12f) return -1.0f;
    glm::vec3 t = o - a;
    float u = glm::dot(t, p) / det;
    if (u < 0.0f || u > 1.0f) return -1.0f;
    glm::vec3 q = glm::cross(t, e1);
    float v = glm::dot(d, q) / det;
    if (v < 0.0f || u + v > 1.0f) return -1.0f;
    float along = glm::dot(e2, q) / det;
    return along > 1e-4f ? along : -1.0f;
}

bool rayHitsBox(const glm::vec3& o, const glm::vec3& d, const Aabb& box) {
    glm::vec3 t0 = (box.min - o) / d, t1 = (box.max - o) / d;
    glm::vec3 lo = glm::min(t0, t1), hi = glm::max(t0, t1);
    return std::max(std::max(lo.x, lo.y), lo.z) <= std::min(std::min(hi.x, hi.y), hi.z) &&
           std::min(std::min(hi.x, hi.y), hi.z) > 0.0f;
}

// The nearest surface along a ray from origin in direction dir (t in units of |dir|), brute force over every triangle
// at `pose`; infinity if none. anyHit: the first one found instead (a shadow ray's question).
float nearestSurface(const Scene& s, const ScenePose& pose, const glm::vec3& origin, const glm::vec3& dir,
                     bool anyHit = false) {
    float nearest = std::numeric_limits<float>::infinity();
    for (size_t i = 0; i < s.instances.size(); ++i) {
        const Mesh& mesh = s.meshes[s.instances[i].mesh];
        const glm::mat4& w = pose.instanceWorld[i];
        for (uint32_t p = 0; p < mesh.primitiveCount; ++p) {
            const Primitive& prim = s.primitives[mesh.firstPrimitive + p];
            if (!rayHitsBox(origin, dir, prim.bounds.transformed(w))) continue;
            for (uint32_t k = 0; k < prim.indexCount; k += 3) {
                glm::vec3 v[3];
                for (int j = 0; j < 3; ++j)
                    v[j] = glm::vec3(
                        w *
                        glm::vec4(s.vertices[prim.vertexOffset + s.indices[prim.firstIndex + k + j]].position, 1.0f));
                const float t = rayTriangleT(origin, dir, v[0], v[1], v[2]);
                if (t > 0.0f && anyHit) return t;
                if (t > 0.0f) nearest = std::min(nearest, t);
            }
        }
    }
    return nearest;
}

// The hall's three doorways open into galleries whose linings stand plan::kLiningGap in front of the hall's walls.
// Seen from inside a doorway, its jambs and head must be closed all the way to the lining: a ray aimed at a point of
// that gap's mouth meets a surface there, not a slot behind it (the black line down the frame beside the west doorway,
// whose hidden wall the bake cannot light; README, Fidelity).
TEST_F(Museum, DoorwaysAreClosedUpToTheGalleriesLinings) {
    using namespace museum::plan;
    const Scene& s = museum();
    const ScenePose pose = s.evaluate(0.0);
    struct Doorway {
        glm::vec3 inner;   // centre of the doorway's floor line on the hall's inner face
        glm::vec3 outward; // into the gallery
        glm::vec3 along;   // along the wall
    };
    const Doorway doorways[] = {{{-kHallX, 0, 0}, {-1, 0, 0}, {0, 0, 1}},
                                {{kHallX, 0, 0}, {1, 0, 0}, {0, 0, 1}},
                                {{0, 0, kHallZ}, {0, 0, 1}, {1, 0, 0}}};
    const glm::vec3 up(0, 1, 0);
    const float gapMiddle = kWall + 0.5f * kLiningGap;
    int rays = 0;
    auto expectClosedAt = [&](const glm::vec3& origin, const glm::vec3& aim, const char* where) {
        const float distance = glm::length(aim - origin);
        const float hit = nearestSurface(s, pose, origin, (aim - origin) / distance);
        EXPECT_NEAR(hit, distance, 2e-3f) << where << ": aimed at (" << aim.x << ", " << aim.y << ", " << aim.z
                                          << "), a surface " << hit << " m away instead of " << distance;
        ++rays;
    };
    for (const Doorway& d : doorways) {
        const glm::vec3 middle = d.inner + d.outward * (0.5f * kWall);
        for (float y : {0.3f, 1.2f, 2.4f, 3.5f}) {
            for (float side : {-1.0f, 1.0f}) {
                const glm::vec3 origin = middle + up * y + d.along * (0.6f * side);
                expectClosedAt(origin, d.inner + d.outward * gapMiddle + up * y + d.along * (kDoorHalf * side), "jamb");
            }
        }
        for (float a : {-1.2f, 0.0f, 1.1f}) {
            const glm::vec3 origin = middle + up * (kDoorH - 0.8f) + d.along * a;
            expectClosedAt(origin, d.inner + d.outward * gapMiddle + up * kDoorH + d.along * a, "head");
        }
    }
    EXPECT_EQ(rays, 3 * (8 + 3));
}

// Sunlight reaches the hall floor through the openings in patches: some floor points see the sun,
// most do not (a closed roof would give none, a missing one all).
TEST_F(Museum, SunlightFallsInPatches) {
    const Scene& s = museum();
    glm::vec3 toSun = glm::normalize(s.sun.toSun);
    ScenePose pose = s.evaluate(0.0);
    auto lit = [&](const glm::vec3& origin) {
        return nearestSurface(s, pose, origin, toSun, true) == std::numeric_limits<float>::infinity();
    };
    int litCount = 0, total = 0;
    for (float x = -15.0f; x <= 15.0f; x += 0.5f) {
        for (float z = -6.5f; z <= 6.5f; z += 0.5f) {
            litCount += lit({x + 0.37f, 0.01f, z + 0.21f}) ? 1 : 0;
            ++total;
        }
    }
    float fraction = float(litCount) / total;
    EXPECT_GT(fraction, 0.03f) << litCount << " of " << total;
    EXPECT_LT(fraction, 0.5f) << litCount << " of " << total;
    // Outside the building, under the open sky, the sun is never blocked from above.
    EXPECT_TRUE(lit({0.0f, 0.01f, -30.0f}));
}

} // namespace
} // namespace vitrine::scene
