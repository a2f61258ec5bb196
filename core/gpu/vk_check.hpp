#pragma once

#include <vulkan/vulkan.h>

#include <string>

namespace vitrine {

const char* vkResultName(VkResult result);
[[noreturn]] void throwVkError(VkResult result, const char* expression, const char* file, int line);

} // namespace vitrine

// Every Vulkan call that returns a VkResult goes through this; a failure names the call, the
// file and the line, and becomes an InternalError (exit status 2 in the CLI).
#define VK_CHECK(expr)                                                                                                 \
    do {                                                                                                               \
        VkResult vkCheckResult_ = (expr);                                                                              \
        if (vkCheckResult_ < 0) ::vitrine::throwVkError(vkCheckResult_, #expr, __FILE__, __LINE__);                   \
    } while (0)
