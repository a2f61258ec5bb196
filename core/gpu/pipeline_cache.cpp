#include "core/gpu/pipeline_cache.hpp"

#include "core/base/atomic_file.hpp"
#include "core/base/error.hpp"
#include "core/base/log.hpp"
#include "core/gpu/vk_check.hpp"

#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>

namespace vitrine {

namespace fs = std::filesystem;

namespace {

constexpr char kMagic[8] = {'V', 'T', 'R', 'N', 'P', 'C', '0', '1'};

struct FileHeader {
    char magic[8];
    uint32_t vendorID;
    uint32_t deviceID;
    uint32_t driverVersion;
    uint8_t uuid[VK_UUID_SIZE];
    uint32_t reserved[3];
    uint64_t payloadSize;
    uint64_t payloadHash;
};
static_assert(sizeof(FileHeader) == 64);

uint64_t fnv1a(const char* data, size_t size) {
    uint64_t h = 1469598103934665603ull;
    for (size_t i = 0; i < size; ++i) {
        h ^= static_cast<unsigned char>(data[i]);
        h *= 1099511628211ull;
    }
    return h;
}

std::string hex(const uint8_t* bytes, size_t n) {
    static const char* digits = "0123456789abcdef";
    std::string s;
    for (size_t i = 0; i < n; ++i) {
        s += digits[bytes[i] >> 4];
        s += digits[bytes[i] & 15];
    }
    return s;
}

std::string hex32(uint32_t v) {
    char buf[16];
    std::snprintf(buf, sizeof buf, "%04x", v);
    return buf;
}

} // namespace

std::vector<char> PipelineCache::wrap(const std::vector<char>& payload, const VkPhysicalDeviceProperties& p) {
    FileHeader h{};
    std::memcpy(h.magic, kMagic, sizeof kMagic);
    h.vendorID = p.vendorID;
    h.deviceID = p.deviceID;
    h.driverVersion = p.driverVersion;
    std::memcpy(h.uuid, p.pipelineCacheUUID, VK_UUID_SIZE);
    h.payloadSize = payload.size();
    h.payloadHash = fnv1a(payload.data(), payload.size());
    std::vector<char> out(sizeof h + payload.size());
    std::memcpy(out.data(), &h, sizeof h);
    if (!payload.empty()) std::memcpy(out.data() + sizeof h, payload.data(), payload.size());
    return out;
}

std::string PipelineCache::check(const std::vector<char>& bytes, const VkPhysicalDeviceProperties& p,
                                 std::vector<char>* payload) {
    FileHeader h{};
    if (bytes.size() < sizeof h)
        return "truncated: " + std::to_string(bytes.size()) + " bytes, shorter than the " + std::to_string(sizeof h) +
               "-byte header";
    std::memcpy(&h, bytes.data(), sizeof h);
    if (std::memcmp(h.magic, kMagic, sizeof kMagic) != 0) return "not a vitrine pipeline cache (wrong magic)";
    if (h.vendorID != p.vendorID || h.deviceID != p.deviceID)
        return "made for another device (vendor " + hex32(h.vendorID) + ", device " + hex32(h.deviceID) +
               "; this is vendor " + hex32(p.vendorID) + ", device " + hex32(p.deviceID) + ")";
    if (std::memcmp(h.uuid, p.pipelineCacheUUID, VK_UUID_SIZE) != 0)
        return "made with another pipelineCacheUUID (" + hex(h.uuid, VK_UUID_SIZE) + ")";
    if (h.driverVersion != p.driverVersion)
        return "made by another driver version (" + std::to_string(h.driverVersion) + "; this is " +
               std::to_string(p.driverVersion) + ")";
    if (h.payloadSize != bytes.size() - sizeof h)
        return "truncated or padded: the header says " + std::to_string(h.payloadSize) + " bytes of data, the file has " +
               std::to_string(bytes.size() - sizeof h);
    if (fnv1a(bytes.data() + sizeof h, h.payloadSize) != h.payloadHash) return "corrupt: the data's hash does not match";
    // The driver's own header (Vulkan spec: VkPipelineCacheHeaderVersionOne) must name this device too.
    VkPipelineCacheHeaderVersionOne vk{};
    if (h.payloadSize < sizeof vk) return "the driver data is shorter than Vulkan's pipeline cache header";
    std::memcpy(&vk, bytes.data() + sizeof h, sizeof vk);
    if (vk.headerSize < sizeof vk || vk.headerVersion != VK_PIPELINE_CACHE_HEADER_VERSION_ONE ||
        vk.vendorID != p.vendorID || vk.deviceID != p.deviceID ||
        std::memcmp(vk.pipelineCacheUUID, p.pipelineCacheUUID, VK_UUID_SIZE) != 0)
        return "the driver data's Vulkan header does not match this device";
    if (payload) payload->assign(bytes.begin() + sizeof h, bytes.end());
    return "";
}

PipelineCache::PipelineCache(VkDevice device, const VkPhysicalDeviceProperties& properties, fs::path dir)
    : mDevice(device), mProperties(properties) {
    if (!dir.empty()) {
        mFile = dir / (hex32(properties.vendorID) + "-" + hex32(properties.deviceID) + "-" +
                       hex(properties.pipelineCacheUUID, VK_UUID_SIZE) + ".bin");
        std::error_code ec;
        if (fs::exists(mFile, ec)) {
            std::ifstream in(mFile, std::ios::binary);
            std::vector<char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
            mRejected = in.bad() ? std::string("cannot be read") : check(bytes, properties, &mLoaded);
            if (!mRejected.empty()) {
                mLoaded.clear();
                logWarning(mFile.string() + ": pipeline cache ignored: " + mRejected +
                           "; starting with an empty one (the file is replaced when this run ends)");
            }
        }
    }
    VkPipelineCacheCreateInfo ci{VK_STRUCTURE_TYPE_PIPELINE_CACHE_CREATE_INFO};
    ci.initialDataSize = mLoaded.size();
    ci.pInitialData = mLoaded.empty() ? nullptr : mLoaded.data();
    VkResult result = vkCreatePipelineCache(device, &ci, nullptr, &mCache);
    if (result != VK_SUCCESS && !mLoaded.empty()) {
        // The checks passed but the driver still refused the data: start empty rather than fail the run.
        logWarning(mFile.string() + ": the driver refused the pipeline cache data (" + vkResultName(result) +
                   "); starting with an empty one");
        mRejected = std::string("refused by the driver (") + vkResultName(result) + ")";
        mLoaded.clear();
        ci.initialDataSize = 0;
        ci.pInitialData = nullptr;
        result = vkCreatePipelineCache(device, &ci, nullptr, &mCache);
    }
    VK_CHECK(result);
    mLoadedBytes = mLoaded.size();
    if (mLoadedBytes) logDebug("pipeline cache: loaded " + std::to_string(mLoadedBytes) + " bytes from " + mFile.string());
}

PipelineCache::~PipelineCache() {
    try {
        save();
    } catch (const std::exception& e) {
        logWarning(std::string("pipeline cache not saved: ") + e.what());
    }
    if (mCreated)
        logDebug("pipeline cache: " + std::to_string(mCreated.load()) + " pipelines created, " +
                 (hitsReported() ? std::to_string(mHits.load()) + " found in the cache"
                                 : std::string("the driver does not report cache hits")));
    vkDestroyPipelineCache(mDevice, mCache, nullptr);
}

VkPipelineCreationFeedbackCreateInfo PipelineCache::feedbackInfo(VkPipelineCreationFeedback* feedback, const void* next) {
    *feedback = {};
    VkPipelineCreationFeedbackCreateInfo info{VK_STRUCTURE_TYPE_PIPELINE_CREATION_FEEDBACK_CREATE_INFO};
    info.pNext = next;
    info.pPipelineCreationFeedback = feedback;
    return info;
}

void PipelineCache::created(const VkPipelineCreationFeedback& feedback) {
    ++mCreated;
    if (feedback.flags & VK_PIPELINE_CREATION_FEEDBACK_VALID_BIT) {
        ++mFeedbackValid;
        if (feedback.flags & VK_PIPELINE_CREATION_FEEDBACK_APPLICATION_PIPELINE_CACHE_HIT_BIT) ++mHits;
    }
}

void PipelineCache::save() {
    if (mFile.empty() || !mCache) return;
    size_t size = 0;
    VK_CHECK(vkGetPipelineCacheData(mDevice, mCache, &size, nullptr));
    std::vector<char> data(size);
    if (size) VK_CHECK(vkGetPipelineCacheData(mDevice, mCache, &size, data.data()));
    data.resize(size);
    if (data == mLoaded && mRejected.empty() && fs::exists(mFile)) return;
    fs::create_directories(mFile.parent_path());
    const std::vector<char> bytes = wrap(data, mProperties);
    writeFileAtomically(mFile, std::string_view(bytes.data(), bytes.size()));
    mLoaded = std::move(data);
    mRejected.clear();
}

} // namespace vitrine
