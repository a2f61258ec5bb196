// Included by both C++ (nodes/) and GLSL (shaders/) so a node's push constants are declared
// once. Use scalars, vec4/ivec4 and vec2 on 8-byte offsets only, so std430 (GLSL) and C++
// layouts agree; every C++ side static_asserts its size and the executor checks it against
// the reflected push-constant block.
#ifndef VITRINE_SHARED_H
#define VITRINE_SHARED_H

#ifdef __cplusplus
#include <glm/glm.hpp>
#include <cstdint>
#define VITRINE_PUSH_BEGIN(Name) struct Name {
#define VITRINE_PUSH_END(instance) };
namespace vitrine::gpu_types {
using vec2 = glm::vec2;
using vec4 = glm::vec4;
using mat4 = glm::mat4;
using uvec4 = glm::uvec4;
using ivec2 = glm::ivec2;
using ivec4 = glm::ivec4;
using uint = uint32_t;
} // namespace vitrine::gpu_types
#else
#define VITRINE_PUSH_BEGIN(Name) layout(push_constant) uniform Name {
#define VITRINE_PUSH_END(instance) } instance;
#endif

#endif
