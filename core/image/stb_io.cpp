#include "core/image/io.hpp"

#include "core/base/atomic_file.hpp"
#include "core/base/error.hpp"
#include "core/image/io_detail.hpp"

// Declarations only: the implementations come from Debian's libstb.
#include <stb_image.h>
#include <stb_image_write.h>

#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <memory>

namespace vitrine {

namespace {

using StbPixels = std::unique_ptr<void, decltype(&stbi_image_free)>;

UserError decodeError(const std::filesystem::path& path, const char* format) {
    const char* reason = stbi_failure_reason();
    return UserError(path.string() + ": cannot decode as " + format + " (" + (reason ? reason : "unknown error") +
                     "); expected an intact " + format + " file");
}

template <typename Sample> Image toImage(const Sample* samples, int width, int height, float scale) {
    Image image(width, height);
    for (size_t i = 0; i < image.pixels.size(); ++i)
        image.pixels[i] = static_cast<float>(samples[i]) * scale;
    return image;
}

unsigned char quantize(float value) {
    if (!(value > 0.0f)) return 0; // also NaN
    if (value >= 1.0f) return 255;
    return static_cast<unsigned char>(std::lround(value * 255.0f));
}

} // namespace

Image detail::loadLdrImage(const std::filesystem::path& path) {
    const std::string file = path.string();
    int width = 0;
    int height = 0;
    int channels = 0;
    // Four channels requested: stb replicates grey to RGB and fills a missing alpha with opaque.
    if (stbi_is_16_bit(file.c_str())) {
        StbPixels data(stbi_load_16(file.c_str(), &width, &height, &channels, 4), &stbi_image_free);
        if (!data) throw decodeError(path, "16-bit PNG");
        return toImage(static_cast<const stbi_us*>(data.get()), width, height, 1.0f / 65535.0f);
    }
    StbPixels data(stbi_load(file.c_str(), &width, &height, &channels, 4), &stbi_image_free);
    if (!data) throw decodeError(path, "PNG/JPEG");
    return toImage(static_cast<const stbi_uc*>(data.get()), width, height, 1.0f / 255.0f);
}

Image detail::loadHdrImage(const std::filesystem::path& path) {
    const std::string file = path.string();
    // stbi_loadf would happily load a PNG renamed to .hdr and gamma-decode it: refuse instead.
    if (!stbi_is_hdr(file.c_str()))
        throw UserError(file + ": not a Radiance RGBE file; expected a .hdr file starting with '#?RADIANCE'");
    int width = 0;
    int height = 0;
    int channels = 0;
    StbPixels data(stbi_loadf(file.c_str(), &width, &height, &channels, 4), &stbi_image_free);
    if (!data) throw decodeError(path, "Radiance HDR");
    return toImage(static_cast<const float*>(data.get()), width, height, 1.0f);
}

std::vector<unsigned char> displayBytes(const Image& linear, const ColorConfig& config, const std::string& display,
                                        const std::string& view) {
    const Image encoded = config.toDisplay(linear, "scene_linear", display, view);
    std::vector<unsigned char> bytes(linear.pixels.size());
    for (size_t i = 0; i < bytes.size(); ++i) {
        const bool alpha = i % 4 == 3; // alpha is coverage, not colour: it never goes through the display curve
        bytes[i] = quantize(alpha ? linear.pixels[i] : encoded.pixels[i]);
    }
    return bytes;
}

std::vector<unsigned char> encodePng(const Image& linear, const ColorConfig& config, const std::string& display,
                                     const std::string& view) {
    if (linear.empty()) throw InternalError("encodePng: the image is empty");
    const std::vector<unsigned char> bytes = displayBytes(linear, config, display, view);

    std::vector<unsigned char> png;
    auto append = [](void* context, void* data, int size) {
        auto* out = static_cast<std::vector<unsigned char>*>(context);
        out->insert(out->end(), static_cast<unsigned char*>(data), static_cast<unsigned char*>(data) + size);
    };
    if (!stbi_write_png_to_func(append, &png, linear.width, linear.height, 4, bytes.data(), linear.width * 4))
        throw InternalError("encodePng: stb_image_write failed for a " + std::to_string(linear.width) + "x" +
                            std::to_string(linear.height) + " image");
    return png;
}

void writePng(const std::filesystem::path& path, const Image& linear, const ColorConfig& config,
              const std::string& display, const std::string& view) {
    detail::requireParentDirectory(path);
    const std::vector<unsigned char> png = encodePng(linear, config, display, view);
    writeFileAtomically(path, std::string_view(reinterpret_cast<const char*>(png.data()), png.size()));
}

} // namespace vitrine
