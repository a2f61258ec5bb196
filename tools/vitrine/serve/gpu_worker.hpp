#pragma once

#include "core/gpu/context.hpp"
#include "core/graph/compiler.hpp"
#include "core/image/image.hpp"
#include "core/shader/compiler.hpp"
#include "tools/vitrine/serve/http_util.hpp"
#include "tools/vitrine/serve/warm_graphs.hpp"

#include <atomic>
#include <condition_variable>
#include <deque>
#include <functional>
#include <future>
#include <list>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

// The GPU side of `vitrine serve`: one thread owns the Vulkan device, the shader compiler and the graphs compiled
// for earlier requests, and runs the requests' GPU work one at a time in the order they came (the queue is the one
// place GPU work is serialised). The queue is bounded: past `maxQueued` waiting jobs a new one is refused at once
// (HttpError 503 with a Retry-After estimate) instead of waiting without end. A request that fails (a UserError from
// a node's setup, a Vulkan error) fails alone; the thread goes on with the next one.
namespace vitrine::serve {

// What a render job reports while it runs, on the GPU thread: "compiling", then "rendering" with frames done/total.
using ProgressFn = std::function<void(const std::string& stage, uint32_t done, uint32_t total)>;
// Long work inside one node (a bake, the probe capture), on the GPU thread: the node's id, what it does, its counts.
using NodeProgressFn =
    std::function<void(const std::string& node, const std::string& label, size_t done, size_t total)>;

struct RenderResult {
    Image image;                         // the output at the last frame (with previews: the last one written)
    std::map<std::string, Image> images; // every graph output at the last frame, by name
    bool warm = false;                   // the compiled graph was kept from an earlier request
    size_t validationMessages = 0;       // Vulkan validation messages during this job (with --validate)
};

class GpuWorker {
public:
    // Starts the thread and creates the device on it; rethrows when that fails (no Vulkan device). At most
    // `maxQueued` jobs wait behind the running one.
    GpuWorker(const ContextOptions& options, size_t warmGraphs, size_t maxQueued);
    ~GpuWorker();
    GpuWorker(const GpuWorker&) = delete;
    GpuWorker& operator=(const GpuWorker&) = delete;

    // Renders the frames of `graph` and returns its one output at the last frame. Blocks the calling thread until
    // the job has run on the GPU thread; rethrows what it threw.
    // A job posted with a `tag` replaces the queued job with the same tag that has not started (the editor's preview
    // of a document it has edited since): that one fails with HttpError 409 "superseded".
    RenderResult render(const PreparedGraph& graph, const ProgressFn& progress, const NodeProgressFn& nodeProgress = {},
                        const std::string& tag = {});
    // Runs `job` on the GPU thread after the jobs before it (fire and forget: `job` handles its own errors).
    // With a `tag`, a queued job with the same tag that has not started is dropped and its `cancel` called.
    // Throws queueFull() (nothing posted, nothing dropped) when `maxQueued` jobs wait already.
    void post(std::function<void()> job, const std::string& tag = {}, std::function<void()> cancel = {});
    // render() for a job already on the GPU thread.
    RenderResult renderNow(const PreparedGraph& graph, const ProgressFn& progress,
                           const NodeProgressFn& nodeProgress = {});
    // Runs the jobs already posted, then frees the device and ends the thread; later posts throw. Idempotent.
    void stop();

    std::string deviceName() const { return mDeviceName; }
    size_t queued() const;
    size_t maxQueued() const { return mMaxQueued; }
    bool busy() const { return mBusy; }
    // Seconds until the queue has room, estimated from the mean time of the latest jobs (at least 1, at most 60):
    // the Retry-After of a 503.
    int retryAfterSeconds() const;
    // The 503 a request gets when the queue is full: {"reason": "queue-full", "retry_after", "queued"}.
    HttpError queueFull() const;
    size_t warmGraphs() const { return mWarmCount; }

private:
    void loop();
    HttpError fullError(size_t queued) const;

    ContextOptions mOptions;
    size_t mWarmCapacity;
    std::unique_ptr<Context> mCtx;
    std::unique_ptr<ShaderCompiler> mShaders;
    std::unique_ptr<WarmGraphs> mWarm;
    std::string mDeviceName;
    std::atomic<size_t> mWarmCount{0};

    size_t mMaxQueued;
    std::atomic<bool> mBusy{false};
    std::atomic<double> mMeanJobSeconds{1.0}; // moving mean of the latest jobs' run times

    mutable std::mutex mMutex;
    std::condition_variable mWake;
    struct Job {
        std::function<void()> run;
        std::string tag;
        std::function<void()> cancel;
    };
    std::deque<Job> mJobs;
    bool mStopping = false;
    std::thread mThread;
};

} // namespace vitrine::serve
