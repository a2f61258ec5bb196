// Generated tangents: orthogonal to the normal, along the UV gradient, with glTF's handedness.

#include "core/scene/tangents.hpp"

#include <cmath>

#include <gtest/gtest.h>

namespace vitrine::scene {
namespace {

// A unit quad in the xz-plane (normal +y) whose uv = M · (x, z) + (0.5, 0.5).
std::vector<Vertex> planarQuad(const glm::mat2& m) {
    const glm::vec2 xz[4] = {{0, 0}, {1, 0}, {1, -1}, {0, -1}};
    std::vector<Vertex> v(4);
    for (int i = 0; i < 4; ++i) {
        v[i].position = glm::vec3(xz[i].x, 0.0f, xz[i].y);
        v[i].normal = glm::vec3(0, 1, 0);
        v[i].uv0 = m * xz[i] + glm::vec2(0.5f);
    }
    return v;
}

const std::vector<uint32_t> kQuadIndices = {0, 1, 2, 0, 2, 3};

TEST(Tangents, FollowTheUvGradientOnAKnownQuad) {
    // u = x, v = -z: dP/du = +x and dP/dv = -z.
    std::vector<Vertex> v = planarQuad(glm::mat2(1, 0, 0, -1));
    generateTangents(v, kQuadIndices);
    for (const Vertex& x : v) {
        EXPECT_NEAR(x.tangent.x, 1.0f, 1e-6f);
        EXPECT_NEAR(x.tangent.y, 0.0f, 1e-6f);
        EXPECT_NEAR(x.tangent.z, 0.0f, 1e-6f);
        // bitangent = cross(n, t) · w = cross(+y, +x) · w = -z · w must point along -v, i.e. +z: w = -1.
        EXPECT_EQ(x.tangent.w, -1.0f);
    }
}

TEST(Tangents, RotatedAndScaledMapping) {
    // uv = R(30°) · S(2, 0.5) · (x, z): the tangent must keep v constant and increase u.
    float c = std::cos(0.5236f), s = std::sin(0.5236f);
    glm::mat2 m = glm::mat2(c, s, -s, c) * glm::mat2(2.0f, 0.0f, 0.0f, 0.5f);
    std::vector<Vertex> v = planarQuad(m);
    generateTangents(v, kQuadIndices);
    // Gradients of u and v in the plane: the rows of m, as world vectors (x, 0, z).
    glm::vec3 gradU(m[0][0], 0.0f, m[1][0]), gradV(m[0][1], 0.0f, m[1][1]);
    for (const Vertex& x : v) {
        glm::vec3 t(x.tangent);
        EXPECT_NEAR(glm::length(t), 1.0f, 1e-5f);
        EXPECT_NEAR(glm::dot(t, x.normal), 0.0f, 1e-6f);
        EXPECT_NEAR(glm::dot(t, gradV), 0.0f, 1e-5f);
        EXPECT_GT(glm::dot(t, gradU), 0.0f);
        glm::vec3 bitangent = glm::cross(x.normal, t) * x.tangent.w;
        EXPECT_LT(glm::dot(bitangent, gradV), 0.0f); // towards -v: "up" in the image
    }
}

TEST(Tangents, MirroredUvFlipsTheSign) {
    std::vector<Vertex> v = planarQuad(glm::mat2(-1, 0, 0, -1)); // u runs along -x
    generateTangents(v, kQuadIndices);
    for (const Vertex& x : v) {
        EXPECT_NEAR(x.tangent.x, -1.0f, 1e-6f);
        EXPECT_EQ(x.tangent.w, 1.0f);
    }
}

TEST(Tangents, OrthogonalToSmoothNormalsOnASphere) {
    const int rings = 12, segments = 24;
    std::vector<Vertex> v;
    std::vector<uint32_t> idx;
    for (int r = 0; r <= rings; ++r) {
        for (int s = 0; s <= segments; ++s) {
            float theta = 3.14159265f * r / rings, phi = 6.2831853f * s / segments;
            Vertex x;
            x.position = glm::vec3(std::sin(theta) * std::cos(phi), std::cos(theta), std::sin(theta) * std::sin(phi));
            x.uv0 = glm::vec2(float(s) / segments, float(r) / rings);
            v.push_back(x);
        }
    }
    for (int r = 0; r < rings; ++r) {
        for (int s = 0; s < segments; ++s) {
            uint32_t a = r * (segments + 1) + s, b = a + segments + 1;
            idx.insert(idx.end(), {a, a + 1, b, a + 1, b + 1, b});
        }
    }
    generateSmoothNormals(v, idx);
    generateTangents(v, idx);
    for (size_t i = 0; i < v.size(); ++i) {
        const Vertex& x = v[i];
        EXPECT_NEAR(glm::length(x.normal), 1.0f, 1e-5f);
        EXPECT_NEAR(glm::length(glm::vec3(x.tangent)), 1.0f, 1e-5f) << i;
        EXPECT_NEAR(glm::dot(glm::vec3(x.tangent), x.normal), 0.0f, 1e-5f) << i;
        EXPECT_TRUE(x.tangent.w == 1.0f || x.tangent.w == -1.0f);
        if (i > static_cast<size_t>(segments) && i < v.size() - segments - 1) { // away from the poles
            EXPECT_GT(glm::dot(x.normal, x.position), 0.99f) << i;
        }
    }
}

TEST(Tangents, DegenerateUvsStillGiveAPerpendicularUnitTangent) {
    std::vector<Vertex> v = planarQuad(glm::mat2(0.0f));
    generateTangents(v, kQuadIndices);
    for (const Vertex& x : v) {
        EXPECT_NEAR(glm::length(glm::vec3(x.tangent)), 1.0f, 1e-6f);
        EXPECT_NEAR(glm::dot(glm::vec3(x.tangent), x.normal), 0.0f, 1e-6f);
    }
}

} // namespace
} // namespace vitrine::scene
