#pragma once

#include "core/gpu/resources.hpp"
#include "core/image/image.hpp"

#include <cstdint>
#include <vector>

namespace vitrine {

// Texel packing between vitrine::Image (float RGBA) and the formats of formats.hpp. Missing
// channels read back as 0 (alpha as 1); sRGB formats are decoded to linear on unpack.
std::vector<uint8_t> packPixels(const Image& image, VkFormat format);
Image unpackPixels(const void* data, uint32_t width, uint32_t height, VkFormat format);

// Copies one mip/layer of `image` to the host. The image is in `layout` before and after.
// Waits for the GPU: for tests, the CLI's output writing and debugging, not per-frame work.
Image readImage(Context& ctx, const GpuImage& image, VkImageLayout layout, uint32_t mip = 0, uint32_t layer = 0);

// A device-local buffer filled with `bytes` of `data` (zeros where data is null) through a staging copy.
// At least 16 bytes, so empty arrays still bind. Waits for the GPU: for uploads at load time.
GpuBuffer uploadBuffer(Context& ctx, const void* data, size_t bytes, VkBufferUsageFlags usage, const std::string& name);

// Records a copy of `pixels` into mip 0 / layer `layer` of `image`, which must be in
// TRANSFER_DST_OPTIMAL. The staging buffer is returned so the caller keeps it alive (its
// destruction is deferred anyway).
GpuBuffer recordUpload(Context& ctx, VkCommandBuffer cmd, const GpuImage& image, const Image& pixels,
                       uint32_t layer = 0);

// Records one image memory barrier over mips [baseMip, baseMip + mips) of layer 0 (colour aspect). For code that
// works outside the render graph (uploads, bakes); graph passes get their barriers from the executor.
void imageBarrier(VkCommandBuffer cmd, VkImage image, uint32_t baseMip, uint32_t mips, VkImageLayout from, VkImageLayout to,
                  VkPipelineStageFlags2 srcStage, VkAccessFlags2 srcAccess, VkPipelineStageFlags2 dstStage,
                  VkAccessFlags2 dstAccess);

} // namespace vitrine
