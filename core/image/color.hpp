#pragma once

#include "core/image/image.hpp"

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

namespace vitrine {

// Colour management through OpenColorIO. Every colour space, display and view name used by vitrine
// (JSON parameters, the CLI, image loading) is resolved against one of these configs. Names may be
// colour spaces, their aliases or roles ("scene_linear", "data").
//
// Thread safety: all member functions are const and may be called from several threads at once;
// OCIO caches processors inside the config.
class ColorConfig {
public:
    // Loads an OCIO v2 config file. UserError if the file is missing or OCIO rejects it.
    explicit ColorConfig(const std::filesystem::path& file);
    ~ColorConfig();
    ColorConfig(ColorConfig&&) noexcept;
    ColorConfig& operator=(ColorConfig&&) noexcept;
    ColorConfig(const ColorConfig&) = delete;
    ColorConfig& operator=(const ColorConfig&) = delete;

    // The config the renderer uses unless told otherwise: the file named by the environment
    // variable VITRINE_OCIO when it is set and not empty, else the shipped data/ocio/config.ocio.
    // Loaded once, on first use. OCIO's own $OCIO is deliberately ignored, so that an artist's
    // studio config never changes vitrine's images without the user asking for it.
    static const ColorConfig& builtin();

    const std::filesystem::path& file() const;

    // Names of all colour spaces (scene- and display-referred), in config order.
    std::vector<std::string> colorSpaces() const;
    // True for a colour space name, an alias or a role.
    bool hasColorSpace(const std::string& name) const;
    std::vector<std::string> displays() const;
    std::vector<std::string> views(const std::string& display) const;

    // Converts every pixel from colour space src to dst; alpha passes through. UserError when a
    // name is unknown.
    Image convert(const Image& image, const std::string& src, const std::string& dst) const;
    // In-place variant for the loaders, which own their pixels already.
    void convertInPlace(Image& image, const std::string& src, const std::string& dst) const;

    // Applies the display/view transform on the CPU: the reference for the GPU path and what
    // PNG writing uses. Output is display-encoded (not clamped); alpha passes through.
    Image toDisplay(const Image& image, const std::string& src = "scene_linear", const std::string& display = "sRGB",
                    const std::string& view = "Standard") const;

    // The same transform as toDisplay as GLSL source defining `vec4 functionName(vec4 inPixel)`.
    // It is self-contained (no textures, no uniforms) so it can be pasted after `#version 460`
    // into any shader stage. InternalError when OCIO needs LUT textures or uniforms for it, which
    // the GPU side cannot bind yet, or when functionName is not a GLSL identifier.
    std::string displayShaderGlsl(const std::string& src, const std::string& display, const std::string& view,
                                  const std::string& functionName) const;

private:
    struct Impl;
    std::unique_ptr<Impl> mImpl;
};

} // namespace vitrine
