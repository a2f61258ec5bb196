#include "core/gpu/raster.hpp"

#include "core/gpu/context.hpp"
#include "core/gpu/pipeline.hpp"
#include "core/gpu/pipeline_cache.hpp"
#include "core/gpu/vk_check.hpp"

#include <utility>

namespace vitrine {

RasterPipeline::RasterPipeline(Context& ctx, const RasterPipelineDesc& desc) : mCtx(&ctx) {
    VkDevice device = ctx.device();
    VkPushConstantRange range{VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT, 0, desc.pushConstantSize};
    VkPipelineLayoutCreateInfo pl{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
    pl.setLayoutCount = static_cast<uint32_t>(desc.setLayouts.size());
    pl.pSetLayouts = desc.setLayouts.data();
    pl.pushConstantRangeCount = desc.pushConstantSize ? 1 : 0;
    pl.pPushConstantRanges = &range;
    VK_CHECK(vkCreatePipelineLayout(device, &pl, nullptr, &mLayout));

    std::vector<VkPipelineShaderStageCreateInfo> stages;
    std::vector<VkShaderModule> modules;
    modules.push_back(createShaderModule(device, desc.vertex));
    stages.push_back({VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO, nullptr, 0, VK_SHADER_STAGE_VERTEX_BIT,
                      modules.back(), "main", nullptr});
    if (desc.fragment) {
        modules.push_back(createShaderModule(device, *desc.fragment));
        stages.push_back({VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO, nullptr, 0, VK_SHADER_STAGE_FRAGMENT_BIT,
                          modules.back(), "main", nullptr});
    }

    VkPipelineVertexInputStateCreateInfo vi{VK_STRUCTURE_TYPE_PIPELINE_VERTEX_INPUT_STATE_CREATE_INFO};
    vi.vertexBindingDescriptionCount = static_cast<uint32_t>(desc.vertexBindings.size());
    vi.pVertexBindingDescriptions = desc.vertexBindings.data();
    vi.vertexAttributeDescriptionCount = static_cast<uint32_t>(desc.vertexAttributes.size());
    vi.pVertexAttributeDescriptions = desc.vertexAttributes.data();
    VkPipelineInputAssemblyStateCreateInfo ia{VK_STRUCTURE_TYPE_PIPELINE_INPUT_ASSEMBLY_STATE_CREATE_INFO};
    ia.topology = VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST;
    VkPipelineViewportStateCreateInfo vp{VK_STRUCTURE_TYPE_PIPELINE_VIEWPORT_STATE_CREATE_INFO};
    vp.viewportCount = 1;
    vp.scissorCount = 1;
    VkPipelineRasterizationStateCreateInfo rs{VK_STRUCTURE_TYPE_PIPELINE_RASTERIZATION_STATE_CREATE_INFO};
    rs.polygonMode = VK_POLYGON_MODE_FILL;
    rs.cullMode = desc.cullMode;
    rs.frontFace = desc.frontFace;
    rs.depthBiasEnable = desc.depthBias;
    rs.depthClampEnable = desc.depthClamp;
    rs.lineWidth = 1.0f;
    VkPipelineMultisampleStateCreateInfo ms{VK_STRUCTURE_TYPE_PIPELINE_MULTISAMPLE_STATE_CREATE_INFO};
    ms.rasterizationSamples = VK_SAMPLE_COUNT_1_BIT;
    VkPipelineDepthStencilStateCreateInfo ds{VK_STRUCTURE_TYPE_PIPELINE_DEPTH_STENCIL_STATE_CREATE_INFO};
    ds.depthTestEnable = desc.depthTest;
    ds.depthWriteEnable = desc.depthWrite;
    ds.depthCompareOp = desc.depthCompare;
    std::vector<VkPipelineColorBlendAttachmentState> blends(desc.colorFormats.size());
    for (auto& b : blends) {
        if (desc.blend) b = *desc.blend;
        b.colorWriteMask = 0xf;
    }
    VkPipelineColorBlendStateCreateInfo cb{VK_STRUCTURE_TYPE_PIPELINE_COLOR_BLEND_STATE_CREATE_INFO};
    cb.attachmentCount = static_cast<uint32_t>(blends.size());
    cb.pAttachments = blends.data();
    std::vector<VkDynamicState> dynamic = {VK_DYNAMIC_STATE_VIEWPORT, VK_DYNAMIC_STATE_SCISSOR};
    if (desc.depthBias) dynamic.push_back(VK_DYNAMIC_STATE_DEPTH_BIAS);
    VkPipelineDynamicStateCreateInfo dy{VK_STRUCTURE_TYPE_PIPELINE_DYNAMIC_STATE_CREATE_INFO};
    dy.dynamicStateCount = static_cast<uint32_t>(dynamic.size());
    dy.pDynamicStates = dynamic.data();
    VkPipelineRenderingCreateInfo rendering{VK_STRUCTURE_TYPE_PIPELINE_RENDERING_CREATE_INFO};
    rendering.colorAttachmentCount = static_cast<uint32_t>(desc.colorFormats.size());
    rendering.pColorAttachmentFormats = desc.colorFormats.data();
    rendering.depthAttachmentFormat = desc.depthFormat;

    VkPipelineCreationFeedback feedback;
    const VkPipelineCreationFeedbackCreateInfo feedbackInfo = PipelineCache::feedbackInfo(&feedback, &rendering);
    VkGraphicsPipelineCreateInfo ci{VK_STRUCTURE_TYPE_GRAPHICS_PIPELINE_CREATE_INFO};
    ci.pNext = &feedbackInfo;
    ci.stageCount = static_cast<uint32_t>(stages.size());
    ci.pStages = stages.data();
    ci.pVertexInputState = &vi;
    ci.pInputAssemblyState = &ia;
    ci.pViewportState = &vp;
    ci.pRasterizationState = &rs;
    ci.pMultisampleState = &ms;
    ci.pDepthStencilState = &ds;
    ci.pColorBlendState = &cb;
    ci.pDynamicState = &dy;
    ci.layout = mLayout;
    VkResult result = vkCreateGraphicsPipelines(device, ctx.pipelineCache().handle(), 1, &ci, nullptr, &mPipeline);
    for (VkShaderModule m : modules) vkDestroyShaderModule(device, m, nullptr);
    if (result != VK_SUCCESS) release();
    VK_CHECK(result);
    ctx.pipelineCache().created(feedback);
    ctx.setName(reinterpret_cast<uint64_t>(mPipeline), VK_OBJECT_TYPE_PIPELINE, desc.name);
}

RasterPipeline::~RasterPipeline() { release(); }

RasterPipeline::RasterPipeline(RasterPipeline&& other) noexcept
    : mCtx(std::exchange(other.mCtx, nullptr)), mPipeline(std::exchange(other.mPipeline, VK_NULL_HANDLE)),
      mLayout(std::exchange(other.mLayout, VK_NULL_HANDLE)) {}

RasterPipeline& RasterPipeline::operator=(RasterPipeline&& other) noexcept {
    if (this != &other) {
        release();
        mCtx = std::exchange(other.mCtx, nullptr);
        mPipeline = std::exchange(other.mPipeline, VK_NULL_HANDLE);
        mLayout = std::exchange(other.mLayout, VK_NULL_HANDLE);
    }
    return *this;
}

void RasterPipeline::release() {
    if (!mCtx) return;
    VkDevice device = mCtx->device();
    VkPipeline pipeline = std::exchange(mPipeline, VK_NULL_HANDLE);
    VkPipelineLayout layout = std::exchange(mLayout, VK_NULL_HANDLE);
    if (pipeline || layout)
        mCtx->destroyLater([device, pipeline, layout] {
            if (pipeline) vkDestroyPipeline(device, pipeline, nullptr);
            if (layout) vkDestroyPipelineLayout(device, layout, nullptr);
        });
    mCtx = nullptr;
}

void beginRendering(VkCommandBuffer cmd, VkExtent2D extent, const std::vector<Attachment>& colors,
                    const std::optional<Attachment>& depth) {
    std::vector<VkRenderingAttachmentInfo> color(colors.size());
    for (size_t i = 0; i < colors.size(); ++i) {
        color[i] = {VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO};
        color[i].imageView = colors[i].view;
        color[i].imageLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
        color[i].loadOp = colors[i].clear ? VK_ATTACHMENT_LOAD_OP_CLEAR : VK_ATTACHMENT_LOAD_OP_LOAD;
        color[i].storeOp = VK_ATTACHMENT_STORE_OP_STORE;
        color[i].clearValue = colors[i].clearValue;
    }
    VkRenderingAttachmentInfo depthInfo{VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO};
    if (depth) {
        depthInfo.imageView = depth->view;
        depthInfo.imageLayout =
            depth->readOnly ? VK_IMAGE_LAYOUT_DEPTH_STENCIL_READ_ONLY_OPTIMAL : VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL;
        depthInfo.loadOp = depth->clear ? VK_ATTACHMENT_LOAD_OP_CLEAR : VK_ATTACHMENT_LOAD_OP_LOAD;
        depthInfo.storeOp = depth->readOnly ? VK_ATTACHMENT_STORE_OP_NONE : VK_ATTACHMENT_STORE_OP_STORE;
        depthInfo.clearValue = depth->clearValue;
    }
    VkRenderingInfo info{VK_STRUCTURE_TYPE_RENDERING_INFO};
    info.renderArea = {{0, 0}, extent};
    info.layerCount = 1;
    info.colorAttachmentCount = static_cast<uint32_t>(color.size());
    info.pColorAttachments = color.data();
    info.pDepthAttachment = depth ? &depthInfo : nullptr;
    vkCmdBeginRendering(cmd, &info);
    VkViewport viewport{0.0f, 0.0f, static_cast<float>(extent.width), static_cast<float>(extent.height), 0.0f, 1.0f};
    VkRect2D scissor{{0, 0}, extent};
    vkCmdSetViewport(cmd, 0, 1, &viewport);
    vkCmdSetScissor(cmd, 0, 1, &scissor);
}

void endRendering(VkCommandBuffer cmd) { vkCmdEndRendering(cmd); }

} // namespace vitrine
