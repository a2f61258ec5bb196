#pragma once
// The lens aperture's shape for depth of field (MUSEUM_SPEC §7): a regular polygon of `blades` straight blades
// whose corners lie on the unit circle, rounded toward that circle by `roundness`, and a circle when the lens is
// wide open. The scene nodes' thin-lens mode samples it (the accumulated DOF reference) and post.dof draws its
// bokeh with the same boundary (shaders/post/aperture.glsl is the GLSL twin; the DOF tests compare the two).

#include <glm/glm.hpp>

#include <cstdint>

namespace vitrine::scene {

struct ApertureShape {
    uint32_t blades = 0;    // 0 (or < 3): a circle
    float roundness = 0.0f; // 0: straight blades, 1: a circle
    float rotation = 0.0f;  // radians: the angle of the first corner, counter-clockwise from +x
};

// The shape at f-number `fNumber` of a lens that opens to `wideOpenFNumber`: round wide open, the blades' own
// roundness once stopped down by a stop or more, blended linearly in stops in between (the blades swing in).
ApertureShape apertureAt(uint32_t blades, float bladeRoundness, float rotation, float fNumber, float wideOpenFNumber);

// Distance from the centre to the boundary along direction angle `theta`, relative to the circumradius (1 at the
// corners, cos(pi / blades) at the middle of a straight blade).
float apertureBoundary(const ApertureShape& shape, float theta);

// Whether p (relative to the circumradius) lies inside the aperture.
bool insideAperture(const ApertureShape& shape, glm::vec2 p);

// Area of the aperture relative to the unit circumradius (pi for a circle).
float apertureArea(const ApertureShape& shape);

// Sample `index` of a low-discrepancy sequence uniform over the aperture (relative to the circumradius): the
// accepted points of the R2 sequence on [-1, 1]^2 that fall inside, so any first N are well spread over the shape.
glm::vec2 apertureSample(const ApertureShape& shape, uint32_t index);

} // namespace vitrine::scene
