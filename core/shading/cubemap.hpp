#pragma once

#include <glm/glm.hpp>

#include <functional>

#include "core/shading/sh.hpp"

// Cube-map texel geometry, the CPU mirror of shaders/common/cubemap.glsl: Vulkan's layer order
// +X, -X, +Y, -Y, +Z, -Z and face orientation; texel (x, y) of a face of size N (y = row from
// the top) has face coordinates u = 2 (x + 0.5) / N - 1, v = 2 (y + 0.5) / N - 1.
namespace vitrine::shading {

// Unnormalised direction through face coordinates (u, v) in [-1, 1]^2.
glm::dvec3 cubeDirection(int face, double u, double v);
glm::dvec3 cubeTexelDirection(int face, int x, int y, int size); // normalised

struct CubeCoord {
    int face = 0;
    double u = 0.0, v = 0.0; // [-1, 1]
};
CubeCoord cubeCoord(glm::dvec3 dir);

// Exact solid angle of a texel (sr); all 6 N^2 texels sum to 4 pi.
double cubeTexelSolidAngle(int x, int y, int size);

// SH9 projection of a cube map given texel by texel (radiance of texel (x, y) of `face`),
// each texel weighted by its solid angle.
Sh9 projectCube(int size, const std::function<glm::dvec3(int face, int x, int y)>& radiance);

} // namespace vitrine::shading
