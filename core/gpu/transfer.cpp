#include "core/gpu/transfer.hpp"

#include "core/base/error.hpp"
#include "core/gpu/context.hpp"
#include "core/gpu/formats.hpp"
#include "core/image/rgb9e5.hpp"

#include <glm/gtc/packing.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>

namespace vitrine {

namespace {

float srgbToLinear(float c) { return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f); }
float linearToSrgb(float c) { return c <= 0.0031308f ? c * 12.92f : 1.055f * std::pow(c, 1.0f / 2.4f) - 0.055f; }

template <typename T> T unorm(float v, float maxValue) {
    return static_cast<T>(std::lround(std::clamp(v, 0.0f, 1.0f) * maxValue));
}

} // namespace

std::vector<uint8_t> packPixels(const Image& image, VkFormat format) {
    const FormatInfo& info = formatInfo(format);
    const size_t count = static_cast<size_t>(image.width) * image.height;
    std::vector<uint8_t> out(count * info.bytesPerPixel);
    uint8_t* dst = out.data();
    for (size_t i = 0; i < count; ++i, dst += info.bytesPerPixel) {
        const float* p = &image.pixels[i * 4];
        switch (format) {
        case VK_FORMAT_R8G8B8A8_UNORM:
            for (int c = 0; c < 4; ++c) dst[c] = unorm<uint8_t>(p[c], 255.0f);
            break;
        case VK_FORMAT_R8G8B8A8_SRGB:
            for (int c = 0; c < 3; ++c) dst[c] = unorm<uint8_t>(linearToSrgb(p[c]), 255.0f);
            dst[3] = unorm<uint8_t>(p[3], 255.0f);
            break;
        case VK_FORMAT_R8_UNORM: dst[0] = unorm<uint8_t>(p[0], 255.0f); break;
        case VK_FORMAT_R8G8_UNORM:
            for (int c = 0; c < 2; ++c) dst[c] = unorm<uint8_t>(p[c], 255.0f);
            break;
        case VK_FORMAT_R16_UNORM:
        case VK_FORMAT_R16G16_UNORM: {
            uint16_t v[2];
            for (uint32_t c = 0; c < info.channels; ++c) v[c] = unorm<uint16_t>(p[c], 65535.0f);
            std::memcpy(dst, v, info.bytesPerPixel);
            break;
        }
        case VK_FORMAT_R16_SFLOAT:
        case VK_FORMAT_R16G16_SFLOAT:
        case VK_FORMAT_R16G16B16A16_SFLOAT: {
            uint16_t v[4];
            for (uint32_t c = 0; c < info.channels; ++c) v[c] = glm::packHalf1x16(p[c]);
            std::memcpy(dst, v, info.bytesPerPixel);
            break;
        }
        case VK_FORMAT_R32_SFLOAT:
        case VK_FORMAT_R32G32_SFLOAT:
        case VK_FORMAT_R32G32B32A32_SFLOAT:
        case VK_FORMAT_D32_SFLOAT: std::memcpy(dst, p, info.bytesPerPixel); break;
        case VK_FORMAT_B10G11R11_UFLOAT_PACK32: {
            uint32_t v = glm::packF2x11_1x10(glm::vec3(std::max(p[0], 0.0f), std::max(p[1], 0.0f), std::max(p[2], 0.0f)));
            std::memcpy(dst, &v, 4);
            break;
        }
        case VK_FORMAT_E5B9G9R9_UFLOAT_PACK32: {
            uint32_t v = packRgb9e5(glm::vec3(p[0], p[1], p[2]));
            std::memcpy(dst, &v, 4);
            break;
        }
        default: throw InternalError("packPixels: unsupported format " + formatName(format));
        }
    }
    return out;
}

Image unpackPixels(const void* data, uint32_t width, uint32_t height, VkFormat format) {
    const FormatInfo& info = formatInfo(format);
    Image image(static_cast<int>(width), static_cast<int>(height));
    const size_t count = static_cast<size_t>(width) * height;
    const uint8_t* src = static_cast<const uint8_t*>(data);
    for (size_t i = 0; i < count; ++i, src += info.bytesPerPixel) {
        float* p = &image.pixels[i * 4];
        p[0] = p[1] = p[2] = 0.0f;
        p[3] = 1.0f;
        switch (format) {
        case VK_FORMAT_R8G8B8A8_UNORM:
        case VK_FORMAT_R8_UNORM:
        case VK_FORMAT_R8G8_UNORM:
            for (uint32_t c = 0; c < info.channels; ++c) p[c] = src[c] / 255.0f;
            break;
        case VK_FORMAT_R8G8B8A8_SRGB:
            for (int c = 0; c < 3; ++c) p[c] = srgbToLinear(src[c] / 255.0f);
            p[3] = src[3] / 255.0f;
            break;
        case VK_FORMAT_R16_UNORM:
        case VK_FORMAT_R16G16_UNORM: {
            uint16_t v[2];
            std::memcpy(v, src, info.bytesPerPixel);
            for (uint32_t c = 0; c < info.channels; ++c) p[c] = v[c] / 65535.0f;
            break;
        }
        case VK_FORMAT_R16_SFLOAT:
        case VK_FORMAT_R16G16_SFLOAT:
        case VK_FORMAT_R16G16B16A16_SFLOAT: {
            uint16_t v[4];
            std::memcpy(v, src, info.bytesPerPixel);
            for (uint32_t c = 0; c < info.channels; ++c) p[c] = glm::unpackHalf1x16(v[c]);
            break;
        }
        case VK_FORMAT_R32_SFLOAT:
        case VK_FORMAT_R32G32_SFLOAT:
        case VK_FORMAT_R32G32B32A32_SFLOAT:
        case VK_FORMAT_D32_SFLOAT: std::memcpy(p, src, info.bytesPerPixel); break;
        case VK_FORMAT_R32_UINT: {
            uint32_t v;
            std::memcpy(&v, src, 4);
            p[0] = static_cast<float>(v);
            break;
        }
        case VK_FORMAT_B10G11R11_UFLOAT_PACK32: {
            uint32_t v;
            std::memcpy(&v, src, 4);
            glm::vec3 c = glm::unpackF2x11_1x10(v);
            p[0] = c.x;
            p[1] = c.y;
            p[2] = c.z;
            break;
        }
        case VK_FORMAT_E5B9G9R9_UFLOAT_PACK32: {
            uint32_t v;
            std::memcpy(&v, src, 4);
            glm::vec3 c = unpackRgb9e5(v);
            p[0] = c.x;
            p[1] = c.y;
            p[2] = c.z;
            break;
        }
        default: throw InternalError("unpackPixels: unsupported format " + formatName(format));
        }
    }
    return image;
}

namespace {

void transition(VkCommandBuffer cmd, const GpuImage& image, VkImageLayout from, VkImageLayout to, uint32_t mip,
                uint32_t layer) {
    VkImageMemoryBarrier2 b{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER_2};
    b.srcStageMask = VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT;
    b.srcAccessMask = VK_ACCESS_2_MEMORY_WRITE_BIT;
    b.dstStageMask = VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT;
    b.dstAccessMask = VK_ACCESS_2_MEMORY_READ_BIT | VK_ACCESS_2_MEMORY_WRITE_BIT;
    b.oldLayout = from;
    b.newLayout = to;
    b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    b.image = image.image();
    b.subresourceRange = {aspectOf(image.desc().format), mip, 1, layer, 1};
    VkDependencyInfo dep{VK_STRUCTURE_TYPE_DEPENDENCY_INFO};
    dep.imageMemoryBarrierCount = 1;
    dep.pImageMemoryBarriers = &b;
    vkCmdPipelineBarrier2(cmd, &dep);
}

} // namespace

Image readImage(Context& ctx, const GpuImage& image, VkImageLayout layout, uint32_t mip, uint32_t layer) {
    const ImageDesc& d = image.desc();
    uint32_t w = std::max(1u, d.width >> mip), h = std::max(1u, d.height >> mip);
    const FormatInfo& info = formatInfo(d.format);
    GpuBuffer staging(ctx, static_cast<VkDeviceSize>(w) * h * info.bytesPerPixel, VK_BUFFER_USAGE_TRANSFER_DST_BIT,
                      true, image.name() + ".readback");
    ctx.immediate([&](VkCommandBuffer cmd) {
        transition(cmd, image, layout, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, mip, layer);
        VkBufferImageCopy region{};
        region.imageSubresource = {aspectOf(d.format), mip, layer, 1};
        region.imageExtent = {w, h, 1};
        vkCmdCopyImageToBuffer(cmd, image.image(), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, staging.buffer(), 1, &region);
        if (layout != VK_IMAGE_LAYOUT_UNDEFINED)
            transition(cmd, image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, layout, mip, layer);
    });
    return unpackPixels(staging.mapped(), w, h, d.format);
}

GpuBuffer recordUpload(Context& ctx, VkCommandBuffer cmd, const GpuImage& image, const Image& pixels, uint32_t layer) {
    const ImageDesc& d = image.desc();
    if (static_cast<uint32_t>(pixels.width) != d.width || static_cast<uint32_t>(pixels.height) != d.height)
        throw InternalError("upload of a " + std::to_string(pixels.width) + "x" + std::to_string(pixels.height) +
                            " image into " + image.name() + " (" + std::to_string(d.width) + "x" +
                            std::to_string(d.height) + ")");
    std::vector<uint8_t> bytes = packPixels(pixels, d.format);
    GpuBuffer staging(ctx, bytes.size(), VK_BUFFER_USAGE_TRANSFER_SRC_BIT, true, image.name() + ".upload");
    std::memcpy(staging.mapped(), bytes.data(), bytes.size());
    VkBufferImageCopy region{};
    region.imageSubresource = {aspectOf(d.format), 0, layer, 1};
    region.imageExtent = {d.width, d.height, 1};
    vkCmdCopyBufferToImage(cmd, staging.buffer(), image.image(), VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &region);
    return staging;
}

GpuBuffer uploadBuffer(Context& ctx, const void* data, size_t bytes, VkBufferUsageFlags usage, const std::string& name) {
    bytes = std::max<size_t>(bytes, 16);
    GpuBuffer staging(ctx, bytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, true, name + ".staging");
    std::memset(staging.mapped(), 0, bytes);
    if (data) std::memcpy(staging.mapped(), data, bytes);
    GpuBuffer buffer(ctx, bytes, usage | VK_BUFFER_USAGE_TRANSFER_DST_BIT, false, name);
    ctx.immediate([&](VkCommandBuffer cmd) {
        VkBufferCopy copy{0, 0, bytes};
        vkCmdCopyBuffer(cmd, staging.buffer(), buffer.buffer(), 1, &copy);
    });
    return buffer;
}

void imageBarrier(VkCommandBuffer cmd, VkImage image, uint32_t baseMip, uint32_t mips, VkImageLayout from, VkImageLayout to,
                  VkPipelineStageFlags2 srcStage, VkAccessFlags2 srcAccess, VkPipelineStageFlags2 dstStage,
                  VkAccessFlags2 dstAccess) {
    VkImageMemoryBarrier2 b{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER_2};
    b.srcStageMask = srcStage;
    b.srcAccessMask = srcAccess;
    b.dstStageMask = dstStage;
    b.dstAccessMask = dstAccess;
    b.oldLayout = from;
    b.newLayout = to;
    b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    b.image = image;
    b.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, baseMip, mips, 0, 1};
    VkDependencyInfo dep{VK_STRUCTURE_TYPE_DEPENDENCY_INFO};
    dep.imageMemoryBarrierCount = 1;
    dep.pImageMemoryBarriers = &b;
    vkCmdPipelineBarrier2(cmd, &dep);
}

} // namespace vitrine
