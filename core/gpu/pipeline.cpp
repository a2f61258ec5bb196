#include "core/gpu/pipeline.hpp"

#include "core/gpu/pipeline_cache.hpp"
#include "core/gpu/vk_check.hpp"

namespace vitrine {

VkShaderModule createShaderModule(VkDevice device, const CompiledShader& shader) {
    VkShaderModuleCreateInfo mi{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
    mi.codeSize = shader.spirv.size() * 4;
    mi.pCode = shader.spirv.data();
    VkShaderModule module;
    VK_CHECK(vkCreateShaderModule(device, &mi, nullptr, &module));
    return module;
}

VkPipeline createComputePipeline(Context& ctx, const CompiledShader& shader, VkPipelineLayout layout) {
    VkDevice device = ctx.device();
    VkShaderModule module = createShaderModule(device, shader);
    VkPipelineCreationFeedback feedback;
    const VkPipelineCreationFeedbackCreateInfo feedbackInfo = PipelineCache::feedbackInfo(&feedback, nullptr);
    VkComputePipelineCreateInfo ci{VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO};
    ci.pNext = &feedbackInfo;
    ci.stage = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO, nullptr, 0, VK_SHADER_STAGE_COMPUTE_BIT, module, "main", nullptr};
    ci.layout = layout;
    VkPipeline pipeline = VK_NULL_HANDLE;
    VkResult result = vkCreateComputePipelines(device, ctx.pipelineCache().handle(), 1, &ci, nullptr, &pipeline);
    vkDestroyShaderModule(device, module, nullptr);
    VK_CHECK(result);
    ctx.pipelineCache().created(feedback);
    return pipeline;
}

} // namespace vitrine
