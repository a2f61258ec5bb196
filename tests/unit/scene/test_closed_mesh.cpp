// core/scene/closed_mesh.hpp: which faces bound a volume (KHR_materials_volume needs a closed mesh), checked on boxes
// built here face by face, each face with its own four corners as exporters split them at hard edges.

#include "core/scene/closed_mesh.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>

namespace vitrine::scene {
namespace {

// A face: four corners counter-clockwise seen from outside.
using Face = std::array<glm::vec3, 4>;

// The six faces of the box [-1, 1]^3, wound counter-clockwise seen from outside (normals outward).
std::vector<Face> boxFaces() {
    std::vector<Face> faces;
    for (int axis = 0; axis < 3; ++axis)
        for (float side : {-1.0f, 1.0f}) {
            glm::vec3 n(0.0f), u(0.0f), v(0.0f);
            n[axis] = side;
            u[(axis + 1) % 3] = 1.0f;
            v[(axis + 2) % 3] = 1.0f;
            if (side < 0.0f) std::swap(u, v); // u x v along n
            faces.push_back({n - u - v, n + u - v, n + u + v, n - u + v});
        }
    return faces;
}

// Appends a primitive of the faces (two triangles each, every face its own vertices) of `material` to the scene's
// last mesh, adding a mesh first when `newMesh`.
void addPrimitive(Scene& s, const std::vector<Face>& faces, uint32_t material, bool newMesh) {
    if (newMesh) s.meshes.push_back({"m", static_cast<uint32_t>(s.primitives.size()), 0});
    Primitive p;
    p.firstIndex = static_cast<uint32_t>(s.indices.size());
    p.vertexOffset = static_cast<uint32_t>(s.vertices.size());
    p.material = material;
    for (const Face& f : faces) {
        const uint32_t base = static_cast<uint32_t>(s.vertices.size()) - p.vertexOffset;
        for (const glm::vec3& c : f) {
            Vertex v;
            v.position = c;
            s.vertices.push_back(v);
        }
        for (uint32_t k : {0u, 1u, 2u, 0u, 2u, 3u})
            s.indices.push_back(base + k);
    }
    p.indexCount = static_cast<uint32_t>(s.indices.size()) - p.firstIndex;
    p.vertexCount = static_cast<uint32_t>(s.vertices.size()) - p.vertexOffset;
    s.primitives.push_back(p);
    ++s.meshes.back().primitiveCount;
}

// Materials: 0 glass bounding a volume, 1 thin-walled glass (no thickness), 2 opaque with a thickness.
Scene withMaterials() {
    Scene s;
    Material glass;
    glass.transmission = 1.0f;
    glass.thickness = 0.5f;
    Material thin = glass;
    thin.thickness = 0.0f;
    Material opaque;
    opaque.thickness = 0.5f;
    s.materials = {glass, thin, opaque};
    return s;
}

bool closed(const std::vector<Face>& faces) {
    Scene s = withMaterials();
    addPrimitive(s, faces, 0, true);
    return trianglesClosed(s, {0});
}

TEST(ClosedMesh, ABoxIsClosedAndLosesItWithAFaceMissingOrTurned) {
    const std::vector<Face> box = boxFaces();
    EXPECT_TRUE(closed(box));
    for (size_t f = 0; f < box.size(); ++f) {
        SCOPED_TRACE(f);
        std::vector<Face> missing = box;
        missing.erase(missing.begin() + static_cast<ptrdiff_t>(f));
        EXPECT_FALSE(closed(missing));
        std::vector<Face> turned = box;
        std::reverse(turned[f].begin(), turned[f].end());
        EXPECT_FALSE(closed(turned)) << "a face wound against the others leaves its edges crossed one way twice";
    }
    EXPECT_FALSE(closed({box[0]})) << "a single quad bounds nothing";
    // Two boxes in one primitive are closed.
    std::vector<Face> two = box;
    for (Face f : box) {
        for (glm::vec3& c : f)
            c += glm::vec3(5.0f, 0.0f, 0.0f);
        two.push_back(f);
    }
    EXPECT_TRUE(closed(two));
    // A degenerate triangle (a sliver with two corners at one position) changes nothing.
    Scene s = withMaterials();
    addPrimitive(s, box, 0, true);
    const uint32_t v = static_cast<uint32_t>(s.vertices.size()) - s.primitives[0].vertexOffset;
    s.vertices.push_back(s.vertices[0]);
    s.indices.insert(s.indices.end(), {0u, 1u, v});
    s.primitives[0].indexCount += 3;
    EXPECT_TRUE(trianglesClosed(s, {0}));
}

// Corners are welded within a millionth of the mesh's extent: a UV sphere whose seam column is computed at 2 pi (its
// sine about -2e-7, not 0) and whose poles repeat one point per column is closed; a box with one face's corner moved
// by a thousandth of its size is not.
TEST(ClosedMesh, CornersWeldWithinRoundingNotAcrossARealGap) {
    const int rings = 8, segments = 12;
    const float radius = 2.0f, pi = 3.14159265358979f;
    Scene s = withMaterials();
    s.meshes.push_back({"sphere", 0, 1});
    Primitive p;
    for (int i = 0; i <= rings; ++i)
        for (int j = 0; j <= segments; ++j) {
            const float theta = pi * static_cast<float>(i) / rings, phi = 2.0f * pi * static_cast<float>(j) / segments;
            Vertex v;
            v.position =
                radius * glm::vec3(std::sin(theta) * std::cos(phi), std::cos(theta), std::sin(theta) * std::sin(phi));
            s.vertices.push_back(v);
        }
    auto at = [&](int i, int j) { return static_cast<uint32_t>(i * (segments + 1) + j); };
    for (int i = 0; i < rings; ++i)
        for (int j = 0; j < segments; ++j) // outward: along phi, then down in theta
            s.indices.insert(s.indices.end(),
                             {at(i, j), at(i, j + 1), at(i + 1, j + 1), at(i, j), at(i + 1, j + 1), at(i + 1, j)});
    p.indexCount = static_cast<uint32_t>(s.indices.size());
    p.vertexCount = static_cast<uint32_t>(s.vertices.size());
    s.primitives.push_back(p);
    ASSERT_NE(s.vertices[at(4, 0)].position, s.vertices[at(4, segments)].position) << "the seam must not be exact";
    EXPECT_TRUE(trianglesClosed(s, {0}));

    std::vector<Face> box = boxFaces();
    box[0][2] += glm::vec3(0.0f, 2e-3f, 0.0f);
    EXPECT_FALSE(closed(box));
}

TEST(ClosedMesh, OpenVolumePrimitivesAreTheOpenFacesOfAVolumeMaterialPerMesh) {
    const std::vector<Face> box = boxFaces();
    Scene s = withMaterials();
    // Mesh 0: a box split over two primitives of the glass: closed together.
    addPrimitive(s, {box.begin(), box.begin() + 3}, 0, true);
    addPrimitive(s, {box.begin() + 3, box.end()}, 0, false);
    // Mesh 1: the same split, the second half in the thin glass: the glass's half is open, the thin glass is not a
    // volume.
    addPrimitive(s, {box.begin(), box.begin() + 3}, 0, true);
    addPrimitive(s, {box.begin() + 3, box.end()}, 1, false);
    // Mesh 2: a quad of glass (open) and one of the opaque material with a thickness (not a volume).
    addPrimitive(s, {box[0]}, 0, true);
    addPrimitive(s, {box[1]}, 2, false);
    // Mesh 3: a whole box of glass: closed, even though mesh 1 has half of one of the same material.
    addPrimitive(s, box, 0, true);
    EXPECT_EQ(openVolumePrimitives(s), (std::vector<uint8_t>{0, 0, 1, 0, 1, 0, 0}));
    EXPECT_TRUE(boundsVolume(s.materials[0]));
    EXPECT_FALSE(boundsVolume(s.materials[1]));
    EXPECT_FALSE(boundsVolume(s.materials[2]));
}

} // namespace
} // namespace vitrine::scene
