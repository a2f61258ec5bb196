#include "core/bake/lightmap_atlas.hpp"

#include "core/base/error.hpp"
#include "core/scene/scene.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace vitrine::bake {

namespace {

struct Areas {
    double world = 0.0; // m², after the instance's transform
    double uv = 0.0;    // in uv1 space
};

// The world-space and uv1 areas of an instance's lightmapped triangles.
Areas measure(const scene::Scene& s, const scene::MeshInstance& inst) {
    Areas a;
    const scene::Mesh& mesh = s.meshes[inst.mesh];
    for (uint32_t i = 0; i < mesh.primitiveCount; ++i) {
        const scene::Primitive& p = s.primitives[mesh.firstPrimitive + i];
        if (!p.lightmapUvs) continue;
        for (uint32_t t = 0; t + 2 < p.indexCount; t += 3) {
            const scene::Vertex* v[3];
            for (int k = 0; k < 3; ++k) v[k] = &s.vertices[p.vertexOffset + s.indices[p.firstIndex + t + k]];
            glm::dvec3 w[3];
            for (int k = 0; k < 3; ++k) w[k] = glm::dvec3(inst.world * glm::vec4(v[k]->position, 1.0f));
            a.world += 0.5 * glm::length(glm::cross(w[1] - w[0], w[2] - w[0]));
            glm::dvec2 e1 = glm::dvec2(v[1]->uv1 - v[0]->uv1), e2 = glm::dvec2(v[2]->uv1 - v[0]->uv1);
            a.uv += 0.5 * std::abs(e1.x * e2.y - e1.y * e2.x);
        }
    }
    return a;
}

bool hasLightmapUvs(const scene::Scene& s, const scene::MeshInstance& inst) {
    const scene::Mesh& mesh = s.meshes[inst.mesh];
    for (uint32_t i = 0; i < mesh.primitiveCount; ++i)
        if (s.primitives[mesh.firstPrimitive + i].lightmapUvs) return true;
    return false;
}

} // namespace

double LightmapAtlas::coverage() const {
    if (width == 0 || height == 0) return 0.0;
    double texels = 0.0;
    for (const LightmapRegion& r : regions) texels += double(r.size) * r.size;
    return texels / (double(width) * height);
}

LightmapAtlas planLightmapAtlas(const scene::Scene& s, const LightmapAtlasOptions& o) {
    if (!(o.texelsPerMeter > 0.0f) || o.minSize == 0 || o.maxSize < o.minSize || o.atlasWidth == 0)
        throw UserError("lightmap atlas: expected texels_per_meter > 0 and 1 <= min_size <= max_size");
    if (o.maxSize + 2 * o.gutter > o.atlasWidth)
        throw UserError("lightmap atlas: a region of " + std::to_string(o.maxSize) + " texels plus its gutter does "
                        "not fit an atlas " + std::to_string(o.atlasWidth) + " texels wide");

    LightmapAtlas atlas;
    atlas.regionOfInstance.assign(s.instances.size(), -1);
    for (uint32_t i = 0; i < s.instances.size(); ++i) {
        const scene::MeshInstance& inst = s.instances[i];
        if (inst.dynamic) {
            atlas.skipped.emplace_back(i, "dynamic");
            continue;
        }
        if (!hasLightmapUvs(s, inst)) {
            atlas.skipped.emplace_back(i, "no lightmap UVs (TEXCOORD_1)");
            continue;
        }
        const Areas a = measure(s, inst);
        if (!(a.uv > 0.0) || !(a.world > 0.0)) {
            atlas.skipped.emplace_back(i, "degenerate lightmap UVs (zero area)");
            continue;
        }
        // size² texels over the uv square: world area per texel = world / (uv size²) = 1 / texelsPerMeter².
        // (The small allowance keeps float noise in the areas from adding a texel row to an exact size.)
        double size = std::ceil(o.texelsPerMeter * std::sqrt(a.world / a.uv) - 1e-3);
        // Charts a known distance apart get at least minChartGap texels between them.
        const float gap = s.meshes[inst.mesh].lightmapChartGap;
        if (gap > 0.0f) size = std::max(size, std::ceil(double(o.minChartGap) / gap - 1e-3));
        LightmapRegion r;
        r.instance = i;
        r.size = static_cast<uint32_t>(std::clamp(size, double(o.minSize), double(o.maxSize)));
        if (gap > 0.0f && float(r.size) * gap < o.minChartGap)
            atlas.narrowChartGaps.emplace_back(i, float(r.size) * gap);
        atlas.regions.push_back(r);
    }

    // Shelf packing, tallest first (ties by instance, so the plan does not depend on sort stability).
    std::vector<size_t> order(atlas.regions.size());
    std::iota(order.begin(), order.end(), size_t(0));
    std::sort(order.begin(), order.end(), [&](size_t a, size_t b) {
        const LightmapRegion &ra = atlas.regions[a], &rb = atlas.regions[b];
        return ra.size != rb.size ? ra.size > rb.size : ra.instance < rb.instance;
    });
    uint32_t x = 0, y = 0, shelf = 0;
    for (size_t k : order) {
        LightmapRegion& r = atlas.regions[k];
        const uint32_t cell = r.size + 2 * o.gutter;
        if (x + cell > o.atlasWidth) {
            x = 0;
            y += shelf;
            shelf = 0;
        }
        r.x = x + o.gutter;
        r.y = y + o.gutter;
        x += cell;
        shelf = std::max(shelf, cell);
    }
    atlas.width = o.atlasWidth;
    atlas.height = std::max(4u, (y + shelf + 3u) / 4u * 4u); // a multiple of 4 for block-compressed storage
    for (size_t k = 0; k < atlas.regions.size(); ++k) {
        LightmapRegion& r = atlas.regions[k];
        r.scaleOffset = glm::vec4(float(r.size) / float(atlas.width), float(r.size) / float(atlas.height),
                                  float(r.x) / float(atlas.width), float(r.y) / float(atlas.height));
        atlas.regionOfInstance[r.instance] = static_cast<int32_t>(k);
    }
    return atlas;
}

} // namespace vitrine::bake
