#pragma once

#include "core/gpu/allocator.hpp"

#include <string>
#include <vector>

namespace vitrine {

class Context;

struct ImageDesc {
    uint32_t width = 1;
    uint32_t height = 1;
    uint32_t mipLevels = 1;
    uint32_t layers = 1;
    VkFormat format = VK_FORMAT_R16G16B16A16_SFLOAT;
    VkImageUsageFlags usage = 0;
    bool cube = false;
    bool cubeArray = false; // with cube: the full view is a cube-map array even for 6 layers (one probe)

    VkImageCreateInfo createInfo() const;
    bool operator==(const ImageDesc&) const = default;
};

VkImageAspectFlags aspectOf(VkFormat format);

// A 2D (array/cube) image with its full view and one view per mip. Move-only; destruction is
// deferred through Context::destroyLater until the GPU is done with it. Either owns its
// memory (from the Allocator) or is placed at an offset of memory the render graph owns
// (transient aliasing).
class GpuImage {
public:
    GpuImage() = default;
    GpuImage(Context& ctx, const ImageDesc& desc, const std::string& name);
    GpuImage(Context& ctx, const ImageDesc& desc, const std::string& name, VkDeviceMemory memory, VkDeviceSize offset);
    ~GpuImage();
    GpuImage(GpuImage&& other) noexcept;
    GpuImage& operator=(GpuImage&& other) noexcept;
    GpuImage(const GpuImage&) = delete;
    GpuImage& operator=(const GpuImage&) = delete;

    static VkMemoryRequirements requirements(Context& ctx, const ImageDesc& desc);

    VkImage image() const { return mImage; }
    VkImageView view() const { return mView; }
    VkImageView mipView(uint32_t mip) const { return mMipViews.at(mip); }
    const ImageDesc& desc() const { return mDesc; }
    const std::string& name() const { return mName; }
    explicit operator bool() const { return mImage != VK_NULL_HANDLE; }

private:
    void createViews();
    void release();

    Context* mCtx = nullptr;
    ImageDesc mDesc;
    std::string mName;
    VkImage mImage = VK_NULL_HANDLE;
    VkImageView mView = VK_NULL_HANDLE;
    std::vector<VkImageView> mMipViews;
    Allocation mAllocation;
};

class GpuBuffer {
public:
    GpuBuffer() = default;
    GpuBuffer(Context& ctx, VkDeviceSize size, VkBufferUsageFlags usage, bool hostVisible, const std::string& name);
    ~GpuBuffer();
    GpuBuffer(GpuBuffer&& other) noexcept;
    GpuBuffer& operator=(GpuBuffer&& other) noexcept;
    GpuBuffer(const GpuBuffer&) = delete;
    GpuBuffer& operator=(const GpuBuffer&) = delete;

    VkBuffer buffer() const { return mBuffer; }
    VkDeviceSize size() const { return mSize; }
    void* mapped() const { return mAllocation.mapped; }
    explicit operator bool() const { return mBuffer != VK_NULL_HANDLE; }

private:
    void release();

    Context* mCtx = nullptr;
    VkBuffer mBuffer = VK_NULL_HANDLE;
    VkDeviceSize mSize = 0;
    Allocation mAllocation;
};

} // namespace vitrine
