#pragma once
// Raster passes: a graphics pipeline for dynamic rendering and the begin/end of a rendering scope.
// Raster nodes own their pipelines (they depend on the scene's descriptor layout and vertex format,
// which only the node knows); the render graph still owns the attachments, their layouts and barriers.

#include "core/shader/compiler.hpp"

#include <vulkan/vulkan.h>

#include <optional>
#include <string>
#include <vector>

namespace vitrine {

class Context;

struct RasterPipelineDesc {
    std::string name; // for errors and debug names
    CompiledShader vertex;
    std::optional<CompiledShader> fragment; // none: depth only
    std::vector<VkDescriptorSetLayout> setLayouts;
    uint32_t pushConstantSize = 0; // visible to vertex and fragment stages
    std::vector<VkVertexInputBindingDescription> vertexBindings;
    std::vector<VkVertexInputAttributeDescription> vertexAttributes;
    std::vector<VkFormat> colorFormats;
    VkFormat depthFormat = VK_FORMAT_UNDEFINED;
    VkCullModeFlags cullMode = VK_CULL_MODE_BACK_BIT;
    VkFrontFace frontFace = VK_FRONT_FACE_COUNTER_CLOCKWISE;
    bool depthTest = true;
    bool depthWrite = true;
    VkCompareOp depthCompare = VK_COMPARE_OP_GREATER_OR_EQUAL; // reverse Z
    bool depthBias = false;  // dynamic state: set with vkCmdSetDepthBias
    bool depthClamp = false; // needs the depthClamp feature (shadow pancaking)
    // Blending of every colour attachment (none: written as is). Dual-source factors need the dualSrcBlend
    // feature (Context::dualSourceBlend()).
    std::optional<VkPipelineColorBlendAttachmentState> blend;
};

// A graphics pipeline and its layout. Viewport and scissor are dynamic. Move-only; destruction is
// deferred until the GPU is done with it.
class RasterPipeline {
public:
    RasterPipeline() = default;
    RasterPipeline(Context& ctx, const RasterPipelineDesc& desc);
    ~RasterPipeline();
    RasterPipeline(RasterPipeline&& other) noexcept;
    RasterPipeline& operator=(RasterPipeline&& other) noexcept;
    RasterPipeline(const RasterPipeline&) = delete;
    RasterPipeline& operator=(const RasterPipeline&) = delete;

    VkPipeline pipeline() const { return mPipeline; }
    VkPipelineLayout layout() const { return mLayout; }
    explicit operator bool() const { return mPipeline != VK_NULL_HANDLE; }

private:
    void release();
    Context* mCtx = nullptr;
    VkPipeline mPipeline = VK_NULL_HANDLE;
    VkPipelineLayout mLayout = VK_NULL_HANDLE;
};

struct Attachment {
    VkImageView view = VK_NULL_HANDLE;
    bool clear = true; // else load
    VkClearValue clearValue{};
    bool readOnly = false; // depth: a Usage::DepthRead port (DEPTH_STENCIL_READ_ONLY_OPTIMAL, sampled by the pass)
};

// vkCmdBeginRendering over `extent` with the attachments in the layouts the render graph put them in
// (COLOR_ATTACHMENT_OPTIMAL / DEPTH_ATTACHMENT_OPTIMAL), plus a full viewport and scissor. Layered
// rendering is not used: a cascade or cube face is one scope over one layer's view.
void beginRendering(VkCommandBuffer cmd, VkExtent2D extent, const std::vector<Attachment>& colors,
                    const std::optional<Attachment>& depth);
void endRendering(VkCommandBuffer cmd);

} // namespace vitrine
