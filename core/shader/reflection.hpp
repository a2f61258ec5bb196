#pragma once

#include "core/shader/compiler.hpp"

#include <string>

namespace glslang {
class TProgram;
}

namespace vitrine {

// Descriptor bindings, push-constant size and workgroup size from glslang's reflection.
ShaderReflection reflect(const glslang::TProgram& program, VkShaderStageFlagBits stage);

std::string reflectionToJson(const ShaderReflection& reflection);
bool reflectionFromJson(const std::string& text, ShaderReflection& out);

const ShaderBinding* findBinding(const ShaderReflection& reflection, const std::string& name);

} // namespace vitrine
