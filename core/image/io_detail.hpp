#pragma once

#include "core/image/image.hpp"

#include <filesystem>

// Internal to core/image: the per-format loaders behind loadImage, and shared file checks.
namespace vitrine::detail {

// UserError unless path names an existing regular file.
void requireFile(const std::filesystem::path& path);
// UserError unless the directory that would hold path exists.
void requireParentDirectory(const std::filesystem::path& path);

// 8- or 16-bit PNG/JPEG through stb_image, values as stored (no colour conversion).
Image loadLdrImage(const std::filesystem::path& path);
// Radiance RGBE through stb_image.
Image loadHdrImage(const std::filesystem::path& path);
// The layer loadImage picks from an EXR file: the unnamed one, else the first with colour channels.
Image loadExrDefaultLayer(const std::filesystem::path& path);

} // namespace vitrine::detail
