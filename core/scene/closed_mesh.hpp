// KHR_materials_volume asks for a closed mesh: its thickness is the depth of a volume that the mesh's faces bound, and
// a path tracer refracts into that volume at one face and out of it at another (shaders/pathtrace/volume.glsl). Assets
// do not always honour it: a window pane modelled as one quad, with a thicknessFactor for the rasteriser's estimate,
// bounds nothing, and a path refracted into it would never find the way out. This finds such primitives, so the
// tracers can treat them as the rasteriser does, thin-walled glass tinted over its thickness, and the loader can say
// so.
#pragma once

#include "core/scene/scene.hpp"

#include <cstdint>
#include <vector>

namespace vitrine::scene {

// Whether m bounds a volume: transmission and a thicknessFactor > 0 (shaders/pathtrace/surface.glsl
// materialBoundsVolume; a factor of 0 is thin-walled whatever the thickness texture says).
bool boundsVolume(const Material& m);

// Whether the triangles are closed: with corners welded by position (within a millionth of the triangles' extent),
// every edge is crossed as often in one direction as in the other, as the faces of a consistently wound closed surface
// cross each edge once each way. Degenerate triangles (two corners welded into one) are ignored.
bool trianglesClosed(const Scene& scene, const std::vector<uint32_t>& primitives);

// One entry per primitive of the mesh: 1 where the primitive's material bounds a volume but the faces of that material
// in the mesh (its primitives sharing the material, taken together) are not closed; 0 elsewhere.
std::vector<uint8_t> openVolumePrimitives(const Scene& scene, const Mesh& mesh);
// The same for every mesh, one entry per Scene::primitives.
std::vector<uint8_t> openVolumePrimitives(const Scene& scene);

} // namespace vitrine::scene
