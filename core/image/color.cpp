#include "core/image/color.hpp"

#include "core/base/error.hpp"
#include "core/base/paths.hpp"

#include <OpenColorIO/OpenColorIO.h>

#include <algorithm>
#include <cstdlib>
#include <regex>


namespace OCIO = OCIO_NAMESPACE;

namespace vitrine {

namespace {

std::string quotedList(const std::vector<std::string>& names) {
    std::string text;
    for (const std::string& name : names) {
        text += text.empty() ? "" : ", ";
        text += "'" + name + "'";
    }
    return text;
}

// The default level lets OCIO replace pow/log/exp by fast approximations (OPTIMIZATION_FAST_LOG_EXP_POW,
// in SSE builds). The CPU path is the reference the GPU shader (real pow()) is compared with: keep it exact.
constexpr OCIO::OptimizationFlags kOptimization = OCIO::OPTIMIZATION_LOSSLESS;

void applyCpu(const OCIO::ConstProcessorRcPtr& processor, Image& image) {
    if (image.empty() || processor->isNoOp()) return;
    OCIO::PackedImageDesc desc(image.pixels.data(), image.width, image.height, 4);
    processor->getOptimizedCPUProcessor(kOptimization)->apply(desc);
}

} // namespace

struct ColorConfig::Impl {
    std::filesystem::path file;
    OCIO::ConstConfigRcPtr config;

    void requireColorSpace(const std::string& name) const {
        if (config->getColorSpace(name.c_str())) return;
        std::vector<std::string> names;
        for (int i = 0; i < config->getNumColorSpaces(); ++i)
            names.emplace_back(config->getColorSpaceNameByIndex(i));
        throw UserError(file.string() + ": unknown colour space '" + name + "'; expected one of " + quotedList(names) +
                        " or a role such as 'scene_linear'");
    }

    void requireDisplayView(const std::string& display, const std::string& view) const {
        std::vector<std::string> displays;
        for (int i = 0; i < config->getNumDisplays(); ++i)
            displays.emplace_back(config->getDisplay(i));
        if (std::find(displays.begin(), displays.end(), display) == displays.end())
            throw UserError(file.string() + ": unknown display '" + display + "'; expected one of " +
                            quotedList(displays));
        std::vector<std::string> views;
        for (int i = 0; i < config->getNumViews(display.c_str()); ++i)
            views.emplace_back(config->getView(display.c_str(), i));
        if (std::find(views.begin(), views.end(), view) == views.end())
            throw UserError(file.string() + ": display '" + display + "' has no view '" + view + "'; expected one of " +
                            quotedList(views));
    }

    OCIO::ConstProcessorRcPtr displayProcessor(const std::string& src, const std::string& display,
                                               const std::string& view) const {
        requireColorSpace(src);
        requireDisplayView(display, view);
        try {
            return config->getProcessor(src.c_str(), display.c_str(), view.c_str(), OCIO::TRANSFORM_DIR_FORWARD);
        } catch (const OCIO::Exception& e) {
            throw UserError(file.string() + ": cannot build the transform from '" + src + "' to display '" + display +
                            "', view '" + view + "': " + e.what());
        }
    }
};

ColorConfig::ColorConfig(const std::filesystem::path& file) : mImpl(std::make_unique<Impl>()) {
    mImpl->file = file;
    if (!std::filesystem::is_regular_file(file))
        throw UserError(file.string() + ": OCIO config file not found; expected an OpenColorIO v2 config");
    try {
        mImpl->config = OCIO::Config::CreateFromFile(file.string().c_str());
        mImpl->config->validate();
    } catch (const OCIO::Exception& e) {
        throw UserError(file.string() + ": not a valid OpenColorIO config: " + e.what());
    }
}

ColorConfig::~ColorConfig() = default;
ColorConfig::ColorConfig(ColorConfig&&) noexcept = default;
ColorConfig& ColorConfig::operator=(ColorConfig&&) noexcept = default;

const ColorConfig& ColorConfig::builtin() {
    static const ColorConfig config([] {
        const char* override = std::getenv("VITRINE_OCIO");
        if (override && *override) return std::filesystem::path(override);
        return dataDir() / "ocio" / "config.ocio";
    }());
    return config;
}

const std::filesystem::path& ColorConfig::file() const {
    return mImpl->file;
}

std::vector<std::string> ColorConfig::colorSpaces() const {
    std::vector<std::string> names;
    const OCIO::ConstConfigRcPtr& config = mImpl->config;
    for (int i = 0; i < config->getNumColorSpaces(); ++i)
        names.emplace_back(config->getColorSpaceNameByIndex(i));
    return names;
}

bool ColorConfig::hasColorSpace(const std::string& name) const {
    return mImpl->config->getColorSpace(name.c_str()) != nullptr;
}

std::vector<std::string> ColorConfig::displays() const {
    std::vector<std::string> names;
    for (int i = 0; i < mImpl->config->getNumDisplays(); ++i)
        names.emplace_back(mImpl->config->getDisplay(i));
    return names;
}

std::vector<std::string> ColorConfig::views(const std::string& display) const {
    std::vector<std::string> names;
    for (int i = 0; i < mImpl->config->getNumViews(display.c_str()); ++i)
        names.emplace_back(mImpl->config->getView(display.c_str(), i));
    return names;
}

Image ColorConfig::convert(const Image& image, const std::string& src, const std::string& dst) const {
    Image result = image;
    convertInPlace(result, src, dst);
    return result;
}

void ColorConfig::convertInPlace(Image& image, const std::string& src, const std::string& dst) const {
    mImpl->requireColorSpace(src);
    mImpl->requireColorSpace(dst);
    OCIO::ConstProcessorRcPtr processor;
    try {
        processor = mImpl->config->getProcessor(src.c_str(), dst.c_str());
    } catch (const OCIO::Exception& e) {
        throw UserError(mImpl->file.string() + ": cannot convert from '" + src + "' to '" + dst + "': " + e.what());
    }
    applyCpu(processor, image);
}

Image ColorConfig::toDisplay(const Image& image, const std::string& src, const std::string& display,
                             const std::string& view) const {
    Image result = image;
    applyCpu(mImpl->displayProcessor(src, display, view), result);
    return result;
}

std::string ColorConfig::displayShaderGlsl(const std::string& src, const std::string& display, const std::string& view,
                                           const std::string& functionName) const {
    static const std::regex kIdentifier("[A-Za-z_][A-Za-z0-9_]*");
    if (!std::regex_match(functionName, kIdentifier) || functionName.starts_with("gl_"))
        throw InternalError("displayShaderGlsl: '" + functionName + "' is not a valid GLSL function name");

    OCIO::GpuShaderDescRcPtr desc = OCIO::GpuShaderDesc::CreateShaderDesc();
    desc->setLanguage(OCIO::GPU_LANGUAGE_GLSL_4_0);
    desc->setFunctionName(functionName.c_str());
    // A per-function prefix keeps helper names apart when one shader pastes several transforms.
    desc->setResourcePrefix((functionName + "_").c_str());
    mImpl->displayProcessor(src, display, view)->getOptimizedGPUProcessor(kOptimization)->extractGpuShaderInfo(desc);

    const std::string what =
        "'" + src + "' to display '" + display + "', view '" + view + "' of " + mImpl->file.string();
    if (desc->getNumTextures() > 0 || desc->getNum3DTextures() > 0)
        throw InternalError("displayShaderGlsl: OCIO needs LUT textures for " + what +
                            "; the GPU display pass cannot bind them yet");
    if (desc->getNumUniforms() > 0)
        throw InternalError("displayShaderGlsl: OCIO needs uniforms (dynamic properties) for " + what +
                            "; the GPU display pass cannot bind them yet");
    return desc->getShaderText();
}

} // namespace vitrine
