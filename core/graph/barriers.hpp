#pragma once

#include "core/graph/types.hpp"

#include <optional>
#include <vector>

namespace vitrine {

// What one use of an image needs: its layout and the stages/accesses the barrier must cover.
struct AccessInfo {
    VkImageLayout layout = VK_IMAGE_LAYOUT_UNDEFINED;
    VkPipelineStageFlags2 stage = VK_PIPELINE_STAGE_2_NONE;
    VkAccessFlags2 access = VK_ACCESS_2_NONE;
    bool write = false;
};
AccessInfo accessOf(Usage usage, PassKind pass);

// Synchronization state of one physical image between passes.
struct ImageSyncState {
    VkImageLayout layout = VK_IMAGE_LAYOUT_UNDEFINED;
    VkPipelineStageFlags2 writeStage = VK_PIPELINE_STAGE_2_NONE; // last write
    VkAccessFlags2 writeAccess = VK_ACCESS_2_NONE;
    VkPipelineStageFlags2 readStages = VK_PIPELINE_STAGE_2_NONE;   // reads since the last write
    VkPipelineStageFlags2 visibleStages = VK_PIPELINE_STAGE_2_NONE; // stages the last write is visible to

    // Contents are discarded (start of frame for a transient): the next use starts from
    // UNDEFINED but must still wait for whatever used the memory before (aliasing).
    static ImageSyncState discarded();
};

struct ImageBarrier {
    uint32_t image = 0; // caller's index of the physical image
    VkImageLayout oldLayout = VK_IMAGE_LAYOUT_UNDEFINED;
    VkImageLayout newLayout = VK_IMAGE_LAYOUT_UNDEFINED;
    VkPipelineStageFlags2 srcStage = VK_PIPELINE_STAGE_2_NONE;
    VkAccessFlags2 srcAccess = VK_ACCESS_2_NONE;
    VkPipelineStageFlags2 dstStage = VK_PIPELINE_STAGE_2_NONE;
    VkAccessFlags2 dstAccess = VK_ACCESS_2_NONE;
};

// Phase 6: the barrier (if any) that must precede `use` of `image`, and the updated state.
// Read-after-read in the same layout needs none; write-after-read needs an execution
// dependency only; anything after a write makes the write available and visible.
std::optional<ImageBarrier> requireAccess(ImageSyncState& state, uint32_t image, const AccessInfo& use);

VkImageMemoryBarrier2 toVulkan(const ImageBarrier& barrier, VkImage image, VkImageAspectFlags aspect);

} // namespace vitrine
