#pragma once

// Collects the triangles of one museum mesh (one primitive per material) and, when the mesh is static,
// its lightmap charts: every surface patch is given 2D chart coordinates in metres, and commit() packs
// the charts into the unit square (uv1) at one texel density for the whole mesh, kChartGapMeters apart.

#include "core/scene/scene.hpp"

#include <string>
#include <vector>

namespace vitrine::scene::museum {

// The gap between two lightmap charts, metres: 3 texels at bake.lightmap's default 4 texels per metre, so that
// bilinear filtering of one chart's border never reads the next chart's light (the atlas keeps the gap at least
// that many texels at other densities: Mesh::lightmapChartGap).
inline constexpr float kChartGapMeters = 0.75f;

class MeshBuilder {
public:
    explicit MeshBuilder(std::string name) : mName(std::move(name)) {}

    // Following triangles use this material.
    void material(uint32_t material);
    // Following vertices belong to a new lightmap chart.
    void chart() { ++mChart; }
    // Applied to following vertices (positions, normals, and the chart scale). Rigid + uniform scale.
    void transform(const glm::mat4& m);
    const glm::mat4& transform() const { return mTransform; }

    // chartUv: the vertex's position in its chart's plane, metres (before the transform's scale).
    uint32_t vertex(const glm::vec3& p, const glm::vec3& n, const glm::vec2& uv, const glm::vec2& chartUv,
                    float ao = 1.0f);
    // Counter-clockwise seen from the front (glTF's front faces).
    void triangle(uint32_t a, uint32_t b, uint32_t c);
    void quad(uint32_t a, uint32_t b, uint32_t c, uint32_t d);

    size_t triangleCount() const;
    bool empty() const { return triangleCount() == 0; }

    // Appends the mesh to the scene: tangents generated, lightmap UVs packed (unless lightmapped is
    // false: dynamic meshes are lit by probes). Returns the mesh index.
    uint32_t commit(Scene& scene, bool lightmapped = true);

private:
    struct Part {
        uint32_t material = 0;
        std::vector<Vertex> vertices;
        std::vector<uint32_t> indices;
        std::vector<uint32_t> charts;    // per vertex
        std::vector<glm::vec2> chartUvs; // per vertex, metres
    };
    // Packs the charts into uv1; returns the gap between charts in uv1 units (Mesh::lightmapChartGap).
    float packCharts();

    std::string mName;
    std::vector<Part> mParts;
    size_t mCurrent = 0;
    uint32_t mChart = 0;
    glm::mat4 mTransform{1.0f};
    glm::mat3 mNormalMatrix{1.0f};
    float mScale = 1.0f;
};

} // namespace vitrine::scene::museum
