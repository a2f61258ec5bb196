#include "core/gpu/formats.hpp"

#include "core/base/error.hpp"

namespace vitrine {

const std::vector<FormatInfo>& allFormats() {
    static const std::vector<FormatInfo> kFormats = {
        {"rgba8", VK_FORMAT_R8G8B8A8_UNORM, 4, 4, false, false},
        {"rgba8_srgb", VK_FORMAT_R8G8B8A8_SRGB, 4, 4, false, true},
        {"r8", VK_FORMAT_R8_UNORM, 1, 1, false, false},
        {"rg8", VK_FORMAT_R8G8_UNORM, 2, 2, false, false},
        {"r16", VK_FORMAT_R16_UNORM, 2, 1, false, false},
        {"rg16", VK_FORMAT_R16G16_UNORM, 4, 2, false, false},
        {"r16f", VK_FORMAT_R16_SFLOAT, 2, 1, false, false},
        {"rg16f", VK_FORMAT_R16G16_SFLOAT, 4, 2, false, false},
        {"rgba16f", VK_FORMAT_R16G16B16A16_SFLOAT, 8, 4, false, false},
        {"r32f", VK_FORMAT_R32_SFLOAT, 4, 1, false, false},
        {"rg32f", VK_FORMAT_R32G32_SFLOAT, 8, 2, false, false},
        {"rgba32f", VK_FORMAT_R32G32B32A32_SFLOAT, 16, 4, false, false},
        {"r11g11b10f", VK_FORMAT_B10G11R11_UFLOAT_PACK32, 4, 3, false, false},
        {"rgb9e5", VK_FORMAT_E5B9G9R9_UFLOAT_PACK32, 4, 3, false, false},
        {"d32f", VK_FORMAT_D32_SFLOAT, 4, 1, true, false},
        {"r32ui", VK_FORMAT_R32_UINT, 4, 1, false, false}, // counters and bit masks (image atomics); read back as floats
    };
    return kFormats;
}

const FormatInfo* findFormat(std::string_view name) {
    for (const auto& f : allFormats())
        if (name == f.name) return &f;
    return nullptr;
}

const FormatInfo& formatInfo(VkFormat format) {
    for (const auto& f : allFormats())
        if (f.format == format) return f;
    throw InternalError("VkFormat " + std::to_string(static_cast<int>(format)) + " is not in vitrine's format table");
}

std::string formatName(VkFormat format) {
    for (const auto& f : allFormats())
        if (f.format == format) return f.name;
    return "VkFormat(" + std::to_string(static_cast<int>(format)) + ")";
}

} // namespace vitrine
