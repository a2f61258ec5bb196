#include "core/accel/ray_batch.hpp"

#include "core/base/error.hpp"
#include "core/gpu/context.hpp"
#include "core/gpu/pipeline.hpp"
#include "core/gpu/profiler.hpp"
#include "core/gpu/transfer.hpp"
#include "core/gpu/vk_check.hpp"
#include "core/shader/compiler.hpp"
#include "core/shader/reflection.hpp"

#include <algorithm>
#include <chrono>
#include <cstring>

namespace vitrine {

using namespace gpu_types;

namespace {

VkDescriptorSetLayout storageLayout(VkDevice device, uint32_t count) {
    std::vector<VkDescriptorSetLayoutBinding> b(count);
    for (uint32_t i = 0; i < count; ++i)
        b[i] = {i, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, VK_SHADER_STAGE_COMPUTE_BIT | VK_SHADER_STAGE_FRAGMENT_BIT,
                nullptr};
    VkDescriptorSetLayoutCreateInfo li{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
    li.bindingCount = count;
    li.pBindings = b.data();
    VkDescriptorSetLayout layout;
    VK_CHECK(vkCreateDescriptorSetLayout(device, &li, nullptr, &layout));
    return layout;
}

void bufferBarrier(VkCommandBuffer cmd, VkPipelineStageFlags2 srcStage, VkAccessFlags2 srcAccess,
                   VkPipelineStageFlags2 dstStage, VkAccessFlags2 dstAccess) {
    VkMemoryBarrier2 b{VK_STRUCTURE_TYPE_MEMORY_BARRIER_2};
    b.srcStageMask = srcStage;
    b.srcAccessMask = srcAccess;
    b.dstStageMask = dstStage;
    b.dstAccessMask = dstAccess;
    VkDependencyInfo dep{VK_STRUCTURE_TYPE_DEPENDENCY_INFO};
    dep.memoryBarrierCount = 1;
    dep.pMemoryBarriers = &b;
    vkCmdPipelineBarrier2(cmd, &dep);
}

} // namespace

RayBatchTracer::RayBatchTracer(Context& ctx, ShaderCompiler& shaders) : mCtx(ctx) {
    CompiledShader shader = shaders.compile("accel/trace_rays.comp");
    const ShaderReflection& r = shader.reflection;
    if (r.pushConstantSize != sizeof(TraceRaysPush))
        throw InternalError("accel/trace_rays.comp: push constants are " + std::to_string(r.pushConstantSize) +
                            " bytes, TraceRaysPush " + std::to_string(sizeof(TraceRaysPush)));
    // The layouts below are written by hand; the shader must agree (BvhPrimitives is not read by traversal,
    // so reflection does not list it).
    const struct {
        const char* name;
        uint32_t set, binding;
    } expected[] = {{"Rays", 0, 0},         {"Hits", 0, 1},    {"BvhNodes", 1, 0},
                    {"BvhTriangles", 1, 1}, {"BvhRefs", 1, 2}, {"BvhTop", 1, 4}};
    for (const auto& e : expected) {
        const ShaderBinding* b = findBinding(r, e.name);
        if (!b || b->set != e.set || b->binding != e.binding || b->type != VK_DESCRIPTOR_TYPE_STORAGE_BUFFER)
            throw InternalError(std::string("accel/trace_rays.comp: expected storage buffer ") + e.name + " at set " +
                                std::to_string(e.set) + ", binding " + std::to_string(e.binding));
    }
    mLocalSize = r.localSize[0];
    VkDevice device = ctx.device();
    mRaySetLayout = storageLayout(device, 2);
    mBvhSetLayout = storageLayout(device, 5);
    VkDescriptorSetLayout sets[2] = {mRaySetLayout, mBvhSetLayout};
    VkPushConstantRange range{VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof(TraceRaysPush)};
    VkPipelineLayoutCreateInfo pl{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
    pl.setLayoutCount = 2;
    pl.pSetLayouts = sets;
    pl.pushConstantRangeCount = 1;
    pl.pPushConstantRanges = &range;
    VK_CHECK(vkCreatePipelineLayout(device, &pl, nullptr, &mLayout));
    mPipeline = createComputePipeline(ctx, shader, mLayout);
}

RayBatchTracer::~RayBatchTracer() {
    VkDevice device = mCtx.device();
    VkPipeline pipeline = mPipeline;
    VkPipelineLayout layout = mLayout;
    VkDescriptorSetLayout a = mRaySetLayout, b = mBvhSetLayout;
    mCtx.destroyLater([device, pipeline, layout, a, b] {
        vkDestroyPipeline(device, pipeline, nullptr);
        vkDestroyPipelineLayout(device, layout, nullptr);
        vkDestroyDescriptorSetLayout(device, a, nullptr);
        vkDestroyDescriptorSetLayout(device, b, nullptr);
    });
}

RayBatchTracer::Result RayBatchTracer::trace(const GpuBvh& bvh, std::span<const GpuRay> rays, bool anyHit) {
    Result result;
    if (rays.empty()) return result;
    const size_t rayBytes = rays.size_bytes(), hitBytes = rays.size() * sizeof(GpuRayHit);
    GpuBuffer rayBuffer = uploadBuffer(mCtx, rays.data(), rayBytes, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, "rays");
    GpuBuffer hitBuffer(mCtx, hitBytes, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT, false,
                        "hits");
    GpuBuffer readback(mCtx, hitBytes, VK_BUFFER_USAGE_TRANSFER_DST_BIT, true, "hits.readback");

    VkDevice device = mCtx.device();
    VkDescriptorPoolSize size{VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 2};
    VkDescriptorPoolCreateInfo pi{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
    pi.maxSets = 1;
    pi.poolSizeCount = 1;
    pi.pPoolSizes = &size;
    VkDescriptorPool pool;
    VK_CHECK(vkCreateDescriptorPool(device, &pi, nullptr, &pool));
    mCtx.destroyLater([device, pool] { vkDestroyDescriptorPool(device, pool, nullptr); });
    VkDescriptorSetAllocateInfo ai{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
    ai.descriptorPool = pool;
    ai.descriptorSetCount = 1;
    ai.pSetLayouts = &mRaySetLayout;
    VkDescriptorSet set;
    VK_CHECK(vkAllocateDescriptorSets(device, &ai, &set));
    VkDescriptorBufferInfo infos[2] = {{rayBuffer.buffer(), 0, VK_WHOLE_SIZE}, {hitBuffer.buffer(), 0, VK_WHOLE_SIZE}};
    VkWriteDescriptorSet writes[2];
    for (uint32_t i = 0; i < 2; ++i) {
        writes[i] = {VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
        writes[i].dstSet = set;
        writes[i].dstBinding = i;
        writes[i].descriptorCount = 1;
        writes[i].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
        writes[i].pBufferInfo = &infos[i];
    }
    vkUpdateDescriptorSets(device, 2, writes, 0, nullptr);

    // Rows of at most 65535 groups (the guaranteed grid limit), as many rows as needed.
    const uint32_t count = static_cast<uint32_t>(rays.size());
    const uint32_t groups = (count + mLocalSize - 1) / mLocalSize;
    const uint32_t groupsX = std::min(groups, 65535u), groupsY = (groups + groupsX - 1) / groupsX;
    TraceRaysPush push{count, anyHit ? 1u : 0u, groupsX * mLocalSize, 0u};

    // The dispatch in a submission of its own, timed twice: by timestamp queries, and on the host from
    // submit to fence (lavapipe writes timestamps without waiting for a running dispatch, so only the
    // second is its real time; on GPUs the two agree up to the submission overhead).
    GpuProfiler profiler(mCtx, 1);
    const auto start = std::chrono::steady_clock::now();
    mCtx.immediate([&](VkCommandBuffer cmd) {
        profiler.begin(cmd);
        vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, mPipeline);
        VkDescriptorSet sets[2] = {set, bvh.set()};
        vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, mLayout, 0, 2, sets, 0, nullptr);
        vkCmdPushConstants(cmd, mLayout, VK_SHADER_STAGE_COMPUTE_BIT, 0, sizeof push, &push);
        profiler.beginScope(cmd, 0);
        vkCmdDispatch(cmd, groupsX, groupsY, 1);
        profiler.endScope(cmd, 0);
    });
    result.wallMs = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    result.gpuMs = profiler.resolve(1)[0];
    mCtx.immediate([&](VkCommandBuffer cmd) {
        bufferBarrier(cmd, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
                      VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_READ_BIT);
        VkBufferCopy copy{0, 0, hitBytes};
        vkCmdCopyBuffer(cmd, hitBuffer.buffer(), readback.buffer(), 1, &copy);
        bufferBarrier(cmd, VK_PIPELINE_STAGE_2_COPY_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_2_HOST_BIT,
                      VK_ACCESS_2_HOST_READ_BIT);
    });
    result.hits.resize(rays.size());
    std::memcpy(result.hits.data(), readback.mapped(), hitBytes);
    return result;
}

} // namespace vitrine
