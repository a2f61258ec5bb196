#pragma once

#include <vulkan/vulkan.h>

#include <string>
#include <string_view>
#include <vector>

namespace vitrine {

// The texture formats a graph may name. `name` is the JSON spelling.
struct FormatInfo {
    const char* name;
    VkFormat format;
    uint32_t bytesPerPixel;
    uint32_t channels;
    bool depth;
    bool srgb;
};

const std::vector<FormatInfo>& allFormats();
const FormatInfo* findFormat(std::string_view name);
const FormatInfo& formatInfo(VkFormat format); // throws InternalError for a format not in the table
std::string formatName(VkFormat format);

} // namespace vitrine
