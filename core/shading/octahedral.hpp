#pragma once

#include <glm/glm.hpp>

// Octahedral unit-vector encoding [Meyer10], the CPU mirror of shaders/common/octahedral.glsl.
// The G-buffer stores octEncode(n) as-is in two RGBA16F channels.
//
// Error bound (measured by tests/unit/shading/octahedral_test.cpp over 1e6 directions):
// in fp32 the round trip is within 1e-6 rad (measured 2.9e-7); quantised to IEEE half (as
// stored in RGBA16F) it is within 1.1e-3 rad (0.063 deg; measured 1.03e-3): half has 11
// significant bits, so each |e| in [0.5, 1] is rounded by at most 2^-12, and the map stretches
// a step in e by up to ~3 rad per unit next to the folded corners (the -z pole).
namespace vitrine::shading {

// n need not be normalised (it must not be zero). Result in [-1, 1]^2.
glm::vec2 octEncode(glm::vec3 n);
// Inverse of octEncode; the result is normalised.
glm::vec3 octDecode(glm::vec2 e);

} // namespace vitrine::shading
