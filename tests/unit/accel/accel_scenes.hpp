#pragma once

// Scenes and rays for the BVH tests (CPU: tests/unit/accel, GPU: tests/gpu/accel_test.cpp): closed meshes
// with shared vertices, a random triangle soup, a moving instance; rays aimed at edges and vertices; and
// the brute-force reference, a loop over every triangle of the scene in world space.

#include "core/accel/scene_bvh.hpp"
#include "core/accel/traverse.hpp"
#include "core/scene/scene.hpp"

#include <glm/gtc/matrix_transform.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <random>
#include <span>
#include <string>
#include <tuple>
#include <vector>

namespace vitrine::accel::test {

struct IndexedMesh {
    std::vector<glm::vec3> positions;
    std::vector<uint32_t> indices;
};

// The unit icosahedron subdivided `levels` times (20 * 4^levels triangles), vertices on the unit sphere and
// shared between neighbours (midpoints are cached per edge), wound counter-clockwise seen from outside.
inline IndexedMesh icosphere(int levels) {
    const float t = (1.0f + std::sqrt(5.0f)) / 2.0f;
    IndexedMesh m;
    for (glm::vec3 p : {glm::vec3(-1, t, 0), glm::vec3(1, t, 0), glm::vec3(-1, -t, 0), glm::vec3(1, -t, 0),
                        glm::vec3(0, -1, t), glm::vec3(0, 1, t), glm::vec3(0, -1, -t), glm::vec3(0, 1, -t),
                        glm::vec3(t, 0, -1), glm::vec3(t, 0, 1), glm::vec3(-t, 0, -1), glm::vec3(-t, 0, 1)})
        m.positions.push_back(glm::normalize(p));
    m.indices = {0, 11, 5, 0, 5, 1, 0, 1, 7, 0, 7, 10, 0, 10, 11, 1, 5, 9, 5, 11, 4,  11, 10, 2,  10, 7, 6, 7, 1, 8,
                 3, 9,  4, 3, 4, 2, 3, 2, 6, 3, 6, 8,  3, 8,  9,  4, 9, 5, 2, 4,  11, 6,  2,  10, 8,  6, 7, 9, 8, 1};
    for (int level = 0; level < levels; ++level) {
        std::map<std::pair<uint32_t, uint32_t>, uint32_t> midpoints;
        auto mid = [&](uint32_t a, uint32_t b) {
            auto key = std::minmax(a, b);
            auto [it, added] = midpoints.try_emplace(key, static_cast<uint32_t>(m.positions.size()));
            if (added) m.positions.push_back(glm::normalize(m.positions[a] + m.positions[b]));
            return it->second;
        };
        std::vector<uint32_t> next;
        for (size_t i = 0; i < m.indices.size(); i += 3) {
            uint32_t a = m.indices[i], b = m.indices[i + 1], c = m.indices[i + 2];
            uint32_t ab = mid(a, b), bc = mid(b, c), ca = mid(c, a);
            next.insert(next.end(), {a, ab, ca, b, bc, ab, c, ca, bc, ab, bc, ca});
        }
        m.indices = std::move(next);
    }
    return m;
}

// The cube [-1, 1]^3 with n x n quads (two triangles each) per face; vertices along the cube's edges and
// corners are shared by the faces that meet there. Its boxes are flat where its faces are.
inline IndexedMesh tessellatedCube(int n) {
    IndexedMesh m;
    std::map<std::tuple<int, int, int>, uint32_t> ids; // integer grid coordinates in [0, n]^3
    auto vertex = [&](glm::ivec3 g) {
        auto [it, added] = ids.try_emplace({g.x, g.y, g.z}, static_cast<uint32_t>(m.positions.size()));
        if (added) m.positions.push_back(glm::vec3(g) * (2.0f / n) - 1.0f);
        return it->second;
    };
    for (int axis = 0; axis < 3; ++axis)
        for (int side = 0; side < 2; ++side) {
            int u = (axis + 1) % 3, v = (axis + 2) % 3;
            for (int i = 0; i < n; ++i)
                for (int j = 0; j < n; ++j) {
                    glm::ivec3 g[4];
                    for (int k = 0; k < 4; ++k) {
                        g[k][axis] = side * n;
                        g[k][u] = i + (k == 1 || k == 2);
                        g[k][v] = j + (k >= 2);
                    }
                    uint32_t q[4] = {vertex(g[0]), vertex(g[1]), vertex(g[2]), vertex(g[3])};
                    // Counter-clockwise from outside: (u, v, axis) is right-handed, so flip for the - side.
                    if (side == 1)
                        m.indices.insert(m.indices.end(), {q[0], q[1], q[2], q[0], q[2], q[3]});
                    else
                        m.indices.insert(m.indices.end(), {q[0], q[2], q[1], q[0], q[3], q[2]});
                }
        }
    return m;
}

inline void ensureMaterial(scene::Scene& s) {
    if (!s.materials.empty()) return;
    scene::Material m;
    m.name = "default";
    m.layers.emplace_back();
    s.materials.push_back(m);
}

inline uint32_t addMesh(scene::Scene& s, const std::string& name, const IndexedMesh& mesh) {
    ensureMaterial(s);
    scene::Primitive p;
    p.firstIndex = static_cast<uint32_t>(s.indices.size());
    p.indexCount = static_cast<uint32_t>(mesh.indices.size());
    p.vertexOffset = static_cast<uint32_t>(s.vertices.size());
    p.vertexCount = static_cast<uint32_t>(mesh.positions.size());
    for (const glm::vec3& pos : mesh.positions) {
        scene::Vertex v;
        v.position = pos;
        s.vertices.push_back(v);
    }
    s.indices.insert(s.indices.end(), mesh.indices.begin(), mesh.indices.end());
    s.primitives.push_back(p);
    scene::Mesh m;
    m.name = name;
    m.firstPrimitive = static_cast<uint32_t>(s.primitives.size() - 1);
    m.primitiveCount = 1;
    s.meshes.push_back(m);
    return static_cast<uint32_t>(s.meshes.size() - 1);
}

inline uint32_t addRootNode(scene::Scene& s, const std::string& name, uint32_t mesh, const scene::Transform& t = {}) {
    scene::Node n;
    n.name = name;
    n.mesh = static_cast<int32_t>(mesh);
    n.local = t;
    s.nodes.push_back(n);
    s.roots.push_back(static_cast<uint32_t>(s.nodes.size() - 1));
    return static_cast<uint32_t>(s.nodes.size() - 1);
}

// Makes node dynamic: its translation moves linearly from `from` (t = 0 s) to `to` (t = 1 s).
inline void animateTranslation(scene::Scene& s, uint32_t node, glm::vec3 from, glm::vec3 to) {
    scene::Animation a;
    a.name = s.nodes[node].name + ".move";
    scene::AnimationSampler sampler;
    sampler.times = {0.0f, 1.0f};
    sampler.values = {glm::vec4(from, 0.0f), glm::vec4(to, 0.0f)};
    a.samplers.push_back(sampler);
    a.channels.push_back({node, scene::AnimationPath::Translation, 0});
    s.animations.push_back(a);
}

inline scene::Transform transform(glm::vec3 translation, glm::quat rotation = glm::quat(1, 0, 0, 0),
                                  glm::vec3 scale = glm::vec3(1)) {
    scene::Transform t;
    t.translation = translation;
    t.rotation = rotation;
    t.scale = scale;
    return t;
}

// count random triangles in [-1, 1]^3, edge lengths from 0.002 to 0.5 (and a few long slivers), split over
// three meshes with one static instance each (one of them rotated and scaled).
inline scene::Scene randomSoup(uint32_t count, uint32_t seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> unit(-1.0f, 1.0f), size(0.002f, 0.5f);
    scene::Scene s;
    s.name = "soup";
    for (int part = 0; part < 3; ++part) {
        IndexedMesh m;
        for (uint32_t i = 0; i < count / 3; ++i) {
            glm::vec3 c(unit(rng), unit(rng), unit(rng));
            float r = i % 50 == 0 ? 1.5f : size(rng);
            for (int k = 0; k < 3; ++k) {
                m.positions.push_back(c + r * glm::vec3(unit(rng), unit(rng), unit(rng)));
                m.indices.push_back(static_cast<uint32_t>(m.positions.size() - 1));
            }
        }
        uint32_t mesh = addMesh(s, "soup" + std::to_string(part), m);
        scene::Transform t =
            part == 2 ? transform({0.3f, -0.2f, 0.1f}, glm::angleAxis(0.7f, glm::normalize(glm::vec3(1, 2, 3))),
                                  glm::vec3(1.2f, 0.8f, 1.0f))
                      : scene::Transform{};
        addRootNode(s, "soup" + std::to_string(part), mesh, t);
    }
    s.finalize();
    s.validate();
    return s;
}

// World-space triangles of a scene at a pose (instances the pose lacks at rest), for brute force. Static
// instances are transformed exactly as the BVH's static level is (transformPoint), so equal rays give
// equal answers.
struct WorldTriangles {
    std::vector<glm::vec3> v; // 3 per triangle
    std::vector<GpuBvhTriangleRef> refs;
};

// Every BVH triangle of s at pose in world space; vertices: Scene::vertices with the deforming meshes posed (empty:
// Scene::vertices).
inline WorldTriangles worldTriangles(const scene::Scene& s, const scene::ScenePose& pose = {},
                                     std::span<const scene::Vertex> vertices = {}) {
    if (vertices.empty()) vertices = s.vertices;
    WorldTriangles w;
    for (uint32_t i = 0; i < s.instances.size(); ++i) {
        const scene::MeshInstance& inst = s.instances[i];
        const glm::mat4& world = inst.dynamic && i < pose.instanceWorld.size() ? pose.instanceWorld[i] : inst.world;
        const scene::Mesh& mesh = s.meshes[inst.mesh];
        for (uint32_t p = mesh.firstPrimitive; p < mesh.firstPrimitive + mesh.primitiveCount; ++p) {
            const scene::Primitive& prim = s.primitives[p];
            if (s.materials[prim.material].transparent()) continue; // glass is not in the BVH
            for (uint32_t t = 0; t < prim.indexCount / 3; ++t) {
                for (uint32_t k = 0; k < 3; ++k)
                    w.v.push_back(transformPoint(
                        world, vertices[prim.vertexOffset + s.indices[prim.firstIndex + 3 * t + k]].position));
                w.refs.push_back({i, p, t, prim.material});
            }
        }
    }
    return w;
}

struct BruteHit {
    float t = std::numeric_limits<float>::infinity();
    uint32_t index = kNone; // into WorldTriangles
    bool valid() const { return index != kNone; }
};

inline BruteHit bruteForce(const WorldTriangles& w, const Ray& ray) {
    TraversalRay r(ray.origin, ray.direction);
    BruteHit best;
    best.t = ray.tmax;
    for (size_t i = 0; i < w.refs.size(); ++i) {
        float t;
        glm::vec2 uv;
        if (r.intersectTriangle(w.v[3 * i], w.v[3 * i + 1], w.v[3 * i + 2], ray.tmin, best.t, t, uv)) {
            best.t = t;
            best.index = static_cast<uint32_t>(i);
        }
    }
    if (!best.valid()) best.t = std::numeric_limits<float>::infinity();
    return best;
}

inline bool sameSource(const GpuBvhTriangleRef& a, const GpuBvhTriangleRef& b) {
    return a.instance == b.instance && a.primitive == b.primitive && a.triangle == b.triangle;
}

// A refit test's motion of a static-level triangle (ref names its instance): its world corners twisted about +Y by
// 0.8 rad per unit of height, then the whole triangle shifted by up to 0.4 per axis, drawn from its ref; far from
// where the build split it.
inline void movedTriangle(const scene::Scene& s, const GpuBvhTriangleRef& ref, glm::vec3 (&v)[3]) {
    std::mt19937 rng(ref.primitive * 7919u + ref.triangle * 31u + ref.instance);
    std::uniform_real_distribution<float> u(-0.4f, 0.4f);
    const glm::vec3 shift(u(rng), u(rng), u(rng));
    const scene::Primitive& p = s.primitives[ref.primitive];
    for (uint32_t k = 0; k < 3; ++k) {
        const glm::vec3 q =
            transformPoint(s.instances[ref.instance].world,
                           s.vertices[p.vertexOffset + s.indices[p.firstIndex + 3 * ref.triangle + k]].position);
        const float a = 0.8f * q.y, c = std::cos(a), sn = std::sin(a);
        v[k] = glm::vec3(c * q.x + sn * q.z, q.y, -sn * q.x + c * q.z) + shift;
    }
}

inline glm::vec3 randomUnit(std::mt19937& rng) {
    std::normal_distribution<float> n;
    glm::vec3 v;
    do
        v = glm::vec3(n(rng), n(rng), n(rng));
    while (glm::dot(v, v) < 1e-12f);
    return glm::normalize(v);
}

// Rays for comparing against brute force: a third from random points in the scene's box in random
// directions, a third aimed at random points of random triangles (so most hit), a third aimed at random
// triangles' edges or vertices (ties between neighbours). tmin 0, tmax infinite.
inline std::vector<Ray> randomRays(const WorldTriangles& w, const scene::Aabb& bounds, size_t count, uint32_t seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u01(0.0f, 1.0f);
    std::uniform_int_distribution<size_t> tri(0, w.refs.size() - 1);
    std::vector<Ray> rays;
    for (size_t i = 0; i < count; ++i) {
        glm::vec3 o = bounds.min + glm::vec3(u01(rng), u01(rng), u01(rng)) * (bounds.max - bounds.min);
        Ray r;
        r.origin = o;
        if (i % 3 == 0) {
            r.direction = randomUnit(rng);
        } else {
            size_t t = tri(rng);
            float a = u01(rng), b = u01(rng);
            if (i % 3 == 2) (u01(rng) < 0.5f ? a : b) = 0.0f; // on an edge (or a vertex, when both end up 0 or 1)
            if (a + b > 1.0f) a = 1.0f - a, b = 1.0f - b;
            glm::vec3 target = w.v[3 * t] + a * (w.v[3 * t + 1] - w.v[3 * t]) + b * (w.v[3 * t + 2] - w.v[3 * t]);
            r.direction = target - o;
            if (glm::dot(r.direction, r.direction) < 1e-12f) r.direction = randomUnit(rng);
        }
        rays.push_back(r);
    }
    return rays;
}

// Rays from random points inside a closed convex mesh (within `radius` of `center`) aimed at points on its
// edges (uniform along the edge) and at its vertices, in world space. direction = target - origin, so the
// surface is met at t = 1 (up to rounding). A leak is a miss.
inline std::vector<Ray> edgeRays(const std::vector<glm::vec3>& world, const std::vector<uint32_t>& indices,
                                 glm::vec3 center, float radius, size_t count, uint32_t seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u01(0.0f, 1.0f);
    std::uniform_int_distribution<size_t> tri(0, indices.size() / 3 - 1);
    std::vector<Ray> rays(count);
    for (size_t i = 0; i < count; ++i) {
        size_t t = tri(rng);
        uint32_t e = static_cast<uint32_t>(i % 3);
        const glm::vec3& a = world[indices[3 * t + e]];
        const glm::vec3& b = world[indices[3 * t + (e + 1) % 3]];
        glm::vec3 target = i % 4 == 0 ? a : a + u01(rng) * (b - a);
        rays[i].origin = center + radius * std::cbrt(u01(rng)) * randomUnit(rng);
        rays[i].direction = target - rays[i].origin;
    }
    return rays;
}

} // namespace vitrine::accel::test
