#pragma once
// The Vulkan pipeline cache, kept on disk between runs.

#include <vulkan/vulkan.h>

#include <atomic>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace vitrine {

// A VkPipelineCache that every pipeline of a Context is created through, loaded from and saved to
// <cache folder>/pipeline/<vendorID>-<deviceID>-<pipelineCacheUUID>.bin (core/base/paths.hpp: cacheDir()).
//
// The file is vitrine's header (magic, vendorID, deviceID, driverVersion, pipelineCacheUUID, payload size, FNV-1a
// hash of the payload) followed by what vkGetPipelineCacheData returned. On load everything is checked: the header
// against this device and driver, the size and hash against the payload, and the payload's own Vulkan header
// (VkPipelineCacheHeaderVersionOne) against the device; a file that fails any check (truncated, corrupt, another
// device's, another driver version's) is ignored with one warning naming the file and the reason, and the run
// starts with an empty cache (the file is replaced when the context ends). Saving writes atomically
// (core/base/atomic_file.hpp) and only when the driver's data changed, so concurrent runs never leave half a file.
//
// How much it saves depends on the driver: Mesa's lavapipe 22.3 keeps nothing in its pipeline cache (its data is the
// 32-byte header), GPU drivers keep the compiled pipelines. hits() counts pipelines the driver reported as found in
// the cache (VkPipelineCreationFeedback), when it reports that at all.
class PipelineCache {
public:
    // dir empty: an in-memory cache, nothing loaded or saved.
    PipelineCache(VkDevice device, const VkPhysicalDeviceProperties& properties, std::filesystem::path dir);
    ~PipelineCache();
    PipelineCache(const PipelineCache&) = delete;
    PipelineCache& operator=(const PipelineCache&) = delete;

    VkPipelineCache handle() const { return mCache; }
    const std::filesystem::path& file() const { return mFile; }
    // Bytes of driver data loaded from the file (0: none, or the file was rejected).
    size_t loadedBytes() const { return mLoadedBytes; }
    // Why the file was rejected ("" when it was loaded or did not exist).
    const std::string& rejected() const { return mRejected; }

    // Chain `feedback` into a pipeline create info's pNext before creating, then call created() with it.
    static VkPipelineCreationFeedbackCreateInfo feedbackInfo(VkPipelineCreationFeedback* feedback, const void* next);
    void created(const VkPipelineCreationFeedback& feedback);
    uint32_t createdCount() const { return mCreated; }
    uint32_t hits() const { return mHits; }
    // The driver set VK_PIPELINE_CREATION_FEEDBACK_VALID_BIT (so hits() means something).
    bool hitsReported() const { return mFeedbackValid > 0; }

    // Writes the file when the driver's data differs from what was loaded. Called by the destructor too.
    void save();

    // The file's header for this device and driver, and the check of a file's bytes against it ("" when valid;
    // else the reason). Exposed for the tests.
    static std::string check(const std::vector<char>& bytes, const VkPhysicalDeviceProperties& properties,
                             std::vector<char>* payload);
    static std::vector<char> wrap(const std::vector<char>& payload, const VkPhysicalDeviceProperties& properties);

private:
    VkDevice mDevice;
    VkPhysicalDeviceProperties mProperties;
    std::filesystem::path mFile;
    VkPipelineCache mCache = VK_NULL_HANDLE;
    std::vector<char> mLoaded;
    size_t mLoadedBytes = 0;
    std::string mRejected;
    std::atomic<uint32_t> mCreated{0};
    std::atomic<uint32_t> mHits{0};
    std::atomic<uint32_t> mFeedbackValid{0};
};

} // namespace vitrine
