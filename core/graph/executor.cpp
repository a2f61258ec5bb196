#include "core/graph/executor.hpp"

#include "core/base/error.hpp"
#include "core/graph/descriptor_pools.hpp"
#include "core/base/log.hpp"
#include "core/gpu/allocator.hpp"
#include "core/gpu/context.hpp"
#include "core/gpu/formats.hpp"
#include "core/gpu/memory_budget.hpp"
#include "core/gpu/pipeline.hpp"
#include "core/gpu/profiler.hpp"
#include "core/gpu/transfer.hpp"
#include "core/graph/lifetimes.hpp"
#include "core/graph/registry.hpp"
#include "core/shader/compiler.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <mutex>
#include <cstring>
#include <exception>
#include <set>
#include <thread>

namespace vitrine {

const DebugPoison& debugPoison() {
    static const DebugPoison poison = [] {
        DebugPoison p;
        const char* v = std::getenv("VITRINE_DEBUG_POISON");
        if (!v || !*v) return p;
        p.enabled = true;
        if (std::string_view(v) == "nan") {
            p.value = std::numeric_limits<float>::quiet_NaN();
        } else {
            char* end = nullptr;
            p.value = std::strtof(v, &end);
            if (end == v || *end)
                throw UserError(std::string("VITRINE_DEBUG_POISON='") + v + "': expected a number or 'nan'");
        }
        if (const char* only = std::getenv("VITRINE_DEBUG_POISON_ONLY")) p.only = only;
        logWarning("VITRINE_DEBUG_POISON: textures that do not survive the frame are cleared to " + std::string(v) +
                " before their first pass" + (p.only.empty() ? "" : " (only names containing '" + p.only + "')"));
        return p;
    }();
    return poison;
}

struct Executor::Pipeline {
    struct Target {
        uint32_t binding;
        VkDescriptorType type;
        std::string port; // empty for the `Uniforms` block
        bool output;
    };
    std::string shader;
    VkPipeline pipeline = VK_NULL_HANDLE;
    VkPipelineLayout layout = VK_NULL_HANDLE;
    VkDescriptorSetLayout setLayout = VK_NULL_HANDLE;
    ShaderReflection reflection;
    std::vector<Target> targets;
    // Pipelines whose sets 1..nodeSets the node binds: created on the first dispatchWithSets() from its layouts.
    uint32_t nodeSets = 0;
    CompiledShader compiled;
    std::vector<VkDescriptorSetLayout> nodeLayouts;
};

namespace {

using Clock = std::chrono::steady_clock;
double msSince(Clock::time_point t) { return std::chrono::duration<double, std::milli>(Clock::now() - t).count(); }

bool descriptorFits(VkDescriptorType type, Usage usage) {
    switch (usage) {
    case Usage::Sampled:
        return type == VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER || type == VK_DESCRIPTOR_TYPE_SAMPLED_IMAGE;
    case Usage::StorageRead:
    case Usage::StorageWrite:
    case Usage::StorageReadWrite: return type == VK_DESCRIPTOR_TYPE_STORAGE_IMAGE;
    default: return false;
    }
}

constexpr VkDeviceSize kUniformRingSize = 4u << 20;

} // namespace

// The ExecuteContext a pass sees while it is recorded.
class PassContext final : public ExecuteContext {
public:
    PassContext(Executor& ex, uint32_t pass, VkCommandBuffer cmd) : mEx(ex), mPassIndex(pass), mCmd(cmd) {}

    Context& gpu() override { return mEx.mCtx; }
    VkCommandBuffer cmd() override { return mCmd; }
    uint32_t frameIndex() const override { return mEx.mFrame; }
    bool stopRequested() const override { return mEx.mStop && mEx.mStop(); }
    const Params& params() const override { return *pass().params; }
    bool hasInput(const std::string& port) const override { return findUse(port, false) != nullptr; }
    bool inputValid(const std::string& port) const override {
        const PassUse* u = findUse(port, false);
        return u && (!u->previous || mEx.mFrame > 0);
    }
    const GpuImage& input(const std::string& port) override { return imageOf(port, false); }
    const GpuImage& output(const std::string& port) override { return imageOf(port, true); }

    void upload(const std::string& port, const Image& pixels, uint32_t layer) override {
        const PassUse* u = findUse(port, true);
        if (!u || u->usage != Usage::TransferDst)
            throw InternalError("node " + pass().id + ": upload to '" + port + "', which is not a TransferDst output");
        mEx.mFrameStaging.push_back(recordUpload(mEx.mCtx, mCmd, imageOf(port, true), pixels, layer));
    }

    PortObject& object(const std::string& port) override {
        for (int output = 0; output < 2; ++output) {
            const PassUse* u = findUse(port, output != 0);
            if (u && mEx.mGraph.resources[u->resource].object) return *mEx.mGraph.resources[u->resource].object;
        }
        throw InternalError("node " + pass().id + " asks for object port '" + port + "', which carries none");
    }
    ShaderCompiler& shaders() override { return mEx.mShaders; }
    void setUniforms(const void* data, uint32_t size) override {
        VkDeviceSize offset = (mEx.mUniformHead + mEx.mUniformAlign - 1) / mEx.mUniformAlign * mEx.mUniformAlign;
        if (offset + size > kUniformRingSize)
            throw InternalError("node " + pass().id + ": uniform data of this frame exceeds " + std::to_string(kUniformRingSize) + " bytes");
        std::memcpy(static_cast<uint8_t*>(mEx.mUniformRing.mapped()) + offset, data, size);
        mEx.mUniformHead = offset + size;
        mUniformOffset = offset;
        mUniformSize = size;
    }

    void dispatch(PipelineId id, const void* push, uint32_t pushSize, uint32_t width, uint32_t height,
                  uint32_t depth) override {
        record(id, push, pushSize, width, height, depth, {}, {});
    }

    void computeBarrier() override {
        VkMemoryBarrier2 b{VK_STRUCTURE_TYPE_MEMORY_BARRIER_2};
        b.srcStageMask = b.dstStageMask = VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT;
        b.srcAccessMask = VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT;
        b.dstAccessMask = VK_ACCESS_2_SHADER_STORAGE_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT;
        VkDependencyInfo dep{VK_STRUCTURE_TYPE_DEPENDENCY_INFO};
        dep.memoryBarrierCount = 1;
        dep.pMemoryBarriers = &b;
        vkCmdPipelineBarrier2(mCmd, &dep);
    }

    void changeUsage(const std::string& port, Usage usage) override {
        const PassUse* u = findUse(port, true);
        if (!u) throw InternalError("node " + pass().id + ": changeUsage of '" + port + "', which is not its output");
        uint32_t phys = mEx.physicalOf(u->resource, u->previous);
        Executor::Physical& p = mEx.mPhysical[phys];
        if (auto b = requireAccess(p.state, phys, accessOf(usage, pass().schema->pass))) {
            VkImageMemoryBarrier2 vb = toVulkan(*b, p.image.image(), aspectOf(p.image.desc().format));
            VkDependencyInfo dep{VK_STRUCTURE_TYPE_DEPENDENCY_INFO};
            dep.imageMemoryBarrierCount = 1;
            dep.pImageMemoryBarriers = &vb;
            vkCmdPipelineBarrier2(mCmd, &dep);
        }
    }

    void splitSubmission() override {
        VK_CHECK(vkEndCommandBuffer(mCmd));
        mEx.mCtx.waitSerial(mEx.mCtx.submit(mCmd));
        mEx.mDescriptorPools->reset(); // the sets bound so far were only in the work just finished
        VK_CHECK(vkResetCommandBuffer(mCmd, 0));
        VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
        begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
        VK_CHECK(vkBeginCommandBuffer(mCmd, &begin));
    }

    void dispatchWithSets(PipelineId id, const void* push, uint32_t pushSize, uint32_t width, uint32_t height,
                          std::span<const VkDescriptorSetLayout> layouts, std::span<const VkDescriptorSet> sets) override {
        record(id, push, pushSize, width, height, 1, layouts, sets);
    }

private:
    void record(PipelineId id, const void* push, uint32_t pushSize, uint32_t width, uint32_t height, uint32_t depth,
                std::span<const VkDescriptorSetLayout> layouts, std::span<const VkDescriptorSet> sets) {
        auto& pipelines = mEx.mPipelines[mPassIndex];
        if (id >= pipelines.size()) throw InternalError("node " + pass().id + ": unknown pipeline " + std::to_string(id));
        Executor::Pipeline& p = *pipelines[id];
        if (pushSize != p.reflection.pushConstantSize)
            throw InternalError("node " + pass().id + ": pushes " + std::to_string(pushSize) + " bytes but " + p.shader +
                                " declares a push-constant block of " + std::to_string(p.reflection.pushConstantSize));
        if (layouts.size() != p.nodeSets || sets.size() != p.nodeSets)
            throw InternalError("node " + pass().id + ": " + p.shader + " takes " + std::to_string(p.nodeSets) +
                                " node sets, the dispatch binds " + std::to_string(sets.size()));
        if (p.nodeSets) mEx.createNodeSetPipeline(p, layouts, pass().id);
        VkDescriptorSet set = VK_NULL_HANDLE;
        if (p.setLayout) {
            std::vector<VkDescriptorType> types;
            for (const auto& t : p.targets) types.push_back(t.type);
            set = mEx.mDescriptorPools->allocate(p.setLayout, DescriptorPools::countsOf(types));
            std::vector<VkDescriptorImageInfo> images(p.targets.size());
            VkDescriptorBufferInfo uniforms{};
            std::vector<VkWriteDescriptorSet> writes;
            for (size_t i = 0; i < p.targets.size(); ++i) {
                const auto& t = p.targets[i];
                if (t.type == VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER) {
                    if (!mUniformSize)
                        throw InternalError("node " + pass().id + ": " + p.shader + " has a Uniforms block but setUniforms() was not called");
                    uniforms = {mEx.mUniformRing.buffer(), mUniformOffset, mUniformSize};
                    VkWriteDescriptorSet w{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
                    w.dstSet = set;
                    w.dstBinding = t.binding;
                    w.descriptorCount = 1;
                    w.descriptorType = t.type;
                    w.pBufferInfo = &uniforms;
                    writes.push_back(w);
                    continue;
                }
                const PassUse* u = findUse(t.port, t.output);
                if (u) {
                    const Executor::Physical& ph = mEx.mPhysical[mEx.physicalOf(u->resource, u->previous)];
                    images[i] = {mEx.samplerFor(ph.image.desc().format), ph.image.view(), ph.state.layout};
                } else {
                    images[i] = {mEx.mSampler, mEx.mDummy.view(), VK_IMAGE_LAYOUT_GENERAL};
                }
                VkWriteDescriptorSet w{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
                w.dstSet = set;
                w.dstBinding = t.binding;
                w.descriptorCount = 1;
                w.descriptorType = t.type;
                w.pImageInfo = &images[i];
                writes.push_back(w);
            }
            vkUpdateDescriptorSets(mEx.mCtx.device(), static_cast<uint32_t>(writes.size()), writes.data(), 0, nullptr);
        }
        vkCmdBindPipeline(mCmd, VK_PIPELINE_BIND_POINT_COMPUTE, p.pipeline);
        if (set) vkCmdBindDescriptorSets(mCmd, VK_PIPELINE_BIND_POINT_COMPUTE, p.layout, 0, 1, &set, 0, nullptr);
        if (!sets.empty())
            vkCmdBindDescriptorSets(mCmd, VK_PIPELINE_BIND_POINT_COMPUTE, p.layout, 1, static_cast<uint32_t>(sets.size()),
                                    sets.data(), 0, nullptr);
        if (pushSize) vkCmdPushConstants(mCmd, p.layout, VK_SHADER_STAGE_COMPUTE_BIT, 0, pushSize, push);
        const uint32_t* ls = p.reflection.localSize;
        vkCmdDispatch(mCmd, (width + ls[0] - 1) / ls[0], (height + ls[1] - 1) / ls[1], (depth + ls[2] - 1) / ls[2]);
    }

    const CompiledPass& pass() const { return mEx.mGraph.passes[mPassIndex]; }
    const PassUse* findUse(const std::string& port, bool output) const {
        for (const auto& u : pass().uses)
            if (u.output == output && u.port == port) return &u;
        return nullptr;
    }
    const GpuImage& imageOf(const std::string& port, bool output) {
        const PassUse* u = findUse(port, output);
        if (!u)
            throw InternalError("node " + pass().id + " asks for " + (output ? "output" : "unconnected input") + " '" +
                                port + "'");
        return mEx.mPhysical[mEx.physicalOf(u->resource, u->previous)].image;
    }

    Executor& mEx;
    uint32_t mPassIndex;
    VkCommandBuffer mCmd;
    VkDeviceSize mUniformOffset = 0;
    uint32_t mUniformSize = 0;
};

Executor::Executor(Context& ctx, CompiledGraph& graph, ShaderCompiler& shaders)
    : mCtx(ctx), mGraph(graph), mShaders(shaders) {
    try {
        create(shaders);
    } catch (...) {
        destroy();
        throw;
    }
}

void Executor::create(ShaderCompiler& shaders) {
    Context& ctx = mCtx;
    CompiledGraph& graph = mGraph;
    VkSamplerCreateInfo si{VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO};
    si.magFilter = si.minFilter = VK_FILTER_LINEAR;
    si.mipmapMode = VK_SAMPLER_MIPMAP_MODE_LINEAR;
    si.addressModeU = si.addressModeV = si.addressModeW = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE;
    si.maxLod = VK_LOD_CLAMP_NONE;
    VK_CHECK(vkCreateSampler(ctx.device(), &si, nullptr, &mSampler));
    // Formats without linear filtering (depth on most devices) are bound with a nearest sampler.
    si.magFilter = si.minFilter = VK_FILTER_NEAREST;
    si.mipmapMode = VK_SAMPLER_MIPMAP_MODE_NEAREST;
    VK_CHECK(vkCreateSampler(ctx.device(), &si, nullptr, &mNearestSampler));

    mDescriptorPools = std::make_unique<DescriptorPools>(ctx.device());

    ImageDesc dummy;
    dummy.format = VK_FORMAT_R16G16B16A16_SFLOAT;
    dummy.usage = VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_STORAGE_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT;
    mDummy = GpuImage(ctx, dummy, "graph.dummy");
    ctx.immediate([&](VkCommandBuffer cmd) {
        ImageSyncState s;
        auto b = requireAccess(s, 0, accessOf(Usage::TransferDst, PassKind::Transfer));
        VkImageMemoryBarrier2 vb = toVulkan(*b, mDummy.image(), VK_IMAGE_ASPECT_COLOR_BIT);
        VkDependencyInfo dep{VK_STRUCTURE_TYPE_DEPENDENCY_INFO};
        dep.imageMemoryBarrierCount = 1;
        dep.pImageMemoryBarriers = &vb;
        vkCmdPipelineBarrier2(cmd, &dep);
        VkClearColorValue zero{};
        VkImageSubresourceRange range{VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
        vkCmdClearColorImage(cmd, mDummy.image(), VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, &zero, 1, &range);
        vb = toVulkan({0, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_IMAGE_LAYOUT_GENERAL, VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT,
                       VK_ACCESS_2_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, VK_ACCESS_2_MEMORY_READ_BIT},
                      mDummy.image(), VK_IMAGE_ASPECT_COLOR_BIT);
        vkCmdPipelineBarrier2(cmd, &dep);
    });

    VkPhysicalDeviceProperties props;
    vkGetPhysicalDeviceProperties(ctx.physicalDevice(), &props);
    mUniformAlign = std::max<VkDeviceSize>(props.limits.minUniformBufferOffsetAlignment, 16);
    mUniformRing = GpuBuffer(ctx, kUniformRingSize, VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT, true, "graph.uniforms");

    createImages();
    createPipelines(shaders);
    mProfiler = std::make_unique<GpuProfiler>(ctx, static_cast<uint32_t>(graph.passes.size()));
}

Executor::~Executor() { destroy(); }

void Executor::destroy() {
    mCtx.waitIdle();
    for (auto& pass : mGraph.passes) pass.node->releaseGpu();
    for (auto& r : mGraph.resources)
        if (r.object) r.object->releaseGpu();
    mPhysical.clear();
    mDummy = GpuImage();
    mUniformRing = GpuBuffer();
    mProfiler.reset();
    VkDevice device = mCtx.device();
    std::vector<std::unique_ptr<Pipeline>> all;
    for (auto& list : mPipelines)
        for (auto& p : list) all.push_back(std::move(p));
    VkSampler sampler = mSampler, nearest = mNearestSampler;
    std::shared_ptr<DescriptorPools> pools(std::move(mDescriptorPools));
    VkDeviceMemory heap = mTransientHeap;
    auto shared = std::make_shared<std::vector<std::unique_ptr<Pipeline>>>(std::move(all));
    mCtx.destroyLater([device, shared, sampler, nearest, pools, heap]() mutable {
        for (auto& p : *shared) {
            if (p->pipeline) vkDestroyPipeline(device, p->pipeline, nullptr);
            if (p->layout) vkDestroyPipelineLayout(device, p->layout, nullptr);
            if (p->setLayout) vkDestroyDescriptorSetLayout(device, p->setLayout, nullptr);
        }
        if (sampler) vkDestroySampler(device, sampler, nullptr);
        if (nearest) vkDestroySampler(device, nearest, nullptr);
        pools.reset();
        if (heap) vkFreeMemory(device, heap, nullptr);
    });
    mSampler = VK_NULL_HANDLE;
    mNearestSampler = VK_NULL_HANDLE;
    mTransientHeap = VK_NULL_HANDLE;
    mPipelines.clear();
    mCtx.collectGarbage();
}

VkSampler Executor::samplerFor(VkFormat format) {
    auto it = mLinearFilterable.find(format);
    if (it == mLinearFilterable.end()) {
        VkFormatProperties props;
        vkGetPhysicalDeviceFormatProperties(mCtx.physicalDevice(), format, &props);
        it = mLinearFilterable.emplace(format, (props.optimalTilingFeatures & VK_FORMAT_FEATURE_SAMPLED_IMAGE_FILTER_LINEAR_BIT) != 0).first;
    }
    return it->second ? mSampler : mNearestSampler;
}

uint32_t Executor::physicalOf(uint32_t resource, bool previous) const {
    const GraphResource& r = mGraph.resources[resource];
    if (!r.history) return mResourcePhysical[resource][0];
    return mResourcePhysical[resource][(mFrame + (previous ? 1 : 0)) % 2];
}

void Executor::createImages() {
    std::vector<AliasRequest> requests;
    std::vector<uint32_t> transient;
    uint32_t typeBits = ~0u;
    for (uint32_t i = 0; i < mGraph.resources.size(); ++i) {
        const GraphResource& r = mGraph.resources[i];
        if (!r.transient()) continue;
        VkMemoryRequirements req = GpuImage::requirements(mCtx, r.desc);
        requests.push_back({req.size, req.alignment, r.firstPass, r.lastPass});
        transient.push_back(i);
        typeBits &= req.memoryTypeBits;
    }
    AliasPlan plan = planAliasing(requests);
    mMemory.transientAliased = plan.heapSize;
    mMemory.transientUnaliased = plan.unaliasedSize;
    if (!transient.empty() && typeBits == 0)
        throw InternalError("transient textures share no memory type; cannot alias them");

    // Everything the textures will take, checked against the device before the first allocation: a graph too large
    // for the device is the user's to change (frame size, outputs), not a driver failure halfway through.
    GraphMemoryPlan memoryPlan;
    const uint32_t transientType =
        transient.empty() ? 0 : mCtx.allocator().findMemoryType(typeBits, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
    if (!transient.empty())
        memoryPlan.allocations.push_back(
            {"the transient heap (" + std::to_string(transient.size()) + " textures, aliased)", transientType,
             plan.heapSize});
    for (const GraphResource& r : mGraph.resources) {
        if (r.transient() || !r.isTexture()) continue;
        VkMemoryRequirements req = GpuImage::requirements(mCtx, r.desc);
        uint32_t type = mCtx.allocator().findMemoryType(req.memoryTypeBits, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
        for (int c = 0; c < (r.history ? 2 : 1); ++c)
            memoryPlan.allocations.push_back(
                {"texture " + r.name + (r.history ? " (history, 2 copies)" : ""), type, req.size});
    }
    const std::string tooLarge = checkMemoryBudget(memoryPlan, queryMemoryBudget(mCtx.physicalDevice()));
    if (!tooLarge.empty())
        throw UserError(mGraph.desc.file + ": frame " + std::to_string(mGraph.desc.frame.width) + "x" +
                        std::to_string(mGraph.desc.frame.height) + ": " + tooLarge +
                        "; use a smaller frame.width/frame.height or fewer outputs (VITRINE_MEMORY_BUDGET=off skips "
                        "this check, for devices that can use more than they report)");

    if (!transient.empty()) {
        VkMemoryAllocateInfo info{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
        info.allocationSize = plan.heapSize;
        info.memoryTypeIndex = transientType;
        VK_CHECK(vkAllocateMemory(mCtx.device(), &info, nullptr, &mTransientHeap));
        if (debugPoisonMemoryByte() >= 0 &&
            (mCtx.allocator().properties().memoryTypes[transientType].propertyFlags & VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT)) {
            void* mapped = nullptr;
            VK_CHECK(vkMapMemory(mCtx.device(), mTransientHeap, 0, VK_WHOLE_SIZE, 0, &mapped));
            Allocation whole;
            whole.memory = mTransientHeap;
            whole.size = plan.heapSize;
            whole.mapped = mapped;
            debugPoisonAllocation(whole, "transient heap");
            vkUnmapMemory(mCtx.device(), mTransientHeap);
        }
    }

    mResourcePhysical.assign(mGraph.resources.size(), {UINT32_MAX, UINT32_MAX});
    for (size_t k = 0; k < transient.size(); ++k) {
        const GraphResource& r = mGraph.resources[transient[k]];
        mPhysical.push_back({GpuImage(mCtx, r.desc, r.name, mTransientHeap, plan.offsets[k]), {}});
        mResourcePhysical[transient[k]] = {static_cast<uint32_t>(mPhysical.size() - 1), UINT32_MAX};
    }
    for (uint32_t i = 0; i < mGraph.resources.size(); ++i) {
        const GraphResource& r = mGraph.resources[i];
        if (r.transient() || !r.isTexture()) continue;
        int copies = r.history ? 2 : 1;
        for (int c = 0; c < copies; ++c) {
            mPhysical.push_back({GpuImage(mCtx, r.desc, r.name + (r.history ? (c ? "[1]" : "[0]") : "")), {}});
            mResourcePhysical[i][c] = static_cast<uint32_t>(mPhysical.size() - 1);
            mMemory.persistent += GpuImage::requirements(mCtx, r.desc).size;
        }
    }
}

void Executor::createPipelines(ShaderCompiler& shaders) {
    auto start = Clock::now();
    VkDevice device = mCtx.device();
    mPipelines.resize(mGraph.passes.size());
    struct PipelineJob {
        Pipeline* pipeline;
        CompiledShader shader;
        std::string name;
    };
    std::vector<PipelineJob> jobs;
    for (size_t pi = 0; pi < mGraph.passes.size(); ++pi) {
        const CompiledPass& pass = mGraph.passes[pi];
        for (const auto& request : pass.pipelines) {
            CompiledShader shader =
                request.source.empty()
                    ? shaders.compile(request.shader, request.defines)
                    : shaders.compileSource(request.shader, request.source, VK_SHADER_STAGE_COMPUTE_BIT, request.defines);
            mPipelines[pi].push_back(std::make_unique<Pipeline>());
            Pipeline* p = mPipelines[pi].back().get();
            p->shader = request.shader;
            p->reflection = shader.reflection;
            std::vector<VkDescriptorSetLayoutBinding> bindings;
            for (const auto& b : shader.reflection.bindings) {
                std::string where = "shader " + request.shader + " (node " + pass.id + ", " + pass.schema->type + ")";
                if (b.set != 0 && b.set <= request.nodeSets) continue; // bound by the node
                if (b.set != 0)
                    throw InternalError(where + ": binding '" + b.name + "' is in set " + std::to_string(b.set) +
                                        "; nodes use set 0 (and sets 1.." + std::to_string(request.nodeSets) + " of their own)");
                if (b.type == VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER) {
                    if (b.name != "Uniforms")
                        throw InternalError(where + ": uniform block '" + b.name + "' must be named Uniforms (filled by setUniforms())");
                    bindings.push_back({b.binding, b.type, 1, VK_SHADER_STAGE_COMPUTE_BIT, nullptr});
                    p->targets.push_back({b.binding, b.type, {}, false});
                    continue;
                }
                bool output = b.name.rfind("out_", 0) == 0;
                bool input = b.name.rfind("in_", 0) == 0;
                std::string port = b.name.substr(output ? 4 : 3);
                if (!input && !output)
                    throw InternalError(where + ": binding '" + b.name + "' must be named in_<input> or out_<output>");
                Usage usage;
                if (output) {
                    const OutputPort* op = pass.schema->findOutput(port);
                    if (!op) throw InternalError(where + ": binds '" + b.name + "' but " + pass.schema->type + " has no output '" + port + "'");
                    usage = op->usage;
                } else {
                    const InputPort* ip = pass.schema->findInput(port);
                    if (!ip) throw InternalError(where + ": binds '" + b.name + "' but " + pass.schema->type + " has no input '" + port + "'");
                    usage = ip->usage;
                }
                if (!descriptorFits(b.type, usage))
                    throw InternalError(where + ": binding '" + b.name + "' has a descriptor type that does not match the port's declared usage");
                bindings.push_back({b.binding, b.type, 1, VK_SHADER_STAGE_COMPUTE_BIT, nullptr});
                p->targets.push_back({b.binding, b.type, port, output});
            }
            if (!bindings.empty() || request.nodeSets) {
                VkDescriptorSetLayoutCreateInfo li{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
                li.bindingCount = static_cast<uint32_t>(bindings.size());
                li.pBindings = bindings.data();
                VK_CHECK(vkCreateDescriptorSetLayout(device, &li, nullptr, &p->setLayout));
            }
            if (request.nodeSets) {
                p->nodeSets = request.nodeSets;
                p->compiled = std::move(shader);
                continue;
            }
            VkPushConstantRange range{VK_SHADER_STAGE_COMPUTE_BIT, 0, shader.reflection.pushConstantSize};
            VkPipelineLayoutCreateInfo pl{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
            pl.setLayoutCount = p->setLayout ? 1 : 0;
            pl.pSetLayouts = &p->setLayout;
            pl.pushConstantRangeCount = range.size ? 1 : 0;
            pl.pPushConstantRanges = &range;
            VK_CHECK(vkCreatePipelineLayout(device, &pl, nullptr, &p->layout));

            jobs.push_back({p, std::move(shader), pass.id + ":" + request.shader});
        }
    }
    // The pipelines themselves on every core: a driver that compiles at creation (lavapipe's LLVM, or a GPU driver
    // without a cache hit) spends nearly all of the start there, and vkCreateComputePipelines may be called from
    // several threads at once (the pipeline cache is internally synchronised). (It was serial for a while on the
    // suspicion of raising the rate of the SSR garbage-pixel failure; that was a read of the colour pyramid's
    // unwritten padding, which any change of the process's allocation pattern could expose; golden.poison.)
    std::atomic<size_t> next{0};
    std::exception_ptr failure;
    std::mutex failureMutex;
    auto work = [&] {
        for (size_t i; (i = next.fetch_add(1)) < jobs.size();) {
            try {
                jobs[i].pipeline->pipeline = createComputePipeline(mCtx, jobs[i].shader, jobs[i].pipeline->layout);
            } catch (...) {
                std::lock_guard lock(failureMutex);
                if (!failure) failure = std::current_exception();
            }
        }
    };
    const size_t threads = std::min<size_t>(jobs.size(), std::max(1u, std::thread::hardware_concurrency()));
    std::vector<std::thread> pool;
    for (size_t t = 1; t < threads; ++t) pool.emplace_back(work);
    work();
    for (std::thread& t : pool) t.join();
    if (failure) std::rethrow_exception(failure);
    for (const PipelineJob& job : jobs)
        mCtx.setName(reinterpret_cast<uint64_t>(job.pipeline->pipeline), VK_OBJECT_TYPE_PIPELINE, job.name);
    mPipelineMs = msSince(start);
}

void Executor::createNodeSetPipeline(Pipeline& p, std::span<const VkDescriptorSetLayout> layouts, const std::string& passId) {
    if (p.pipeline) {
        if (!std::equal(layouts.begin(), layouts.end(), p.nodeLayouts.begin(), p.nodeLayouts.end()))
            throw InternalError("node " + passId + ": " + p.shader + " was created with other descriptor set layouts");
        return;
    }
    VkDevice device = mCtx.device();
    std::vector<VkDescriptorSetLayout> all = {p.setLayout};
    all.insert(all.end(), layouts.begin(), layouts.end());
    VkPushConstantRange range{VK_SHADER_STAGE_COMPUTE_BIT, 0, p.reflection.pushConstantSize};
    VkPipelineLayoutCreateInfo pl{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
    pl.setLayoutCount = static_cast<uint32_t>(all.size());
    pl.pSetLayouts = all.data();
    pl.pushConstantRangeCount = range.size ? 1 : 0;
    pl.pPushConstantRanges = &range;
    VK_CHECK(vkCreatePipelineLayout(device, &pl, nullptr, &p.layout));
    p.pipeline = createComputePipeline(mCtx, p.compiled, p.layout);
    p.nodeLayouts.assign(layouts.begin(), layouts.end());
    mCtx.setName(reinterpret_cast<uint64_t>(p.pipeline), VK_OBJECT_TYPE_PIPELINE, passId + ":" + p.shader);
}

void Executor::recordFrame(VkCommandBuffer cmd) {
    mFrameStaging.clear();
    mUniformHead = 0;
    mProfiler->begin(cmd);
    std::vector<VkImageMemoryBarrier2> barriers;
    auto flush = [&] {
        if (barriers.empty()) return;
        VkDependencyInfo dep{VK_STRUCTURE_TYPE_DEPENDENCY_INFO};
        dep.imageMemoryBarrierCount = static_cast<uint32_t>(barriers.size());
        dep.pImageMemoryBarriers = barriers.data();
        vkCmdPipelineBarrier2(cmd, &dep);
        barriers.clear();
    };
    auto require = [&](uint32_t phys, const AccessInfo& access) {
        Physical& p = mPhysical[phys];
        if (auto b = requireAccess(p.state, phys, access))
            barriers.push_back(toVulkan(*b, p.image.image(), aspectOf(p.image.desc().format)));
    };

    for (uint32_t i = 0; i < mGraph.resources.size(); ++i) {
        const GraphResource& r = mGraph.resources[i];
        if (r.isTexture() && !r.persistent && !r.history) mPhysical[mResourcePhysical[i][0]].state = ImageSyncState::discarded();
    }
    if (mFrame == 0) {
        // History starts as zeros so a first-frame @prev read is defined (inputValid() says false).
        std::vector<uint32_t> cleared;
        for (uint32_t i = 0; i < mGraph.resources.size(); ++i)
            if (mGraph.resources[i].history)
                for (uint32_t phys : mResourcePhysical[i]) {
                    require(phys, accessOf(Usage::TransferDst, PassKind::Transfer));
                    cleared.push_back(phys);
                }
        flush();
        for (uint32_t phys : cleared) {
            VkClearColorValue zero{};
            VkImageSubresourceRange range{VK_IMAGE_ASPECT_COLOR_BIT, 0, VK_REMAINING_MIP_LEVELS, 0, VK_REMAINING_ARRAY_LAYERS};
            vkCmdClearColorImage(cmd, mPhysical[phys].image.image(), VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, &zero, 1, &range);
        }
    }

    const DebugPoison& poison = debugPoison();
    for (uint32_t pi = 0; pi < mGraph.passes.size(); ++pi) {
        const CompiledPass& pass = mGraph.passes[pi];
        if (poison.enabled) {
            std::vector<uint32_t> poisoned;
            for (uint32_t i = 0; i < mGraph.resources.size(); ++i) {
                const GraphResource& r = mGraph.resources[i];
                if (!r.isTexture() || r.persistent || r.history || r.firstPass != pi) continue;
                if (!poison.only.empty() && r.name.find(poison.only) == std::string::npos) continue;
                require(mResourcePhysical[i][0], accessOf(Usage::TransferDst, PassKind::Transfer));
                poisoned.push_back(mResourcePhysical[i][0]);
            }
            flush();
            for (uint32_t phys : poisoned) {
                const GpuImage& image = mPhysical[phys].image;
                VkImageSubresourceRange range{aspectOf(image.desc().format), 0, VK_REMAINING_MIP_LEVELS, 0,
                                              VK_REMAINING_ARRAY_LAYERS};
                if (formatInfo(image.desc().format).depth) {
                    VkClearDepthStencilValue depth{std::isnan(poison.value) ? 0.5f : std::clamp(poison.value, 0.0f, 1.0f), 0};
                    vkCmdClearDepthStencilImage(cmd, image.image(), VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, &depth, 1, &range);
                } else {
                    VkClearColorValue value;
                    if (image.desc().format == VK_FORMAT_R32_UINT) {
                        uint32_t bits;
                        std::memcpy(&bits, &poison.value, 4);
                        for (auto& c : value.uint32) c = bits;
                    } else {
                        for (auto& c : value.float32) c = poison.value;
                    }
                    vkCmdClearColorImage(cmd, image.image(), VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, &value, 1, &range);
                }
            }
        }
        for (const auto& u : pass.uses)
            if (mGraph.resources[u.resource].isTexture())
                require(physicalOf(u.resource, u.previous), accessOf(u.usage, pass.schema->pass));
        flush();
        mProfiler->beginScope(cmd, pi);
        PassContext ctx(*this, pi, cmd);
        ScopedProgressNode working(pass.id);
        const auto start = Clock::now();
        const double waitedBefore = mCtx.waitMs();
        pass.node->execute(ctx);
        if (mPassCpuMs) (*mPassCpuMs)[pi] = msSince(start) - (mCtx.waitMs() - waitedBefore);
        mProfiler->endScope(cmd, pi);
    }
}

uint32_t Executor::run(const RunOptions& options) {
    const FrameSettings& fs = mGraph.desc.frame;
    const uint32_t frames = options.frames ? options.frames : fs.frames;
    std::set<uint32_t> write(options.write.begin(), options.write.end());
    if (options.write.empty()) {
        for (uint32_t w : fs.write) write.insert(std::min(w, frames - 1));
    }
    std::unique_ptr<Progress> progress;
    if (options.progress) progress = std::make_unique<Progress>("rendering", frames);
    mStop = options.stop;
    struct ClearStop {
        std::function<bool()>& stop;
        ~ClearStop() { stop = nullptr; }
    } clearStop{mStop};
    VkCommandBuffer cmd = mCtx.allocateCommandBuffer();
    for (mFrame = 0; mFrame < frames; ++mFrame) {
        auto recordStart = Clock::now();
        VK_CHECK(vkResetCommandBuffer(cmd, 0));
        VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
        begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
        VK_CHECK(vkBeginCommandBuffer(cmd, &begin));
        mDescriptorPools->reset();
        FrameTiming timing;
        timing.passCpuMs.assign(mGraph.passes.size(), 0.0);
        const uint64_t waitsBefore = mCtx.waitCount();
        const double waitedBefore = mCtx.waitMs();
        mPassCpuMs = &timing.passCpuMs;
        recordFrame(cmd);
        mPassCpuMs = nullptr;
        VK_CHECK(vkEndCommandBuffer(cmd));
        timing.cpuWaitMs = mCtx.waitMs() - waitedBefore;
        timing.inFrameWaits = static_cast<uint32_t>(mCtx.waitCount() - waitsBefore);
        timing.cpuRecordMs = msSince(recordStart) - timing.cpuWaitMs;
        auto gpuStart = Clock::now();
        mCtx.waitSerial(mCtx.submit(cmd));
        timing.frameMs = msSince(gpuStart);
        timing.passGpuMs = mProfiler->resolve(static_cast<uint32_t>(mGraph.passes.size()));
        mTimings.push_back(std::move(timing));
        if (write.count(mFrame) && options.onOutput) {
            for (const auto& [name, resource] : mGraph.outputs) {
                Physical& p = mPhysical[physicalOf(resource, false)];
                options.onOutput(mFrame, name, readImage(mCtx, p.image, p.state.layout));
            }
        }
        if (progress) progress->advance();
        if (options.stop && options.stop() && mFrame + 1 < frames) {
            mCtx.freeCommandBuffer(cmd);
            return mFrame + 1; // mFrame stays the last frame run, as after a full run
        }
    }
    mFrame = frames - 1;
    mCtx.freeCommandBuffer(cmd);
    return frames;
}

const GpuImage& Executor::image(const std::string& resource) const {
    int r = mGraph.findResource(resource);
    if (r < 0) throw UserError("no resource '" + resource + "' in the graph");
    return mPhysical[physicalOf(static_cast<uint32_t>(r), false)].image;
}

Image Executor::read(const std::string& resource, uint32_t mip, uint32_t layer) {
    int r = mGraph.findResource(resource);
    if (r < 0) throw UserError("no resource '" + resource + "' in the graph");
    if (mGraph.resources[r].transient())
        throw UserError("resource '" + resource + "' is transient (its memory is reused within the frame); make it a graph output to read it");
    Physical& p = mPhysical[physicalOf(static_cast<uint32_t>(r), false)];
    if (mip >= p.image.desc().mipLevels || layer >= p.image.desc().layers)
        throw UserError("resource '" + resource + "' has no mip " + std::to_string(mip) + " / layer " + std::to_string(layer));
    return readImage(mCtx, p.image, p.state.layout, mip, layer);
}

} // namespace vitrine
