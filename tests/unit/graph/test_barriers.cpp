// Phase 6: barrier derivation. Expected barriers are written out by hand from the Vulkan
// synchronization rules (a write must be made available by its stage/access and visible to the
// reader's stage/access; a layout transition must wait for every earlier access; read after
// read needs nothing), not taken from the code under test.
#include "core/graph/barriers.hpp"

#include <gtest/gtest.h>

namespace vitrine {
namespace {

constexpr VkPipelineStageFlags2 kCompute = VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT;
constexpr VkAccessFlags2 kStorageWrite = VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT;
constexpr VkAccessFlags2 kStorageRead = VK_ACCESS_2_SHADER_STORAGE_READ_BIT;
constexpr VkAccessFlags2 kSampledRead = VK_ACCESS_2_SHADER_SAMPLED_READ_BIT;

void expectBarrier(const std::optional<ImageBarrier>& b, VkImageLayout oldLayout, VkImageLayout newLayout,
                   VkPipelineStageFlags2 srcStage, VkAccessFlags2 srcAccess, VkPipelineStageFlags2 dstStage,
                   VkAccessFlags2 dstAccess) {
    ASSERT_TRUE(b.has_value());
    EXPECT_EQ(b->oldLayout, oldLayout);
    EXPECT_EQ(b->newLayout, newLayout);
    EXPECT_EQ(b->srcStage, srcStage);
    EXPECT_EQ(b->srcAccess, srcAccess);
    EXPECT_EQ(b->dstStage, dstStage);
    EXPECT_EQ(b->dstAccess, dstAccess);
}

TEST(GraphBarriers, AccessOfComputeUsages) {
    AccessInfo write = accessOf(Usage::StorageWrite, PassKind::Compute);
    EXPECT_EQ(write.layout, VK_IMAGE_LAYOUT_GENERAL);
    EXPECT_EQ(write.stage, kCompute);
    EXPECT_EQ(write.access, kStorageWrite);
    EXPECT_TRUE(write.write);

    AccessInfo sampled = accessOf(Usage::Sampled, PassKind::Compute);
    EXPECT_EQ(sampled.layout, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
    EXPECT_EQ(sampled.stage, kCompute);
    EXPECT_EQ(sampled.access, kSampledRead);
    EXPECT_FALSE(sampled.write);

    AccessInfo fragment = accessOf(Usage::Sampled, PassKind::Raster);
    EXPECT_EQ(fragment.stage, VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT);

    AccessInfo upload = accessOf(Usage::TransferDst, PassKind::Transfer);
    EXPECT_EQ(upload.layout, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL);
    EXPECT_EQ(upload.access, VK_ACCESS_2_TRANSFER_WRITE_BIT);
    EXPECT_TRUE(upload.write);
}

// A depth map drawn by one raster pass, then depth-tested read-only and sampled by a later one (ibl.localized's
// light volumes): one transition to DEPTH_STENCIL_READ_ONLY_OPTIMAL after the depth writes, visible to the depth tests and
// the fragment shader; the read-only use writes nothing, so a later sampled read waits only for the layout change.
TEST(GraphBarriers, DepthWriteThenDepthReadOnlyAndSampled) {
    constexpr VkPipelineStageFlags2 kTests =
        VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT | VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT;
    constexpr VkPipelineStageFlags2 kFragment = VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT;
    AccessInfo read = accessOf(Usage::DepthRead, PassKind::Raster);
    EXPECT_EQ(read.layout, VK_IMAGE_LAYOUT_DEPTH_STENCIL_READ_ONLY_OPTIMAL);
    EXPECT_EQ(read.stage, kTests | kFragment);
    EXPECT_EQ(read.access, VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_READ_BIT | kSampledRead);
    EXPECT_FALSE(read.write);

    ImageSyncState s;
    requireAccess(s, 0, accessOf(Usage::DepthAttachment, PassKind::Raster));
    expectBarrier(requireAccess(s, 0, read), VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL,
                  VK_IMAGE_LAYOUT_DEPTH_STENCIL_READ_ONLY_OPTIMAL, kTests, VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT,
                  kTests | kFragment, VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_READ_BIT | kSampledRead);
    EXPECT_FALSE(requireAccess(s, 0, read).has_value()); // read after read in the same layout
}

TEST(GraphBarriers, WriteSampleSampleWriteSequence) {
    ImageSyncState x;
    const AccessInfo write = accessOf(Usage::StorageWrite, PassKind::Compute);
    const AccessInfo sample = accessOf(Usage::Sampled, PassKind::Compute);

    // Pass 0 writes: a transition out of UNDEFINED with nothing before it to wait for.
    auto b0 = requireAccess(x, 7, write);
    expectBarrier(b0, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_GENERAL, VK_PIPELINE_STAGE_2_NONE, VK_ACCESS_2_NONE,
                  kCompute, kStorageWrite);
    EXPECT_EQ(b0->image, 7u);

    // Pass 1 samples: the storage write must be made available and visible to sampled reads.
    auto b1 = requireAccess(x, 7, sample);
    expectBarrier(b1, VK_IMAGE_LAYOUT_GENERAL, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, kCompute, kStorageWrite,
                  kCompute, kSampledRead);

    // Pass 2 samples again: read after read in the same layout and stage needs nothing.
    EXPECT_FALSE(requireAccess(x, 7, sample).has_value());

    // Pass 3 writes again: write after read. The transition must wait for the compute reads
    // (an execution dependency); there is nothing new to make available, so srcAccess may hold
    // at most the earlier storage write (already available, so harmless) and never a read bit.
    auto b3 = requireAccess(x, 7, write);
    ASSERT_TRUE(b3.has_value());
    EXPECT_EQ(b3->oldLayout, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
    EXPECT_EQ(b3->newLayout, VK_IMAGE_LAYOUT_GENERAL);
    EXPECT_EQ(b3->srcStage, kCompute);
    EXPECT_EQ(b3->srcAccess & ~kStorageWrite, VK_ACCESS_2_NONE);
    EXPECT_EQ(b3->dstStage, kCompute);
    EXPECT_EQ(b3->dstAccess, kStorageWrite);
}

TEST(GraphBarriers, WriteAfterWriteInGeneralNeedsAMemoryBarrier) {
    ImageSyncState x;
    const AccessInfo write = accessOf(Usage::StorageWrite, PassKind::Compute);
    requireAccess(x, 0, write);
    // Same layout, but the second write must not race the first (WAW hazard).
    auto b = requireAccess(x, 0, write);
    expectBarrier(b, VK_IMAGE_LAYOUT_GENERAL, VK_IMAGE_LAYOUT_GENERAL, kCompute, kStorageWrite, kCompute,
                  kStorageWrite);
}

TEST(GraphBarriers, StorageReadAfterWriteInGeneralNeedsAMemoryBarrier) {
    // No layout change here, so only the hazard tracking can ask for the barrier: a storage
    // write of one dispatch is not visible to a later dispatch without one (RAW hazard).
    ImageSyncState x;
    requireAccess(x, 0, accessOf(Usage::StorageWrite, PassKind::Compute));
    auto b = requireAccess(x, 0, accessOf(Usage::StorageRead, PassKind::Compute));
    expectBarrier(b, VK_IMAGE_LAYOUT_GENERAL, VK_IMAGE_LAYOUT_GENERAL, kCompute, kStorageWrite, kCompute, kStorageRead);
    // Now visible to compute storage reads: a second read needs nothing.
    EXPECT_FALSE(requireAccess(x, 0, accessOf(Usage::StorageRead, PassKind::Compute)).has_value());
}

TEST(GraphBarriers, ReadInANewStageMakesTheWriteVisibleThere) {
    ImageSyncState x;
    requireAccess(x, 0, accessOf(Usage::StorageWrite, PassKind::Compute));
    requireAccess(x, 0, accessOf(Usage::Sampled, PassKind::Compute));
    // Same layout, new stage: the fragment shader must wait for the compute write.
    auto b = requireAccess(x, 0, accessOf(Usage::Sampled, PassKind::Raster));
    ASSERT_TRUE(b.has_value());
    EXPECT_EQ(b->oldLayout, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
    EXPECT_EQ(b->newLayout, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
    EXPECT_EQ(b->srcStage & kCompute, kCompute);
    EXPECT_EQ(b->dstStage, VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT);
    EXPECT_EQ(b->dstAccess, kSampledRead);
}

TEST(GraphBarriers, ReadInANewStageWaitsForAnEarlierReadsLayoutTransition) {
    ImageSyncState x;
    requireAccess(x, 0, accessOf(Usage::DepthAttachment, PassKind::Raster)); // a shadow map rendered
    auto toCompute = requireAccess(x, 0, accessOf(Usage::Sampled, PassKind::Compute));
    ASSERT_TRUE(toCompute.has_value()); // the transition to SHADER_READ_ONLY, before the compute shader
    // Sampled by a fragment shader next: the barrier must wait for the compute stage, after which the layout
    // transition is known complete, not only for the depth write.
    auto b = requireAccess(x, 0, accessOf(Usage::Sampled, PassKind::Raster));
    ASSERT_TRUE(b.has_value());
    EXPECT_EQ(b->srcStage & kCompute, kCompute);
    EXPECT_EQ(b->dstStage, VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT);
}

TEST(GraphBarriers, DiscardedImageWaitsForEverythingBefore) {
    // A transient whose memory an earlier resource may have used: the first write starts from
    // UNDEFINED but must wait for all prior commands and their writes.
    ImageSyncState x = ImageSyncState::discarded();
    EXPECT_EQ(x.layout, VK_IMAGE_LAYOUT_UNDEFINED);
    auto b = requireAccess(x, 3, accessOf(Usage::StorageWrite, PassKind::Compute));
    expectBarrier(b, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_GENERAL, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT,
                  VK_ACCESS_2_MEMORY_WRITE_BIT, kCompute, kStorageWrite);
}

TEST(GraphBarriers, UploadThenSampleTransitionsFromTransferDst) {
    ImageSyncState x;
    auto up = requireAccess(x, 0, accessOf(Usage::TransferDst, PassKind::Transfer));
    expectBarrier(up, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_PIPELINE_STAGE_2_NONE,
                  VK_ACCESS_2_NONE, VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT);
    auto read = requireAccess(x, 0, accessOf(Usage::Sampled, PassKind::Compute));
    expectBarrier(read, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
                  VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT, kCompute, kSampledRead);
}

TEST(GraphBarriers, ToVulkanCopiesEveryField) {
    ImageBarrier b{5,           VK_IMAGE_LAYOUT_GENERAL, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
                   kCompute,    kStorageWrite,           VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT,
                   kSampledRead};
    VkImage image = reinterpret_cast<VkImage>(static_cast<uintptr_t>(0x1234));
    VkImageMemoryBarrier2 v = toVulkan(b, image, VK_IMAGE_ASPECT_COLOR_BIT);
    EXPECT_EQ(v.sType, VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER_2);
    EXPECT_EQ(v.oldLayout, VK_IMAGE_LAYOUT_GENERAL);
    EXPECT_EQ(v.newLayout, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
    EXPECT_EQ(v.srcStageMask, kCompute);
    EXPECT_EQ(v.srcAccessMask, kStorageWrite);
    EXPECT_EQ(v.dstStageMask, VK_PIPELINE_STAGE_2_FRAGMENT_SHADER_BIT);
    EXPECT_EQ(v.dstAccessMask, kSampledRead);
    EXPECT_EQ(v.image, image);
    EXPECT_EQ(v.srcQueueFamilyIndex, VK_QUEUE_FAMILY_IGNORED);
    EXPECT_EQ(v.dstQueueFamilyIndex, VK_QUEUE_FAMILY_IGNORED);
    EXPECT_EQ(v.subresourceRange.aspectMask, static_cast<VkImageAspectFlags>(VK_IMAGE_ASPECT_COLOR_BIT));
    EXPECT_EQ(v.subresourceRange.levelCount, VK_REMAINING_MIP_LEVELS);
    EXPECT_EQ(v.subresourceRange.layerCount, VK_REMAINING_ARRAY_LAYERS);
}

} // namespace
} // namespace vitrine
