#include "core/graph/barriers.hpp"

namespace vitrine {

AccessInfo accessOf(Usage usage, PassKind pass) {
    const VkPipelineStageFlags2 shaderStage = pass == PassKind::Raster
                                                  ? VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT
                                                  : VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT;
    switch (usage) {
    case Usage::Sampled:
        return {VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, shaderStage, VK_ACCESS_2_SHADER_SAMPLED_READ_BIT, false};
    case Usage::StorageRead:
        return {VK_IMAGE_LAYOUT_GENERAL, shaderStage, VK_ACCESS_2_SHADER_STORAGE_READ_BIT, false};
    case Usage::StorageWrite:
        return {VK_IMAGE_LAYOUT_GENERAL, shaderStage, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT, true};
    case Usage::StorageReadWrite:
        return {VK_IMAGE_LAYOUT_GENERAL, shaderStage,
                VK_ACCESS_2_SHADER_STORAGE_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT, true};
    case Usage::ColorAttachment:
        return {VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT,
                VK_ACCESS_2_COLOR_ATTACHMENT_READ_BIT | VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT, true};
    case Usage::DepthAttachment:
        return {VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL,
                VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT,
                VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_READ_BIT | VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT, true};
    case Usage::DepthRead:
        return {VK_IMAGE_LAYOUT_DEPTH_STENCIL_READ_ONLY_OPTIMAL,
                VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT | shaderStage,
                VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_READ_BIT | VK_ACCESS_2_SHADER_SAMPLED_READ_BIT, false};
    case Usage::TransferSrc:
        return {VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_READ_BIT,
                false};
    case Usage::TransferDst:
        return {VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT,
                VK_ACCESS_2_TRANSFER_WRITE_BIT, true};
    }
    return {};
}

ImageSyncState ImageSyncState::discarded() {
    ImageSyncState s;
    s.writeStage = VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT;
    s.writeAccess = VK_ACCESS_2_MEMORY_WRITE_BIT;
    return s;
}

std::optional<ImageBarrier> requireAccess(ImageSyncState& s, uint32_t image, const AccessInfo& use) {
    const bool layoutChange = s.layout != use.layout;
    if (!layoutChange && !use.write) {
        // Read after read, or after a write already visible to this stage: nothing to wait for.
        if (s.writeStage == VK_PIPELINE_STAGE_2_NONE || (use.stage & ~s.visibleStages) == 0) {
            s.readStages |= use.stage;
            return std::nullopt;
        }
        ImageBarrier b{image, s.layout, use.layout, s.writeStage, s.writeAccess, use.stage, use.access};
        s.visibleStages |= use.stage;
        s.readStages |= use.stage;
        return b;
    }
    ImageBarrier b;
    b.image = image;
    b.oldLayout = s.layout;
    b.newLayout = use.layout;
    b.srcStage = s.writeStage | s.readStages;
    b.srcAccess = s.writeAccess;
    b.dstStage = use.stage;
    b.dstAccess = use.access;
    s.layout = use.layout;
    if (use.write) {
        s.writeStage = use.stage;
        s.writeAccess = use.access & (VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT | VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT |
                                      VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT | VK_ACCESS_2_TRANSFER_WRITE_BIT);
        s.readStages = VK_PIPELINE_STAGE_2_NONE;
        // Not even the writer's own stage sees the write in a later pass without a barrier.
        s.visibleStages = VK_PIPELINE_STAGE_2_NONE;
    } else {
        // A layout transition is itself a write that the barrier makes visible to this stage. It happens before
        // use.stage, so a later read in another stage waits for use.stage too: that chains it after the transition
        // (a depth map written by fragment tests, transitioned for a compute read, then sampled by a fragment shader).
        s.writeStage |= use.stage;
        s.readStages = use.stage;
        s.visibleStages = use.stage;
    }
    return b;
}

VkImageMemoryBarrier2 toVulkan(const ImageBarrier& b, VkImage image, VkImageAspectFlags aspect) {
    VkImageMemoryBarrier2 v{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER_2};
    v.srcStageMask = b.srcStage;
    v.srcAccessMask = b.srcAccess;
    v.dstStageMask = b.dstStage;
    v.dstAccessMask = b.dstAccess;
    v.oldLayout = b.oldLayout;
    v.newLayout = b.newLayout;
    v.srcQueueFamilyIndex = v.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    v.image = image;
    v.subresourceRange = {aspect, 0, VK_REMAINING_MIP_LEVELS, 0, VK_REMAINING_ARRAY_LAYERS};
    return v;
}

} // namespace vitrine
