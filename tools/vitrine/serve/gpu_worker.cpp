#include "tools/vitrine/serve/gpu_worker.hpp"

#include "core/base/error.hpp"
#include "core/base/log.hpp"
#include "core/graph/executor.hpp"
#include "tools/vitrine/serve/http_util.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

namespace vitrine::serve {

GpuWorker::GpuWorker(const ContextOptions& options, size_t warmGraphs, size_t maxQueued)
    : mOptions(options), mWarmCapacity(warmGraphs), mMaxQueued(maxQueued) {
    std::promise<void> ready;
    std::future<void> started = ready.get_future();
    mThread = std::thread([this, &ready] {
        try {
            mCtx = std::make_unique<Context>(mOptions);
            mShaders = std::make_unique<ShaderCompiler>();
            mWarm = std::make_unique<WarmGraphs>(mWarmCapacity);
            mDeviceName = mCtx->deviceInfo().name;
        } catch (...) {
            ready.set_exception(std::current_exception());
            return;
        }
        ready.set_value();
        loop();
    });
    try {
        started.get();
    } catch (...) {
        mThread.join();
        throw;
    }
}

GpuWorker::~GpuWorker() {
    stop();
}

void GpuWorker::stop() {
    {
        std::lock_guard lock(mMutex);
        mStopping = true;
    }
    mWake.notify_all();
    if (mThread.joinable()) mThread.join();
}

size_t GpuWorker::queued() const {
    std::lock_guard lock(mMutex);
    return mJobs.size();
}

namespace {

int retryAfter(double meanJobSeconds, size_t queued) {
    return static_cast<int>(std::clamp(std::ceil(meanJobSeconds * static_cast<double>(queued + 1)), 1.0, 60.0));
}

} // namespace

int GpuWorker::retryAfterSeconds() const {
    return retryAfter(mMeanJobSeconds.load(), queued());
}

HttpError GpuWorker::queueFull() const {
    return fullError(queued());
}

HttpError GpuWorker::fullError(size_t queued) const {
    const int seconds = retryAfter(mMeanJobSeconds.load(), queued);
    return HttpError(503,
                     "the GPU is busy: " + std::to_string(queued) + " jobs wait already (at most " +
                         std::to_string(mMaxQueued) + ", --max-queue); retry in " + std::to_string(seconds) + " s",
                     {{"reason", "queue-full"}, {"retry_after", seconds}, {"queued", queued}});
}

void GpuWorker::post(std::function<void()> job, const std::string& tag, std::function<void()> cancel) {
    std::vector<std::function<void()>> superseded;
    {
        std::lock_guard lock(mMutex);
        if (mStopping) throw InternalError("vitrine serve is stopping; the GPU queue takes no more work");
        // A job that replaces a queued one with its tag takes that one's place.
        const size_t replaced =
            tag.empty() ? 0 : std::count_if(mJobs.begin(), mJobs.end(), [&](const Job& j) { return j.tag == tag; });
        if (mJobs.size() - replaced >= mMaxQueued) throw fullError(mJobs.size());
        if (!tag.empty())
            std::erase_if(mJobs, [&](Job& queued) {
                if (queued.tag != tag) return false;
                if (queued.cancel) superseded.push_back(std::move(queued.cancel));
                return true;
            });
        mJobs.push_back({std::move(job), tag, std::move(cancel)});
    }
    mWake.notify_one();
    for (auto& c : superseded) c(); // outside the lock: a cancel may publish events or fulfil promises
}

void GpuWorker::loop() {
    for (;;) {
        std::function<void()> job;
        {
            std::unique_lock lock(mMutex);
            mWake.wait(lock, [&] { return mStopping || !mJobs.empty(); });
            if (mJobs.empty()) break; // stopping, and every job posted before has run
            job = std::move(mJobs.front().run);
            mJobs.pop_front();
            mBusy = true;
        }
        const auto start = std::chrono::steady_clock::now();
        job();
        const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        mMeanJobSeconds = 0.75 * mMeanJobSeconds.load() + 0.25 * seconds;
        mBusy = false;
    }
    mWarm.reset();
    mShaders.reset();
    mCtx.reset();
}

RenderResult GpuWorker::render(const PreparedGraph& graph, const ProgressFn& progress,
                              const NodeProgressFn& nodeProgress, const std::string& tag) {
    std::promise<RenderResult> promise;
    std::future<RenderResult> result = promise.get_future();
    // The caller waits for the future, so the job may refer to its arguments. Either the job runs or it is
    // cancelled (superseded), never both: a cancelled job has left the queue.
    post(
        [&] {
            try {
                promise.set_value(renderNow(graph, progress, nodeProgress));
            } catch (...) {
                promise.set_exception(std::current_exception());
            }
        },
        tag,
        [&] {
            promise.set_exception(std::make_exception_ptr(
                HttpError(409, "superseded: a newer request with tag \"" + tag + "\" came before this one started",
                          {{"superseded", true}})));
        });
    return result.get();
}

RenderResult GpuWorker::renderNow(const PreparedGraph& graph, const ProgressFn& progress,
                                  const NodeProgressFn& nodeProgress) {
    RenderResult out;
    ScopedProgressObserver observer(nodeProgress);
    WarmGraphs::Entry* entry = nullptr;
    try {
        if (!mCtx) mCtx = std::make_unique<Context>(mOptions);
        const size_t before = mCtx->validationMessageCount();
        progress("compiling", 0, 0);
        bool compiled = false;
        entry = &mWarm->get(*mCtx, *mShaders, graph, compiled);
        mWarmCount = mWarm->size();
        out.warm = !compiled;
        const uint32_t frames = graph.desc.frame.frames;
        RunOptions options;
        options.frames = frames;
        options.write = {frames - 1};
        options.progress = false;
        options.onOutput = [&](uint32_t, const std::string& name, const Image& image) {
            out.image = image;
            out.images[name] = image;
        };
        uint32_t done = 0;
        options.stop = [&] {
            progress("rendering", ++done, frames);
            return false;
        };
        mWarm->executor(*entry).run(options);
        out.validationMessages = mCtx->validationMessageCount() - before;
        return out;
    } catch (const UserError&) {
        if (entry) mWarm->drop(*entry);
        mWarmCount = mWarm->size();
        throw;
    } catch (...) {
        // A Vulkan failure may have lost the device: start afresh so that the next request gets a working one.
        mWarm->clear();
        mWarmCount = 0;
        try {
            mCtx.reset();
            mCtx = std::make_unique<Context>(mOptions);
            logWarning("vitrine serve: a render failed on the GPU; the Vulkan device was created anew");
        } catch (const std::exception& e) {
            logWarning(std::string("vitrine serve: the Vulkan device could not be created anew: ") + e.what());
        }
        throw;
    }
}

} // namespace vitrine::serve
