#pragma once
// E5B9G9R9 (VK_FORMAT_E5B9G9R9_UFLOAT_PACK32) as the Vulkan specification defines it: three 9-bit mantissas
// sharing a 5-bit exponent (bias 15), no sign. 4 bytes a texel for HDR data that needs no alpha: baked
// lightmaps (core/bake) and uploads of that format (core/gpu/transfer).

#include <glm/glm.hpp>

#include <cstdint>

namespace vitrine {

// Negative and NaN inputs become 0, values above the maximum (65408) clamp.
uint32_t packRgb9e5(glm::vec3 rgb);
glm::vec3 unpackRgb9e5(uint32_t packed);

} // namespace vitrine
