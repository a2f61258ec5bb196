#include "core/gpu/context.hpp"

#include "core/base/error.hpp"
#include "core/base/log.hpp"
#include "core/base/paths.hpp"
#include "core/gpu/allocator.hpp"
#include "core/gpu/pipeline_cache.hpp"

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cstring>

namespace vitrine {

const char* vkResultName(VkResult result) {
    switch (result) {
    case VK_SUCCESS: return "VK_SUCCESS";
    case VK_NOT_READY: return "VK_NOT_READY";
    case VK_TIMEOUT: return "VK_TIMEOUT";
    case VK_ERROR_OUT_OF_HOST_MEMORY: return "VK_ERROR_OUT_OF_HOST_MEMORY";
    case VK_ERROR_OUT_OF_DEVICE_MEMORY: return "VK_ERROR_OUT_OF_DEVICE_MEMORY";
    case VK_ERROR_INITIALIZATION_FAILED: return "VK_ERROR_INITIALIZATION_FAILED";
    case VK_ERROR_DEVICE_LOST: return "VK_ERROR_DEVICE_LOST";
    case VK_ERROR_LAYER_NOT_PRESENT: return "VK_ERROR_LAYER_NOT_PRESENT";
    case VK_ERROR_EXTENSION_NOT_PRESENT: return "VK_ERROR_EXTENSION_NOT_PRESENT";
    case VK_ERROR_FEATURE_NOT_PRESENT: return "VK_ERROR_FEATURE_NOT_PRESENT";
    case VK_ERROR_INCOMPATIBLE_DRIVER: return "VK_ERROR_INCOMPATIBLE_DRIVER";
    case VK_ERROR_FORMAT_NOT_SUPPORTED: return "VK_ERROR_FORMAT_NOT_SUPPORTED";
    case VK_ERROR_OUT_OF_POOL_MEMORY: return "VK_ERROR_OUT_OF_POOL_MEMORY";
    default: return "VkResult(unknown)";
    }
}

void throwVkError(VkResult result, const char* expression, const char* file, int line) {
    throw InternalError(std::string(file) + ":" + std::to_string(line) + ": " + expression + " failed with " +
                        vkResultName(result) + " (" + std::to_string(static_cast<int>(result)) + ")");
}

VkBool32 debugCallback(VkDebugUtilsMessageSeverityFlagBitsEXT severity, VkDebugUtilsMessageTypeFlagsEXT types,
                       const VkDebugUtilsMessengerCallbackDataEXT* data, void* user) {
    auto* ctx = static_cast<Context*>(user);
    std::string message = data && data->pMessage ? data->pMessage : "(no message)";
    ctx->mLog->add(message);
    if (ctx->mPrintValidation) {
        const char* level = (severity & VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT) ? "error" : "warning";
        std::fprintf(stderr, "vulkan validation %s: %s\n", level, message.c_str());
    }
    return VK_FALSE;
}

namespace {

bool hasLayer(const char* name) {
    uint32_t count = 0;
    vkEnumerateInstanceLayerProperties(&count, nullptr);
    std::vector<VkLayerProperties> layers(count);
    vkEnumerateInstanceLayerProperties(&count, layers.data());
    return std::any_of(layers.begin(), layers.end(), [&](const auto& l) { return std::strcmp(l.layerName, name) == 0; });
}

bool hasInstanceExtension(const char* name) {
    uint32_t count = 0;
    vkEnumerateInstanceExtensionProperties(nullptr, &count, nullptr);
    std::vector<VkExtensionProperties> exts(count);
    vkEnumerateInstanceExtensionProperties(nullptr, &count, exts.data());
    return std::any_of(exts.begin(), exts.end(), [&](const auto& e) { return std::strcmp(e.extensionName, name) == 0; });
}

int typeRank(VkPhysicalDeviceType type) {
    switch (type) {
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU: return 4;
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU: return 3;
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU: return 2;
    case VK_PHYSICAL_DEVICE_TYPE_CPU: return 1;
    default: return 0;
    }
}

std::string lower(std::string s) {
    std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::tolower(c); });
    return s;
}

VkDebugUtilsMessengerCreateInfoEXT messengerInfo(void* user) {
    VkDebugUtilsMessengerCreateInfoEXT info{VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
    info.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
    info.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT;
    info.pfnUserCallback = debugCallback;
    info.pUserData = user;
    return info;
}

// validation: the Khronos layer with the debug-utils messenger chained into instance creation (so messages of
// vkCreateInstance/vkDestroyInstance are caught too) and, when asked, synchronization validation.
VkInstance createInstance(bool validation, bool debugUtils, bool syncValidation = false, void* user = nullptr) {
    VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
    app.pApplicationName = "vitrine";
    app.pEngineName = "vitrine";
    app.apiVersion = VK_API_VERSION_1_3;

    std::vector<const char*> layers;
    std::vector<const char*> extensions;
    if (validation) layers.push_back("VK_LAYER_KHRONOS_validation");
    if (debugUtils) extensions.push_back(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);

    VkInstanceCreateInfo info{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
    VkDebugUtilsMessengerCreateInfoEXT messenger = messengerInfo(user);
    const VkValidationFeatureEnableEXT syncFeature = VK_VALIDATION_FEATURE_ENABLE_SYNCHRONIZATION_VALIDATION_EXT;
    VkValidationFeaturesEXT features{VK_STRUCTURE_TYPE_VALIDATION_FEATURES_EXT};
    if (validation) {
        info.pNext = &messenger;
        if (syncValidation) {
            features.enabledValidationFeatureCount = 1;
            features.pEnabledValidationFeatures = &syncFeature;
            messenger.pNext = &features;
        }
    }
    info.pApplicationInfo = &app;
    info.enabledLayerCount = static_cast<uint32_t>(layers.size());
    info.ppEnabledLayerNames = layers.data();
    info.enabledExtensionCount = static_cast<uint32_t>(extensions.size());
    info.ppEnabledExtensionNames = extensions.data();
    VkInstance instance = VK_NULL_HANDLE;
    VkResult result = vkCreateInstance(&info, nullptr, &instance);
    if (result == VK_ERROR_INCOMPATIBLE_DRIVER)
        throw UserError("no Vulkan 1.3 driver found: install mesa-vulkan-drivers (lavapipe) or a GPU driver "
                        "(tools/install-deps.sh does)");
    VK_CHECK(result);
    return instance;
}

std::vector<VkPhysicalDevice> physicalDevices(VkInstance instance) {
    uint32_t count = 0;
    VK_CHECK(vkEnumeratePhysicalDevices(instance, &count, nullptr));
    std::vector<VkPhysicalDevice> devices(count);
    VK_CHECK(vkEnumeratePhysicalDevices(instance, &count, devices.data()));
    return devices;
}

DeviceInfo describe(VkPhysicalDevice pd, uint32_t index) {
    VkPhysicalDeviceProperties p;
    vkGetPhysicalDeviceProperties(pd, &p);
    return DeviceInfo{index, p.deviceName, p.deviceType, p.apiVersion};
}

} // namespace

std::vector<DeviceInfo> Context::listDevices() {
    VkInstance instance = createInstance(false, false);
    std::vector<DeviceInfo> result;
    auto devices = physicalDevices(instance);
    for (uint32_t i = 0; i < devices.size(); ++i) result.push_back(describe(devices[i], i));
    vkDestroyInstance(instance, nullptr);
    return result;
}

Context::Context(const ContextOptions& options)
    : mPrintValidation(options.printValidation),
      mLog(options.log ? options.log : std::make_shared<ValidationLog>()) {
    mValidation = options.validation;
    if (mValidation && !hasLayer("VK_LAYER_KHRONOS_validation"))
        throw UserError("validation requested but VK_LAYER_KHRONOS_validation is not installed "
                        "(Debian package vulkan-validationlayers; tools/install-deps.sh installs it)");
    bool debugUtils = hasInstanceExtension(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
    // Without the messenger the layer's messages could not be counted: a validated run would pass unheard.
    if (mValidation && !debugUtils)
        throw UserError("validation requested but the Vulkan loader offers no " VK_EXT_DEBUG_UTILS_EXTENSION_NAME
                        ", so validation messages could not be counted");
    mInstance = createInstance(mValidation, debugUtils, mValidation && options.synchronizationValidation, this);

    if (debugUtils) {
        mSetName = reinterpret_cast<PFN_vkSetDebugUtilsObjectNameEXT>(
            vkGetInstanceProcAddr(mInstance, "vkSetDebugUtilsObjectNameEXT"));
    }
    if (mValidation && debugUtils) {
        VkDebugUtilsMessengerCreateInfoEXT info = messengerInfo(this);
        auto create = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
            vkGetInstanceProcAddr(mInstance, "vkCreateDebugUtilsMessengerEXT"));
        VK_CHECK(create(mInstance, &info, nullptr, &mMessenger));
    }

    auto devices = physicalDevices(mInstance);
    if (devices.empty())
        throw UserError("no Vulkan device found: install mesa-vulkan-drivers for the lavapipe CPU device");
    int chosen = -1;
    if (!options.device.empty()) {
        bool numeric = std::all_of(options.device.begin(), options.device.end(), ::isdigit);
        for (uint32_t i = 0; i < devices.size() && chosen < 0; ++i) {
            DeviceInfo d = describe(devices[i], i);
            if (numeric ? std::stoul(options.device) == i : lower(d.name).find(lower(options.device)) != std::string::npos)
                chosen = static_cast<int>(i);
        }
        if (chosen < 0) {
            std::string list;
            for (uint32_t i = 0; i < devices.size(); ++i) list += "\n  " + std::to_string(i) + ": " + describe(devices[i], i).name;
            throw UserError("--device " + options.device + ": no such Vulkan device; available:" + list);
        }
    } else {
        int best = -1;
        for (uint32_t i = 0; i < devices.size(); ++i) {
            DeviceInfo d = describe(devices[i], i);
            if (d.apiVersion < VK_API_VERSION_1_3) continue;
            if (typeRank(d.type) > best) {
                best = typeRank(d.type);
                chosen = static_cast<int>(i);
            }
        }
        if (chosen < 0) throw UserError("no Vulkan 1.3 device found");
    }
    mPhysicalDevice = devices[chosen];
    mDeviceInfo = describe(mPhysicalDevice, static_cast<uint32_t>(chosen));
    vkGetPhysicalDeviceProperties(mPhysicalDevice, &mProperties);
    if (mProperties.apiVersion < VK_API_VERSION_1_3)
        throw UserError("device '" + mDeviceInfo.name + "' supports only Vulkan " +
                        std::to_string(VK_API_VERSION_MAJOR(mProperties.apiVersion)) + "." +
                        std::to_string(VK_API_VERSION_MINOR(mProperties.apiVersion)) + "; vitrine needs 1.3");

    uint32_t familyCount = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(mPhysicalDevice, &familyCount, nullptr);
    std::vector<VkQueueFamilyProperties> families(familyCount);
    vkGetPhysicalDeviceQueueFamilyProperties(mPhysicalDevice, &familyCount, families.data());
    bool found = false;
    for (uint32_t i = 0; i < familyCount; ++i) {
        VkQueueFlags need = VK_QUEUE_GRAPHICS_BIT | VK_QUEUE_COMPUTE_BIT;
        if ((families[i].queueFlags & need) == need && families[i].timestampValidBits > 0) {
            mQueueFamily = i;
            found = true;
            break;
        }
    }
    if (!found) throw UserError("device '" + mDeviceInfo.name + "' has no graphics+compute queue with timestamps");

    VkPhysicalDeviceFeatures supported{};
    vkGetPhysicalDeviceFeatures(mPhysicalDevice, &supported);
    VkPhysicalDeviceVulkan13Features f13{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES};
    f13.synchronization2 = VK_TRUE;
    f13.dynamicRendering = VK_TRUE;
    VkPhysicalDeviceVulkan12Features f12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES};
    f12.pNext = &f13;
    f12.hostQueryReset = VK_TRUE;
    VkPhysicalDeviceFeatures2 features{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2};
    features.pNext = &f12;
    if (!supported.shaderStorageImageWriteWithoutFormat)
        throw UserError("device '" + mDeviceInfo.name + "' lacks shaderStorageImageWriteWithoutFormat");
    features.features.shaderStorageImageWriteWithoutFormat = VK_TRUE;
    features.features.samplerAnisotropy = supported.samplerAnisotropy;
    features.features.fragmentStoresAndAtomics = supported.fragmentStoresAndAtomics;
    features.features.shaderInt64 = supported.shaderInt64;
    features.features.depthClamp = supported.depthClamp;
    features.features.dualSrcBlend = supported.dualSrcBlend;
    features.features.imageCubeArray = supported.imageCubeArray; // probe cube-map arrays (ibl.capture, ibl.localized)
    mDualSourceBlend = supported.dualSrcBlend;

    float priority = 1.0f;
    VkDeviceQueueCreateInfo queueInfo{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
    queueInfo.queueFamilyIndex = mQueueFamily;
    queueInfo.queueCount = 1;
    queueInfo.pQueuePriorities = &priority;
    VkDeviceCreateInfo deviceInfo{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
    deviceInfo.pNext = &features;
    deviceInfo.queueCreateInfoCount = 1;
    deviceInfo.pQueueCreateInfos = &queueInfo;
    VK_CHECK(vkCreateDevice(mPhysicalDevice, &deviceInfo, nullptr, &mDevice));
    vkGetDeviceQueue(mDevice, mQueueFamily, 0, &mQueue);

    VkCommandPoolCreateInfo poolInfo{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
    poolInfo.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
    poolInfo.queueFamilyIndex = mQueueFamily;
    VK_CHECK(vkCreateCommandPool(mDevice, &poolInfo, nullptr, &mCommandPool));

    mAllocator = std::make_unique<Allocator>(*this);
    mPipelineCache = std::make_unique<PipelineCache>(
        mDevice, mProperties,
        !options.pipelineCache ? std::filesystem::path()
        : options.pipelineCacheDir.empty() ? cacheDir() / "pipeline" : options.pipelineCacheDir);
}

Context::~Context() {
    if (mDevice) {
        vkDeviceWaitIdle(mDevice);
        mCompleted = mSubmitted;
        collectGarbage();
        mAllocator.reset();
        mPipelineCache.reset(); // saves the file
        for (auto& p : mPending) vkDestroyFence(mDevice, p.fence, nullptr);
        for (VkFence f : mFreeFences) vkDestroyFence(mDevice, f, nullptr);
        vkDestroyCommandPool(mDevice, mCommandPool, nullptr);
        vkDestroyDevice(mDevice, nullptr);
    }
    if (mMessenger) {
        auto destroy = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
            vkGetInstanceProcAddr(mInstance, "vkDestroyDebugUtilsMessengerEXT"));
        destroy(mInstance, mMessenger, nullptr);
    }
    if (mInstance) vkDestroyInstance(mInstance, nullptr);
}

void ValidationLog::add(std::string message) {
    std::lock_guard<std::mutex> lock(mMutex);
    mMessages.push_back(std::move(message));
}

size_t ValidationLog::count() const {
    std::lock_guard<std::mutex> lock(mMutex);
    return mMessages.size();
}

std::vector<std::string> ValidationLog::messages() const {
    std::lock_guard<std::mutex> lock(mMutex);
    return mMessages;
}

size_t Context::validationMessageCount() const { return mLog->count(); }

std::vector<std::string> Context::validationMessages() const { return mLog->messages(); }

void Context::setName(uint64_t handle, VkObjectType type, const std::string& name) const {
    if (!mSetName || name.empty()) return;
    VkDebugUtilsObjectNameInfoEXT info{VK_STRUCTURE_TYPE_DEBUG_UTILS_OBJECT_NAME_INFO_EXT};
    info.objectType = type;
    info.objectHandle = handle;
    info.pObjectName = name.c_str();
    mSetName(mDevice, &info);
}

uint64_t Context::submit(VkCommandBuffer cmd) {
    VkFence fence = VK_NULL_HANDLE;
    if (!mFreeFences.empty()) {
        fence = mFreeFences.back();
        mFreeFences.pop_back();
    } else {
        VkFenceCreateInfo info{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
        VK_CHECK(vkCreateFence(mDevice, &info, nullptr, &fence));
    }
    VkCommandBufferSubmitInfo cmdInfo{VK_STRUCTURE_TYPE_COMMAND_BUFFER_SUBMIT_INFO};
    cmdInfo.commandBuffer = cmd;
    VkSubmitInfo2 submit{VK_STRUCTURE_TYPE_SUBMIT_INFO_2};
    submit.commandBufferInfoCount = 1;
    submit.pCommandBufferInfos = &cmdInfo;
    VK_CHECK(vkQueueSubmit2(mQueue, 1, &submit, fence));
    mPending.push_back({++mSubmitted, fence});
    return mSubmitted;
}

void Context::pollFences() {
    while (!mPending.empty() && vkGetFenceStatus(mDevice, mPending.front().fence) == VK_SUCCESS) {
        mCompleted = mPending.front().serial;
        VK_CHECK(vkResetFences(mDevice, 1, &mPending.front().fence));
        mFreeFences.push_back(mPending.front().fence);
        mPending.pop_front();
    }
}

void Context::waitSerial(uint64_t serial) {
    if (mCompleted < serial && !mPending.empty()) {
        const auto start = std::chrono::steady_clock::now();
        ++mWaitCount;
        while (mCompleted < serial && !mPending.empty()) {
            VK_CHECK(vkWaitForFences(mDevice, 1, &mPending.front().fence, VK_TRUE, UINT64_MAX));
            pollFences();
        }
        mWaitMs += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    }
    collectGarbage();
}

void Context::waitIdle() { waitSerial(mSubmitted); }

VkCommandBuffer Context::allocateCommandBuffer() {
    VkCommandBufferAllocateInfo info{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
    info.commandPool = mCommandPool;
    info.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    info.commandBufferCount = 1;
    VkCommandBuffer cmd = VK_NULL_HANDLE;
    VK_CHECK(vkAllocateCommandBuffers(mDevice, &info, &cmd));
    return cmd;
}

void Context::freeCommandBuffer(VkCommandBuffer cmd) { vkFreeCommandBuffers(mDevice, mCommandPool, 1, &cmd); }

void Context::immediate(const std::function<void(VkCommandBuffer)>& record) {
    VkCommandBuffer cmd = allocateCommandBuffer();
    VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    VK_CHECK(vkBeginCommandBuffer(cmd, &begin));
    record(cmd);
    VK_CHECK(vkEndCommandBuffer(cmd));
    waitSerial(submit(cmd));
    freeCommandBuffer(cmd);
}

void Context::destroyLater(std::function<void()> destroy) {
    // Anything recorded so far may still use the object, so it lives until the latest
    // submission and the one being recorded now (serial + 1) have completed.
    mDeferred.push_back({mSubmitted + 1, std::move(destroy)});
}

void Context::collectGarbage() {
    pollFences();
    // A serial that was never submitted counts as complete only when the GPU is idle.
    uint64_t done = mPending.empty() ? mSubmitted + 1 : mCompleted;
    while (!mDeferred.empty() && mDeferred.front().serial <= done) {
        auto fn = std::move(mDeferred.front().destroy);
        mDeferred.pop_front();
        fn();
    }
}

} // namespace vitrine
