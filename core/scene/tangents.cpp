#include "core/scene/tangents.hpp"

#include <cmath>
#include <vector>

namespace vitrine::scene {

namespace {

float cornerAngle(const glm::vec3& a, const glm::vec3& b) {
    float la = glm::length(a), lb = glm::length(b);
    if (la <= 0.0f || lb <= 0.0f) return 0.0f;
    return std::acos(glm::clamp(glm::dot(a, b) / (la * lb), -1.0f, 1.0f));
}

glm::vec3 anyPerpendicular(const glm::vec3& n) {
    glm::vec3 axis = std::abs(n.x) < 0.9f ? glm::vec3(1, 0, 0) : glm::vec3(0, 1, 0);
    return glm::normalize(axis - n * glm::dot(axis, n));
}

} // namespace

void generateTangents(std::span<Vertex> vertices, std::span<const uint32_t> indices) {
    std::vector<glm::vec3> tangent(vertices.size(), glm::vec3(0.0f));
    std::vector<glm::vec3> bitangent(vertices.size(), glm::vec3(0.0f));
    for (size_t i = 0; i + 2 < indices.size(); i += 3) {
        uint32_t idx[3] = {indices[i], indices[i + 1], indices[i + 2]};
        const Vertex& v0 = vertices[idx[0]];
        const Vertex& v1 = vertices[idx[1]];
        const Vertex& v2 = vertices[idx[2]];
        glm::vec3 e1 = v1.position - v0.position, e2 = v2.position - v0.position;
        glm::vec2 d1 = v1.uv0 - v0.uv0, d2 = v2.uv0 - v0.uv0;
        float det = d1.x * d2.y - d2.x * d1.y;
        if (std::abs(det) < 1e-20f) continue;
        glm::vec3 t = (e1 * d2.y - e2 * d1.y) / det;
        glm::vec3 b = (e2 * d1.x - e1 * d2.x) / det;
        float lt = glm::length(t), lb = glm::length(b);
        if (!(lt > 0.0f) || !(lb > 0.0f) || !std::isfinite(lt) || !std::isfinite(lb)) continue;
        t /= lt;
        b /= lb;
        for (int c = 0; c < 3; ++c) {
            const glm::vec3& p = vertices[idx[c]].position;
            float w = cornerAngle(vertices[idx[(c + 1) % 3]].position - p, vertices[idx[(c + 2) % 3]].position - p);
            tangent[idx[c]] += t * w;
            bitangent[idx[c]] += b * w;
        }
    }
    for (size_t v = 0; v < vertices.size(); ++v) {
        glm::vec3 n = vertices[v].normal;
        float ln = glm::length(n);
        n = ln > 0.0f ? n / ln : glm::vec3(0, 0, 1);
        glm::vec3 t = tangent[v] - n * glm::dot(tangent[v], n);
        float lt = glm::length(t);
        if (lt < 1e-12f || !std::isfinite(lt)) {
            vertices[v].tangent = glm::vec4(anyPerpendicular(n), 1.0f);
            continue;
        }
        t /= lt;
        // The bitangent we accumulated is dP/dv; glTF's cross(n, t) * w must point the other way.
        float w = glm::dot(glm::cross(n, t), bitangent[v]) > 0.0f ? -1.0f : 1.0f;
        vertices[v].tangent = glm::vec4(t, w);
    }
}

void generateSmoothNormals(std::span<Vertex> vertices, std::span<const uint32_t> indices) {
    std::vector<glm::vec3> normal(vertices.size(), glm::vec3(0.0f));
    for (size_t i = 0; i + 2 < indices.size(); i += 3) {
        const glm::vec3& a = vertices[indices[i]].position;
        const glm::vec3& b = vertices[indices[i + 1]].position;
        const glm::vec3& c = vertices[indices[i + 2]].position;
        glm::vec3 n = glm::cross(b - a, c - a); // length = 2 × area: area weighting for free
        for (int k = 0; k < 3; ++k)
            normal[indices[i + k]] += n;
    }
    for (size_t v = 0; v < vertices.size(); ++v) {
        float l = glm::length(normal[v]);
        vertices[v].normal = l > 0.0f ? normal[v] / l : glm::vec3(0, 1, 0);
    }
}

} // namespace vitrine::scene
