#pragma once
// Shader modules and compute pipelines from compiled SPIR-V (raster pipelines: raster.hpp).

#include "core/gpu/context.hpp"
#include "core/shader/compiler.hpp"

#include <vulkan/vulkan.h>

namespace vitrine {

// The caller destroys the module (once the pipelines using it are created).
VkShaderModule createShaderModule(VkDevice device, const CompiledShader& shader);

// A compute pipeline with entry point "main", through the context's pipeline cache (pipeline_cache.hpp); the shader
// module is created and destroyed inside.
VkPipeline createComputePipeline(Context& ctx, const CompiledShader& shader, VkPipelineLayout layout);

} // namespace vitrine
