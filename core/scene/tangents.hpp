#pragma once

// Normal and tangent generation for triangle lists, used by the glTF loader when a file lacks them and
// by the procedural museum for all of its geometry.

#include "core/scene/scene.hpp"

#include <cstdint>
#include <span>

namespace vitrine::scene {

// Sets Vertex::tangent from positions, normals and uv0 (MikkTSpace-like, not bit-exact): per triangle
// the tangent dP/du and bitangent dP/dv from the UV gradient, normalised and accumulated at each corner
// weighted by the corner angle, then Gram-Schmidt-orthogonalised against the vertex normal. w = +1 when
// cross(normal, tangent) points towards -v, i.e. "up" in the image (glTF's normal-map convention, and
// what MikkTSpace gives on Blender's flipped v), else -1. Vertices whose triangles have no usable UV
// gradient get an arbitrary tangent perpendicular to the normal. indices are relative to vertices.
void generateTangents(std::span<Vertex> vertices, std::span<const uint32_t> indices);

// Area-weighted smooth normals (the museum's curved shapes). The glTF loader does not use this: glTF
// asks for flat normals when a primitive has none, and it unwelds the triangles instead.
void generateSmoothNormals(std::span<Vertex> vertices, std::span<const uint32_t> indices);

} // namespace vitrine::scene
