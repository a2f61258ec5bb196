#include "core/image/io.hpp"

#include "core/base/error.hpp"
#include "core/image/io_detail.hpp"

#include <algorithm>
#include <cctype>
#include <optional>
#include <system_error>

namespace vitrine {

namespace {

enum class FileKind { Ldr, Hdr, Exr };

// What "auto" decodes 8- and 16-bit files from; the ACES studio configs use the same name.
const std::string kSrgbTexture = "sRGB - Texture";

std::optional<FileKind> kindOf(const std::filesystem::path& path) {
    std::string extension = path.extension().string();
    std::transform(extension.begin(), extension.end(), extension.begin(),
                   [](unsigned char c) { return std::tolower(c); });
    if (extension == ".png" || extension == ".jpg" || extension == ".jpeg") return FileKind::Ldr;
    if (extension == ".hdr") return FileKind::Hdr;
    if (extension == ".exr") return FileKind::Exr;
    return std::nullopt;
}

} // namespace

void detail::requireFile(const std::filesystem::path& path) {
    std::error_code error;
    if (!std::filesystem::exists(path, error)) throw UserError(path.string() + ": file not found");
    if (!std::filesystem::is_regular_file(path, error))
        throw UserError(path.string() + ": not a regular file; expected an image file");
}

void detail::requireParentDirectory(const std::filesystem::path& path) {
    const std::filesystem::path directory = path.parent_path();
    std::error_code error;
    if (!directory.empty() && !std::filesystem::is_directory(directory, error))
        throw UserError(path.string() + ": cannot write, directory '" + directory.string() + "' does not exist");
}

Image loadImage(const std::filesystem::path& path, const std::string& colorspace, const ColorConfig& config) {
    const std::optional<FileKind> kind = kindOf(path);
    if (!kind)
        throw UserError(path.string() + ": unknown image extension '" + path.extension().string() +
                        "'; expected .png, .jpg, .jpeg, .hdr or .exr");

    // Checked before decoding so that a typo fails fast, and with the file named.
    std::string source = colorspace;
    if (colorspace == "auto") source = *kind == FileKind::Ldr ? kSrgbTexture : "";
    if (!source.empty() && !config.hasColorSpace(source)) {
        std::string known;
        for (const std::string& name : config.colorSpaces())
            known += ", '" + name + "'";
        throw UserError(path.string() + ": unknown colour space '" + source + "' (OCIO config " +
                        config.file().string() + "); expected 'auto'" + known);
    }

    detail::requireFile(path);
    Image image;
    switch (*kind) {
    case FileKind::Ldr:
        image = detail::loadLdrImage(path);
        break;
    case FileKind::Hdr:
        image = detail::loadHdrImage(path);
        break;
    case FileKind::Exr:
        image = detail::loadExrDefaultLayer(path);
        break;
    }
    if (!source.empty()) config.convertInPlace(image, source, "scene_linear");
    return image;
}

} // namespace vitrine
