#pragma once

#include "core/graph/barriers.hpp"
#include "core/graph/compiler.hpp"
#include "core/graph/descriptor_pools.hpp"
#include "core/image/image.hpp"

#include <functional>
#include <map>
#include <memory>
#include <span>
#include <vector>

namespace vitrine {

// Debugging reads of memory no pass wrote: with VITRINE_DEBUG_POISON=<float> (or "nan"), every texture whose
// contents do not survive the frame is cleared to that value right before its first pass each frame, so a pass that
// reads texels nobody wrote sees the poison instead of whatever the memory last held. VITRINE_DEBUG_POISON_ONLY=<text>
// limits it to resources whose name contains <text>. Off by default (the clears cost bandwidth).
struct DebugPoison {
    bool enabled = false;
    float value = 0.0f;
    std::string only;
};
const DebugPoison& debugPoison();

class Context;
class GpuProfiler;
class ShaderCompiler;

struct FrameTiming {
    std::vector<double> passGpuMs; // per pass, from timestamp queries
    std::vector<double> passCpuMs; // per pass, the CPU time of its execute() (less its waits)
    double cpuRecordMs = 0.0;      // recording the command buffer, less the waits below
    double cpuWaitMs = 0.0;        // waiting for the GPU while recording (a node's splitSubmission, immediate, ...)
    uint32_t inFrameWaits = 0;     // how many such waits (fence waits inside the frame's recording)
    double frameMs = 0.0;          // submit to completion, wall clock
};

struct MemoryStats {
    uint64_t transientAliased = 0;   // the one heap all transient textures share
    uint64_t transientUnaliased = 0; // what they would take with one allocation each
    uint64_t persistent = 0;         // history, persistent and extracted textures
};

struct RunOptions {
    uint32_t frames = 0;              // 0: the graph's frame.frames
    std::vector<uint32_t> write;      // empty: the graph's frame.write
    bool progress = true;
    // Called for every graph output of every written frame, after the frame completed.
    std::function<void(uint32_t frame, const std::string& output, const Image& image)> onOutput;
    // Asked after every frame (once its outputs went to onOutput): true ends the run at that frame boundary.
    // `vitrine run` stops there on Ctrl-C / SIGTERM.
    std::function<bool()> stop;
};

// Phase 7: turns a CompiledGraph into Vulkan objects (physical images, the aliased transient
// heap, pipelines from reflected SPIR-V) and runs frames: barriers from the tracked state of
// each image, one timestamp scope per pass, read-back of the outputs of chosen frames.
class Executor {
public:
    Executor(Context& ctx, CompiledGraph& graph, ShaderCompiler& shaders);
    ~Executor();
    Executor(const Executor&) = delete;
    Executor& operator=(const Executor&) = delete;

    // Runs the frames and returns how many completed (fewer than asked when options.stop ended the run).
    uint32_t run(const RunOptions& options = {});

    const std::vector<FrameTiming>& timings() const { return mTimings; }
    const MemoryStats& memory() const { return mMemory; }
    double pipelineMs() const { return mPipelineMs; }
    // The image a resource had in the last frame run (for tests and debugging).
    const GpuImage& image(const std::string& resource) const;
    // One mip / layer of a resource that is not transient, as it was after the last frame (tests read every face of a
    // cube-map array this way).
    Image read(const std::string& resource, uint32_t mip = 0, uint32_t layer = 0);

    struct Pipeline;
    struct Physical {
        GpuImage image;
        ImageSyncState state;
    };

private:
    friend class PassContext;
    void create(ShaderCompiler& shaders);
    void destroy();
    void createImages();
    void createPipelines(ShaderCompiler& shaders);
    void createNodeSetPipeline(Pipeline& p, std::span<const VkDescriptorSetLayout> layouts, const std::string& passId);
    uint32_t physicalOf(uint32_t resource, bool previous) const;
    void recordFrame(VkCommandBuffer cmd);

    Context& mCtx;
    CompiledGraph& mGraph;
    std::vector<Physical> mPhysical;
    std::vector<std::array<uint32_t, 2>> mResourcePhysical; // history resources use both
    VkDeviceMemory mTransientHeap = VK_NULL_HANDLE;
    std::vector<std::vector<std::unique_ptr<Pipeline>>> mPipelines; // per pass
    VkSampler samplerFor(VkFormat format);
    VkSampler mSampler = VK_NULL_HANDLE;
    VkSampler mNearestSampler = VK_NULL_HANDLE;
    std::map<VkFormat, bool> mLinearFilterable;
    std::unique_ptr<DescriptorPools> mDescriptorPools; // the per-dispatch sets, reset every frame and submission
    GpuImage mDummy; // bound to unconnected optional inputs
    std::unique_ptr<GpuProfiler> mProfiler;
    std::vector<FrameTiming> mTimings;
    std::vector<double>* mPassCpuMs = nullptr; // the frame being recorded's FrameTiming::passCpuMs
    MemoryStats mMemory;
    double mPipelineMs = 0.0;
    uint32_t mFrame = 0;
    std::function<bool()> mStop;          // RunOptions::stop of the run in progress (ExecuteContext::stopRequested)
    std::vector<GpuBuffer> mFrameStaging; // uploads recorded this frame
    ShaderCompiler& mShaders;
    // setUniforms() data: one host-visible buffer per executor, rewound every frame (one frame in
    // flight, so the GPU is done with last frame's contents when recording starts).
    GpuBuffer mUniformRing;
    VkDeviceSize mUniformHead = 0;
    VkDeviceSize mUniformAlign = 256;
};

} // namespace vitrine
