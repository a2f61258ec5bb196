#include "core/gpu/resources.hpp"

#include "core/gpu/context.hpp"
#include "core/gpu/formats.hpp"

#include <utility>

namespace vitrine {

VkImageCreateInfo ImageDesc::createInfo() const {
    VkImageCreateInfo info{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
    info.flags = cube ? VK_IMAGE_CREATE_CUBE_COMPATIBLE_BIT : 0;
    info.imageType = VK_IMAGE_TYPE_2D;
    info.format = format;
    info.extent = {width, height, 1};
    info.mipLevels = mipLevels;
    info.arrayLayers = layers;
    info.samples = VK_SAMPLE_COUNT_1_BIT;
    info.tiling = VK_IMAGE_TILING_OPTIMAL;
    info.usage = usage;
    info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
    info.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
    return info;
}

VkImageAspectFlags aspectOf(VkFormat format) {
    return formatInfo(format).depth ? VK_IMAGE_ASPECT_DEPTH_BIT : VK_IMAGE_ASPECT_COLOR_BIT;
}

VkMemoryRequirements GpuImage::requirements(Context& ctx, const ImageDesc& desc) {
    VkImageCreateInfo info = desc.createInfo();
    VkDeviceImageMemoryRequirements query{VK_STRUCTURE_TYPE_DEVICE_IMAGE_MEMORY_REQUIREMENTS};
    query.pCreateInfo = &info;
    VkMemoryRequirements2 req{VK_STRUCTURE_TYPE_MEMORY_REQUIREMENTS_2};
    vkGetDeviceImageMemoryRequirements(ctx.device(), &query, &req);
    return req.memoryRequirements;
}

GpuImage::GpuImage(Context& ctx, const ImageDesc& desc, const std::string& name) : mCtx(&ctx), mDesc(desc), mName(name) {
    VkImageCreateInfo info = desc.createInfo();
    VK_CHECK(vkCreateImage(ctx.device(), &info, nullptr, &mImage));
    VkMemoryRequirements req;
    vkGetImageMemoryRequirements(ctx.device(), mImage, &req);
    mAllocation = ctx.allocator().allocate(req, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT, false);
    debugPoisonAllocation(mAllocation, "image " + name);
    VK_CHECK(vkBindImageMemory(ctx.device(), mImage, mAllocation.memory, mAllocation.offset));
    createViews();
}

GpuImage::GpuImage(Context& ctx, const ImageDesc& desc, const std::string& name, VkDeviceMemory memory,
                   VkDeviceSize offset)
    : mCtx(&ctx), mDesc(desc), mName(name) {
    VkImageCreateInfo info = desc.createInfo();
    VK_CHECK(vkCreateImage(ctx.device(), &info, nullptr, &mImage));
    VK_CHECK(vkBindImageMemory(ctx.device(), mImage, memory, offset));
    createViews();
}

void GpuImage::createViews() {
    mCtx->setName(reinterpret_cast<uint64_t>(mImage), VK_OBJECT_TYPE_IMAGE, mName);
    VkImageViewCreateInfo info{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
    info.image = mImage;
    // A cube image of more than 6 layers is a cube-map array (6 layers per cube: ibl.capture's probes).
    info.viewType = mDesc.cube ? (mDesc.layers > 6 || mDesc.cubeArray ? VK_IMAGE_VIEW_TYPE_CUBE_ARRAY : VK_IMAGE_VIEW_TYPE_CUBE)
                               : (mDesc.layers > 1 ? VK_IMAGE_VIEW_TYPE_2D_ARRAY : VK_IMAGE_VIEW_TYPE_2D);
    info.format = mDesc.format;
    info.subresourceRange = {aspectOf(mDesc.format), 0, mDesc.mipLevels, 0, mDesc.layers};
    VK_CHECK(vkCreateImageView(mCtx->device(), &info, nullptr, &mView));
    mCtx->setName(reinterpret_cast<uint64_t>(mView), VK_OBJECT_TYPE_IMAGE_VIEW, mName + ".view");
    // Per-mip views are 2D arrays for layered images so compute shaders can write any layer.
    if (mDesc.layers > 1) info.viewType = VK_IMAGE_VIEW_TYPE_2D_ARRAY;
    for (uint32_t mip = 0; mip < mDesc.mipLevels; ++mip) {
        info.subresourceRange = {aspectOf(mDesc.format), mip, 1, 0, mDesc.layers};
        VkImageView view;
        VK_CHECK(vkCreateImageView(mCtx->device(), &info, nullptr, &view));
        mMipViews.push_back(view);
    }
}

void GpuImage::release() {
    if (!mCtx || !mImage) return;
    Context* ctx = mCtx;
    VkImage image = mImage;
    VkImageView view = mView;
    std::vector<VkImageView> mips = std::move(mMipViews);
    Allocation allocation = mAllocation;
    ctx->destroyLater([ctx, image, view, mips, allocation] {
        for (VkImageView v : mips) vkDestroyImageView(ctx->device(), v, nullptr);
        vkDestroyImageView(ctx->device(), view, nullptr);
        vkDestroyImage(ctx->device(), image, nullptr);
        if (allocation) ctx->allocator().free(allocation);
    });
    mImage = VK_NULL_HANDLE;
    mView = VK_NULL_HANDLE;
    mAllocation = {};
}

GpuImage::~GpuImage() { release(); }

GpuImage::GpuImage(GpuImage&& o) noexcept
    : mCtx(o.mCtx), mDesc(o.mDesc), mName(std::move(o.mName)), mImage(std::exchange(o.mImage, VK_NULL_HANDLE)),
      mView(std::exchange(o.mView, VK_NULL_HANDLE)), mMipViews(std::move(o.mMipViews)),
      mAllocation(std::exchange(o.mAllocation, {})) {}

GpuImage& GpuImage::operator=(GpuImage&& o) noexcept {
    if (this != &o) {
        release();
        mCtx = o.mCtx;
        mDesc = o.mDesc;
        mName = std::move(o.mName);
        mImage = std::exchange(o.mImage, VK_NULL_HANDLE);
        mView = std::exchange(o.mView, VK_NULL_HANDLE);
        mMipViews = std::move(o.mMipViews);
        mAllocation = std::exchange(o.mAllocation, {});
    }
    return *this;
}

GpuBuffer::GpuBuffer(Context& ctx, VkDeviceSize size, VkBufferUsageFlags usage, bool hostVisible,
                     const std::string& name)
    : mCtx(&ctx), mSize(size) {
    VkBufferCreateInfo info{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
    info.size = size;
    info.usage = usage;
    VK_CHECK(vkCreateBuffer(ctx.device(), &info, nullptr, &mBuffer));
    VkMemoryRequirements req;
    vkGetBufferMemoryRequirements(ctx.device(), mBuffer, &req);
    VkMemoryPropertyFlags props = hostVisible
                                      ? VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT
                                      : VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT;
    mAllocation = ctx.allocator().allocate(req, props, true);
    debugPoisonAllocation(mAllocation, "buffer " + name);
    VK_CHECK(vkBindBufferMemory(ctx.device(), mBuffer, mAllocation.memory, mAllocation.offset));
    ctx.setName(reinterpret_cast<uint64_t>(mBuffer), VK_OBJECT_TYPE_BUFFER, name);
}

void GpuBuffer::release() {
    if (!mCtx || !mBuffer) return;
    Context* ctx = mCtx;
    VkBuffer buffer = mBuffer;
    Allocation allocation = mAllocation;
    ctx->destroyLater([ctx, buffer, allocation] {
        vkDestroyBuffer(ctx->device(), buffer, nullptr);
        ctx->allocator().free(allocation);
    });
    mBuffer = VK_NULL_HANDLE;
    mAllocation = {};
}

GpuBuffer::~GpuBuffer() { release(); }

GpuBuffer::GpuBuffer(GpuBuffer&& o) noexcept
    : mCtx(o.mCtx), mBuffer(std::exchange(o.mBuffer, VK_NULL_HANDLE)), mSize(o.mSize),
      mAllocation(std::exchange(o.mAllocation, {})) {}

GpuBuffer& GpuBuffer::operator=(GpuBuffer&& o) noexcept {
    if (this != &o) {
        release();
        mCtx = o.mCtx;
        mBuffer = std::exchange(o.mBuffer, VK_NULL_HANDLE);
        mSize = o.mSize;
        mAllocation = std::exchange(o.mAllocation, {});
    }
    return *this;
}

} // namespace vitrine
