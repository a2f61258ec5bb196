#include "core/scene/museum/mesh_builder.hpp"

#include "core/scene/tangents.hpp"

#include <algorithm>
#include <cmath>
#include <map>

namespace vitrine::scene::museum {

void MeshBuilder::material(uint32_t material) {
    for (size_t i = 0; i < mParts.size(); ++i) {
        if (mParts[i].material == material) {
            mCurrent = i;
            return;
        }
    }
    mParts.push_back(Part{material, {}, {}, {}, {}});
    mCurrent = mParts.size() - 1;
}

void MeshBuilder::transform(const glm::mat4& m) {
    mTransform = m;
    glm::mat3 linear(m);
    mScale = std::cbrt(std::abs(glm::determinant(linear)));
    mNormalMatrix = glm::transpose(glm::inverse(linear));
}

uint32_t MeshBuilder::vertex(const glm::vec3& p, const glm::vec3& n, const glm::vec2& uv, const glm::vec2& chartUv,
                             float ao) {
    if (mParts.empty()) material(0);
    Part& part = mParts[mCurrent];
    Vertex v;
    v.position = glm::vec3(mTransform * glm::vec4(p, 1.0f));
    v.normal = glm::normalize(mNormalMatrix * n);
    v.uv0 = uv;
    v.color = glm::vec4(1.0f, 1.0f, 1.0f, ao);
    part.vertices.push_back(v);
    part.charts.push_back(mChart);
    part.chartUvs.push_back(chartUv * mScale);
    return static_cast<uint32_t>(part.vertices.size() - 1);
}

void MeshBuilder::triangle(uint32_t a, uint32_t b, uint32_t c) {
    std::vector<uint32_t>& idx = mParts[mCurrent].indices;
    idx.insert(idx.end(), {a, b, c});
}

void MeshBuilder::quad(uint32_t a, uint32_t b, uint32_t c, uint32_t d) {
    triangle(a, b, c);
    triangle(a, c, d);
}

size_t MeshBuilder::triangleCount() const {
    size_t n = 0;
    for (const Part& p : mParts)
        n += p.indices.size() / 3;
    return n;
}

float MeshBuilder::packCharts() {
    struct Chart {
        glm::vec2 min{1e30f}, max{-1e30f};
        bool rotated = false;
        glm::vec2 offset{0.0f};
        glm::vec2 size() const { return rotated ? glm::vec2(max.y - min.y, max.x - min.x) : max - min; }
    };
    std::map<uint32_t, Chart> charts;
    for (const Part& p : mParts) {
        for (size_t i = 0; i < p.vertices.size(); ++i) {
            Chart& c = charts[p.charts[i]];
            c.min = glm::min(c.min, p.chartUvs[i]);
            c.max = glm::max(c.max, p.chartUvs[i]);
        }
    }
    if (charts.empty()) return 0.0f;
    // A gap of kChartGapMeters between charts and around them (the atlas turns it into enough texels).
    const float padding = kChartGapMeters;
    float area = 0.0f, widest = 0.0f; // area: of the charts with their gaps
    for (auto& [id, c] : charts) {
        glm::vec2 s = c.max - c.min;
        c.rotated = s.y > s.x; // lay every chart on its long side: shelves waste less
        glm::vec2 r = c.size();
        area += (r.x + padding) * (r.y + padding);
        widest = std::max(widest, r.x);
    }
    std::vector<Chart*> order;
    for (auto& [id, c] : charts)
        order.push_back(&c);
    std::stable_sort(order.begin(), order.end(),
                     [](const Chart* a, const Chart* b) { return a->size().y > b->size().y; });
    float shelfWidth = std::max(widest + 2 * padding, std::sqrt(area) * 1.15f);
    glm::vec2 cursor(padding);
    float shelfHeight = 0.0f, usedWidth = 0.0f;
    for (Chart* c : order) {
        glm::vec2 s = c->size();
        if (cursor.x + s.x + padding > shelfWidth && cursor.x > padding) {
            cursor = glm::vec2(padding, cursor.y + shelfHeight + padding);
            shelfHeight = 0.0f;
        }
        c->offset = cursor;
        cursor.x += s.x + padding;
        usedWidth = std::max(usedWidth, cursor.x);
        shelfHeight = std::max(shelfHeight, s.y);
    }
    float extent = std::max(usedWidth, cursor.y + shelfHeight + padding);
    for (Part& p : mParts) {
        for (size_t i = 0; i < p.vertices.size(); ++i) {
            const Chart& c = charts[p.charts[i]];
            glm::vec2 local = p.chartUvs[i] - c.min;
            if (c.rotated) local = glm::vec2(local.y, local.x);
            p.vertices[i].uv1 = (c.offset + local) / extent;
        }
    }
    return padding / extent;
}

uint32_t MeshBuilder::commit(Scene& scene, bool lightmapped) {
    Mesh mesh;
    mesh.name = mName;
    if (lightmapped) mesh.lightmapChartGap = packCharts();
    mesh.firstPrimitive = static_cast<uint32_t>(scene.primitives.size());
    for (Part& p : mParts) {
        if (p.indices.empty()) continue;
        generateTangents(p.vertices, p.indices);
        Primitive prim;
        prim.firstIndex = static_cast<uint32_t>(scene.indices.size());
        prim.indexCount = static_cast<uint32_t>(p.indices.size());
        prim.vertexOffset = static_cast<uint32_t>(scene.vertices.size());
        prim.vertexCount = static_cast<uint32_t>(p.vertices.size());
        prim.material = p.material;
        prim.lightmapUvs = lightmapped;
        scene.vertices.insert(scene.vertices.end(), p.vertices.begin(), p.vertices.end());
        scene.indices.insert(scene.indices.end(), p.indices.begin(), p.indices.end());
        scene.primitives.push_back(prim);
    }
    mesh.primitiveCount = static_cast<uint32_t>(scene.primitives.size()) - mesh.firstPrimitive;
    scene.meshes.push_back(mesh);
    return static_cast<uint32_t>(scene.meshes.size() - 1);
}

} // namespace vitrine::scene::museum
