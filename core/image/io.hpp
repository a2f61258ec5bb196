#pragma once

#include "core/image/color.hpp"
#include "core/image/image.hpp"

#include <filesystem>
#include <string>
#include <utility>
#include <vector>

// Image file I/O. Every function works in vitrine's working space (the config's scene_linear,
// linear Rec.709 in the shipped config) and reports bad files as UserError naming the file.
namespace vitrine {

// Loads .png/.jpg/.jpeg (8- or 16-bit, through stb_image), .hdr (Radiance, stb_image) or .exr
// (half/float/uint; the unnamed R,G,B,A/Y layer, else the first layer with R, G or B channels).
// Grey images are replicated to RGB; a missing alpha is 1.
//
// colorspace "auto": PNG/JPEG are taken as sRGB-encoded ("sRGB - Texture") and decoded to linear;
// .hdr/.exr are taken as scene-linear already. Any other string names a colour space (or role, or
// alias) of config, converted to scene_linear: "Raw" for normal maps and other data textures.
//
// UserError: missing, unreadable or truncated file, unknown extension, unknown colour space.
Image loadImage(const std::filesystem::path& path, const std::string& colorspace = "auto",
                const ColorConfig& config = ColorConfig::builtin());

// Loads one layer of an EXR file by name: "" is the unnamed R,G,B,A layer, "diffuse" reads the
// channels diffuse.R, diffuse.G, ... Channels are mapped to RGBA as R/G/B/A, else Y (grey), else
// X/Y/Z (vectors), else a single channel (grey); values are returned as stored (no colour
// conversion). UserError when the layer does not exist, naming the layers that do.
// Only the first part of a multi-part file is read.
Image loadExrLayer(const std::filesystem::path& path, const std::string& layer);

// Every layer of an EXR file, mapped as in loadExrLayer: the unnamed layer first (when present),
// then the named layers in OpenEXR's (alphabetical) channel order.
std::vector<std::pair<std::string, Image>> readExrLayers(const std::filesystem::path& path);

enum class ExrPixelType { Half, Float };

// One layer to write. The image is borrowed, not copied: it must outlive the writeExr call.
struct ExrLayer {
    std::string name; // "" writes channels R,G,B,A; "diffuse" writes diffuse.R, diffuse.G, ...
    const Image* image = nullptr;
};

// Writes a single-part, multi-layer scan-line EXR (the layout Nuke and Blender read), ZIP
// compressed, with Rec.709 chromaticities. Float keeps every value bit-exact; Half rounds to
// nearest and overflows to infinity above 65504. UserError when the layers differ in size, two
// share a name, or the file cannot be written.
void writeExr(const std::filesystem::path& path, const std::vector<ExrLayer>& layers, ExrPixelType type);
inline void writeExr(const std::filesystem::path& path, const Image& image, ExrPixelType type) {
    writeExr(path, {ExrLayer{"", &image}}, type);
}

// The 8-bit RGBA pixels (row-major, top row first) encodePng() writes: display/view of config on colour, alpha
// quantized as it is. The Python module's displayed images.
std::vector<unsigned char> displayBytes(const Image& linear, const ColorConfig& config = ColorConfig::builtin(),
                                        const std::string& display = "sRGB", const std::string& view = "Standard");

// Encodes a scene-linear image as an 8-bit RGBA PNG for viewing: applies display/view of config on
// the CPU, clamps to [0, 1] and rounds. Alpha stays linear (clamped). NaN becomes 0.
std::vector<unsigned char> encodePng(const Image& linear, const ColorConfig& config = ColorConfig::builtin(),
                                     const std::string& display = "sRGB", const std::string& view = "Standard");

// encodePng written to a file. UserError when the directory does not exist or the file cannot be
// written.
void writePng(const std::filesystem::path& path, const Image& linear,
              const ColorConfig& config = ColorConfig::builtin(), const std::string& display = "sRGB",
              const std::string& view = "Standard");

} // namespace vitrine
