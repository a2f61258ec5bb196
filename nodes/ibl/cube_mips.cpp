// Host-side helpers for ibl.capture's and ibl.environment's prefiltered cube maps (nodes/ibl/cube_mips.hpp).
#include "nodes/ibl/cube_mips.hpp"

#include "core/gpu/context.hpp"

#include <cstring>

namespace vitrine {

// The 2x2 box-filtered mip chain of each face, the "mip-filtered source" of filtered importance sampling.
std::vector<std::vector<Image>> boxMips(std::vector<Image> faces, uint32_t mips) {
    std::vector<std::vector<Image>> chain(mips);
    chain[0] = std::move(faces);
    for (uint32_t m = 1; m < mips; ++m)
        for (const Image& src : chain[m - 1]) {
            Image dst(src.width / 2, src.height / 2);
            for (int y = 0; y < dst.height; ++y)
                for (int x = 0; x < dst.width; ++x)
                    for (int c = 0; c < 4; ++c)
                        dst.at(x, y)[c] = 0.25f * (src.at(2 * x, 2 * y)[c] + src.at(2 * x + 1, 2 * y)[c] +
                                                   src.at(2 * x, 2 * y + 1)[c] + src.at(2 * x + 1, 2 * y + 1)[c]);
            chain[m].push_back(std::move(dst));
        }
    return chain;
}

// Fills every mip and layer of `image` (RGBA32F, just created) from host data and leaves it ready to be sampled by
// compute shaders. Outside the frame's command buffer: it waits for the GPU.
void uploadCubeMips(Context& ctx, const GpuImage& image, const std::vector<std::vector<Image>>& mips) {
    const ImageDesc& d = image.desc();
    size_t bytes = 0;
    for (const auto& level : mips)
        for (const Image& face : level)
            bytes += face.pixels.size() * sizeof(float);
    GpuBuffer staging(ctx, bytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, true, "ibl.cube_mips.staging");
    std::vector<VkBufferImageCopy> regions;
    size_t offset = 0;
    for (uint32_t m = 0; m < mips.size(); ++m)
        for (uint32_t layer = 0; layer < mips[m].size(); ++layer) {
            const Image& face = mips[m][layer];
            std::memcpy(static_cast<uint8_t*>(staging.mapped()) + offset, face.pixels.data(), face.pixels.size() * 4);
            VkBufferImageCopy r{};
            r.bufferOffset = offset;
            r.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, m, layer, 1};
            r.imageExtent = {static_cast<uint32_t>(face.width), static_cast<uint32_t>(face.height), 1};
            regions.push_back(r);
            offset += face.pixels.size() * 4;
        }
    ctx.immediate([&](VkCommandBuffer cmd) {
        auto barrier = [&](VkImageLayout from, VkImageLayout to, VkPipelineStageFlags2 srcStage,
                           VkAccessFlags2 srcAccess, VkPipelineStageFlags2 dstStage, VkAccessFlags2 dstAccess) {
            VkImageMemoryBarrier2 b{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER_2};
            b.srcStageMask = srcStage;
            b.srcAccessMask = srcAccess;
            b.dstStageMask = dstStage;
            b.dstAccessMask = dstAccess;
            b.oldLayout = from;
            b.newLayout = to;
            b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
            b.image = image.image();
            b.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, d.mipLevels, 0, d.layers};
            VkDependencyInfo dep{VK_STRUCTURE_TYPE_DEPENDENCY_INFO};
            dep.imageMemoryBarrierCount = 1;
            dep.pImageMemoryBarriers = &b;
            vkCmdPipelineBarrier2(cmd, &dep);
        };
        barrier(VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_PIPELINE_STAGE_2_NONE, 0,
                VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT);
        vkCmdCopyBufferToImage(cmd, staging.buffer(), image.image(), VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                               static_cast<uint32_t>(regions.size()), regions.data());
        barrier(VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
                VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_SAMPLED_READ_BIT);
    });
}

void resetPrefilterSets(Context& gpu, DescriptorSets& sets, const std::string& name) {
    if (!sets) {
        const VkDescriptorSetLayoutBinding bindings[] = {
            {0, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 1, VK_SHADER_STAGE_COMPUTE_BIT, nullptr},
            {1, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, 1, VK_SHADER_STAGE_COMPUTE_BIT, nullptr}};
        const SamplerDesc sampler[] = {{VK_FILTER_LINEAR, VK_SAMPLER_MIPMAP_MODE_LINEAR}};
        sets = DescriptorSets(gpu, bindings, 16, sampler, name);
    }
    sets.reset();
}

VkDescriptorSet prefilterMipSet(Context& gpu, DescriptorSets& sets, VkImageView source, VkImageView target) {
    const VkDescriptorSet set = sets.allocate();
    DescriptorWrites(set)
        .image(0, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER,
               {sets.sampler(0), source, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL})
        .image(1, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, {VK_NULL_HANDLE, target, VK_IMAGE_LAYOUT_GENERAL})
        .update(gpu.device());
    return set;
}

} // namespace vitrine
