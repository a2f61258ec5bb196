#include "core/scene/closed_mesh.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <unordered_map>

namespace vitrine::scene {

bool boundsVolume(const Material& m) {
    return m.transmission > 0.0f && m.thickness > 0.0f;
}

namespace {

// Gives the corners of a set of triangles ids, one per position: corners closer than `tolerance` on every axis share
// one. Exporters split a mesh's vertices at UV seams and hard edges into copies at the same place, and generated
// meshes close their seams up to rounding (the sine of 2 pi is not 0). Cells are counted from `origin`, the corners'
// lowest point, so their indices stay within the extent over the tolerance however far the mesh is from 0.
class Welder {
public:
    Welder(glm::vec3 origin, float tolerance) : mOrigin(origin), mTolerance(tolerance) {}

    uint32_t id(glm::vec3 p) {
        const glm::ivec3 cell = cellOf(p);
        // A corner within the tolerance lies in this cell or one of its neighbours (cells are as wide as it).
        for (int dz = -1; dz <= 1; ++dz)
            for (int dy = -1; dy <= 1; ++dy)
                for (int dx = -1; dx <= 1; ++dx) {
                    auto it = mCells.find(key(cell + glm::ivec3(dx, dy, dz)));
                    if (it == mCells.end()) continue;
                    for (uint32_t i : it->second) {
                        const glm::vec3 d = glm::abs(mPositions[i] - p);
                        if (std::max({d.x, d.y, d.z}) <= mTolerance) return i;
                    }
                }
        const uint32_t i = static_cast<uint32_t>(mPositions.size());
        mPositions.push_back(p);
        mCells[key(cell)].push_back(i);
        return i;
    }

private:
    glm::ivec3 cellOf(glm::vec3 p) const { return glm::ivec3(glm::floor((p - mOrigin) / mTolerance)); }
    static uint64_t key(glm::ivec3 c) {
        auto u = [](int v) { return static_cast<uint64_t>(static_cast<uint32_t>(v) & 0x1fffffu); };
        return u(c.x) | u(c.y) << 21 | u(c.z) << 42;
    }

    glm::vec3 mOrigin;
    float mTolerance;
    std::vector<glm::vec3> mPositions;
    std::unordered_map<uint64_t, std::vector<uint32_t>> mCells;
};

} // namespace

bool trianglesClosed(const Scene& scene, const std::vector<uint32_t>& primitives) {
    auto position = [&](const Primitive& prim, uint32_t i) {
        return scene.vertices[prim.vertexOffset + scene.indices[prim.firstIndex + i]].position;
    };
    // The tolerance: a millionth of the triangles' extent, far below any edge an asset means, far above rounding.
    glm::vec3 lo(INFINITY), hi(-INFINITY);
    for (uint32_t p : primitives)
        for (uint32_t i = 0; i < scene.primitives[p].indexCount; ++i) {
            lo = glm::min(lo, position(scene.primitives[p], i));
            hi = glm::max(hi, position(scene.primitives[p], i));
        }
    const glm::vec3 extent = hi - lo;
    Welder welder(lo, std::max(1e-6f * std::max({extent.x, extent.y, extent.z}), 1e-30f));
    // +1 for each crossing from the lower id to the higher, -1 for each the other way; closed when all sum to 0.
    std::unordered_map<uint64_t, int32_t> balance;
    for (uint32_t p : primitives) {
        const Primitive& prim = scene.primitives[p];
        for (uint32_t t = 0; t + 3 <= prim.indexCount; t += 3) {
            const uint32_t c[3] = {welder.id(position(prim, t)), welder.id(position(prim, t + 1)),
                                   welder.id(position(prim, t + 2))};
            if (c[0] == c[1] || c[1] == c[2] || c[2] == c[0]) continue;
            for (uint32_t k = 0; k < 3; ++k) {
                const uint32_t a = c[k], b = c[(k + 1) % 3];
                const uint64_t edge = (static_cast<uint64_t>(std::min(a, b)) << 32) | std::max(a, b);
                balance[edge] += a < b ? 1 : -1;
            }
        }
    }
    for (const auto& [edge, sum] : balance)
        if (sum != 0) return false;
    return true;
}

std::vector<uint8_t> openVolumePrimitives(const Scene& scene, const Mesh& mesh) {
    std::vector<uint8_t> open(mesh.primitiveCount, 0);
    std::map<uint32_t, std::vector<uint32_t>> byMaterial;
    for (uint32_t p = mesh.firstPrimitive; p < mesh.firstPrimitive + mesh.primitiveCount; ++p) {
        const uint32_t material = scene.primitives[p].material;
        if (material < scene.materials.size() && boundsVolume(scene.materials[material]))
            byMaterial[material].push_back(p);
    }
    for (const auto& [material, primitives] : byMaterial) {
        if (trianglesClosed(scene, primitives)) continue;
        for (uint32_t p : primitives)
            open[p - mesh.firstPrimitive] = 1;
    }
    return open;
}

std::vector<uint8_t> openVolumePrimitives(const Scene& scene) {
    std::vector<uint8_t> open(scene.primitives.size(), 0);
    for (const Mesh& mesh : scene.meshes) {
        const std::vector<uint8_t> flags = openVolumePrimitives(scene, mesh);
        std::copy(flags.begin(), flags.end(), open.begin() + mesh.firstPrimitive);
    }
    return open;
}

} // namespace vitrine::scene
