#pragma once

#include "core/gpu/vk_check.hpp"

#include <cstdint>
#include <deque>
#include <filesystem>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

namespace vitrine {

class Allocator;
class PipelineCache;

// The validation messages of a context. Shared so that a test harness can still read what the layer said while
// the context was being destroyed (leaked objects are reported then).
class ValidationLog {
public:
    void add(std::string message);
    size_t count() const;
    std::vector<std::string> messages() const;

private:
    mutable std::mutex mMutex;
    std::vector<std::string> mMessages;
};

struct ContextOptions {
    bool validation = false;  // enable VK_LAYER_KHRONOS_validation and count its messages
    // With validation: also the layer's synchronization validation (SYNC-HAZARD-* messages count like any other).
    bool synchronizationValidation = true;
    std::string device;       // index ("0") or a case-insensitive substring of the device name; empty: best
    bool printValidation = true;
    std::shared_ptr<ValidationLog> log; // where messages go; made by the context when empty
    // The persistent pipeline cache (pipeline_cache.hpp) in this folder; empty: cacheDir()/pipeline
    // (core/base/paths.hpp). pipelineCache = false: an in-memory cache only, nothing read or written.
    bool pipelineCache = true;
    std::filesystem::path pipelineCacheDir;
};

struct DeviceInfo {
    uint32_t index = 0;
    std::string name;
    VkPhysicalDeviceType type = VK_PHYSICAL_DEVICE_TYPE_OTHER;
    uint32_t apiVersion = 0;
};

// Headless Vulkan 1.3 instance + device + one graphics/compute queue. Owns the allocator and
// the deferred-destruction queue: objects handed to destroyLater() are destroyed only once
// every submission made before the call has completed on the GPU.
class Context {
public:
    explicit Context(const ContextOptions& options = {});
    ~Context();
    Context(const Context&) = delete;
    Context& operator=(const Context&) = delete;

    static std::vector<DeviceInfo> listDevices();

    VkInstance instance() const { return mInstance; }
    VkPhysicalDevice physicalDevice() const { return mPhysicalDevice; }
    VkDevice device() const { return mDevice; }
    VkQueue queue() const { return mQueue; }
    uint32_t queueFamily() const { return mQueueFamily; }
    const VkPhysicalDeviceProperties& properties() const { return mProperties; }
    // The dualSrcBlend feature is enabled (forward.transparent tints what lies behind glass with it).
    bool dualSourceBlend() const { return mDualSourceBlend; }
    const DeviceInfo& deviceInfo() const { return mDeviceInfo; }
    Allocator& allocator() { return *mAllocator; }
    // Every pipeline is created through it; saved to disk when the context ends.
    PipelineCache& pipelineCache() { return *mPipelineCache; }
    bool validationEnabled() const { return mValidation; }

    // Validation messages (warnings and errors) seen since the context was made. Tests fail on any.
    size_t validationMessageCount() const;
    std::vector<std::string> validationMessages() const;
    const std::shared_ptr<ValidationLog>& validationLog() const { return mLog; }

    void setName(uint64_t handle, VkObjectType type, const std::string& name) const;

    // Submits a command buffer; returns the serial that completes with it.
    uint64_t submit(VkCommandBuffer cmd);
    void waitSerial(uint64_t serial);
    void waitIdle();
    uint64_t lastSubmitted() const { return mSubmitted; }
    // Every wait on a fence so far (waitSerial that had to block, waitIdle, immediate) and the time spent in them:
    // the executor takes the difference over a frame's recording as the frame's in-frame waits (bench, tests).
    uint64_t waitCount() const { return mWaitCount; }
    double waitMs() const { return mWaitMs; }

    // Records with `record`, submits and waits. For uploads, read-backs and tests, not per-frame work.
    void immediate(const std::function<void(VkCommandBuffer)>& record);

    VkCommandBuffer allocateCommandBuffer();
    void freeCommandBuffer(VkCommandBuffer cmd);

    void destroyLater(std::function<void()> destroy);
    // Runs the destructions whose submissions have completed.
    void collectGarbage();

    double timestampPeriodNs() const { return mProperties.limits.timestampPeriod; }

private:
    struct Pending {
        uint64_t serial;
        VkFence fence;
    };
    struct Deferred {
        uint64_t serial;
        std::function<void()> destroy;
    };
    void pollFences();

    bool mValidation = false;
    bool mDualSourceBlend = false;
    bool mPrintValidation = true;
    VkInstance mInstance = VK_NULL_HANDLE;
    VkDebugUtilsMessengerEXT mMessenger = VK_NULL_HANDLE;
    VkPhysicalDevice mPhysicalDevice = VK_NULL_HANDLE;
    VkDevice mDevice = VK_NULL_HANDLE;
    VkQueue mQueue = VK_NULL_HANDLE;
    uint32_t mQueueFamily = 0;
    VkPhysicalDeviceProperties mProperties{};
    DeviceInfo mDeviceInfo;
    VkCommandPool mCommandPool = VK_NULL_HANDLE;
    PFN_vkSetDebugUtilsObjectNameEXT mSetName = nullptr;
    std::unique_ptr<Allocator> mAllocator;
    std::unique_ptr<PipelineCache> mPipelineCache;

    uint64_t mSubmitted = 0;
    uint64_t mCompleted = 0;
    uint64_t mWaitCount = 0;
    double mWaitMs = 0.0;
    std::deque<Pending> mPending;
    std::vector<VkFence> mFreeFences;
    std::deque<Deferred> mDeferred;

    std::shared_ptr<ValidationLog> mLog;
    friend VkBool32 debugCallback(VkDebugUtilsMessageSeverityFlagBitsEXT, VkDebugUtilsMessageTypeFlagsEXT,
                                  const VkDebugUtilsMessengerCallbackDataEXT*, void*);
};

} // namespace vitrine
