#pragma once

#include <glm/glm.hpp>

#include <array>

// Real SH9, the CPU mirror of shaders/common/sh.glsl (same order and conventions): radiance
// coefficients; irradiance applies A_0 = pi, A_1 = 2 pi / 3, A_2 = pi / 4 [Ramamoorthi01].
namespace vitrine::shading {

struct Sh9 {
    std::array<glm::dvec3, 9> c{};
};

std::array<double, 9> shBasis9(glm::dvec3 unitDir);

// Adds radiance * Y_lm(dir) * weight; weight is the solid angle the sample stands for.
void shAccumulate(Sh9& sh, glm::dvec3 unitDir, glm::dvec3 radiance, double weight);

glm::dvec3 shRadiance(const Sh9& sh, glm::dvec3 unitDir);
glm::dvec3 shIrradiance(const Sh9& sh, glm::dvec3 unitNormal);

} // namespace vitrine::shading
