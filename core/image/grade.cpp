#include "core/image/grade.hpp"

#include "core/base/error.hpp"
#include "core/image/color.hpp"

#include <OpenColorIO/OpenColorIO.h>

namespace OCIO = OCIO_NAMESPACE;

namespace vitrine {

namespace {
// As in color.cpp: exact pow/log/exp on the CPU, the reference the GPU is compared with.
constexpr OCIO::OptimizationFlags kOptimization = OCIO::OPTIMIZATION_LOSSLESS;
} // namespace

struct Grade::Impl {
    OCIO::ConstProcessorRcPtr processor;
};

Grade::Grade(const ColorConfig& config, const GradeSettings& s) : mImpl(std::make_unique<Impl>()) {
    for (const auto& [what, name] : {std::pair{"source", s.source}, std::pair{"working", s.working}})
        if (!config.hasColorSpace(name))
            throw UserError(std::string(what) + ": no colour space '" + name + "' in " + config.file().string());
    OCIO::ConstConfigRcPtr ocio;
    try {
        ocio = OCIO::Config::CreateFromFile(config.file().string().c_str());
    } catch (const OCIO::Exception& e) {
        throw UserError(config.file().string() + ": " + e.what());
    }
    auto group = OCIO::GroupTransform::Create();

    auto ec = OCIO::ExposureContrastTransform::Create();
    ec->setStyle(OCIO::EXPOSURE_CONTRAST_LINEAR);
    ec->setExposure(s.exposure);
    ec->setContrast(s.contrast);
    ec->setPivot(s.pivot);
    group->appendTransform(ec);

    auto toWorking = OCIO::ColorSpaceTransform::Create();
    toWorking->setSrc(s.source.c_str());
    toWorking->setDst(s.working.c_str());
    group->appendTransform(toWorking);

    auto cdl = OCIO::CDLTransform::Create();
    const double slope[3] = {s.slope.r, s.slope.g, s.slope.b};
    const double offset[3] = {s.offset.r, s.offset.g, s.offset.b};
    const double power[3] = {s.power.r, s.power.g, s.power.b};
    cdl->setSlope(slope);
    cdl->setOffset(offset);
    cdl->setPower(power);
    cdl->setSat(s.saturation);
    cdl->setStyle(s.cdlClamp ? OCIO::CDL_ASC : OCIO::CDL_NO_CLAMP);
    group->appendTransform(cdl);

    if (!s.lut.empty()) {
        if (!std::filesystem::is_regular_file(s.lut)) throw UserError("lut: no LUT file " + s.lut.string());
        auto file = OCIO::FileTransform::Create();
        // Absolute: OCIO resolves a relative path against the config's search path, not the working directory.
        file->setSrc(std::filesystem::absolute(s.lut).string().c_str());
        file->setInterpolation(s.lutTetrahedral ? OCIO::INTERP_TETRAHEDRAL : OCIO::INTERP_LINEAR);
        file->setDirection(OCIO::TRANSFORM_DIR_FORWARD);
        group->appendTransform(file);
    }

    auto back = OCIO::ColorSpaceTransform::Create();
    back->setSrc(s.working.c_str());
    back->setDst(s.source.c_str());
    group->appendTransform(back);

    try {
        mImpl->processor = ocio->getProcessor(group);
    } catch (const OCIO::Exception& e) {
        throw UserError((s.lut.empty() ? std::string("grade") : "lut: " + s.lut.string()) +
                        ": OpenColorIO cannot build the grade: " + e.what());
    }
}

Grade::~Grade() = default;
Grade::Grade(Grade&&) noexcept = default;
Grade& Grade::operator=(Grade&&) noexcept = default;

void Grade::apply(Image& image) const {
    if (image.empty()) return;
    OCIO::PackedImageDesc desc(image.pixels.data(), image.width, image.height, 4);
    mImpl->processor->getOptimizedCPUProcessor(kOptimization)->apply(desc);
}

GradeShader Grade::shader(const std::string& functionName) const {
    OCIO::GpuShaderDescRcPtr desc = OCIO::GpuShaderDesc::CreateShaderDesc();
    desc->setLanguage(OCIO::GPU_LANGUAGE_GLSL_4_0);
    desc->setFunctionName(functionName.c_str());
    desc->setResourcePrefix((functionName + "_").c_str());
    mImpl->processor->getOptimizedGPUProcessor(kOptimization)->extractGpuShaderInfo(desc);
    if (desc->getNumTextures() > 0)
        throw UserError("lut: the grade needs " + std::to_string(desc->getNumTextures()) +
                        " 1D LUT texture(s) on the GPU, which color.grade does not bind; use a 3D LUT");
    if (desc->getNumUniforms() > 0) throw InternalError("color.grade: OCIO asks for uniforms (dynamic properties)");
    GradeShader out;
    out.glsl = desc->getShaderText();
    for (unsigned i = 0; i < desc->getNum3DTextures(); ++i) {
        const char* texture = nullptr;
        const char* sampler = nullptr;
        unsigned edge = 0;
        OCIO::Interpolation interpolation = OCIO::INTERP_LINEAR;
        desc->get3DTexture(i, texture, sampler, edge, interpolation);
        const float* values = nullptr;
        desc->get3DTextureValues(i, values);
        GradeLut3d lut;
        lut.samplerName = sampler;
        lut.edge = edge;
        lut.linear = interpolation != OCIO::INTERP_NEAREST;
        lut.rgb.assign(values, values + size_t(edge) * edge * edge * 3);
        out.luts.push_back(std::move(lut));
    }
    return out;
}

} // namespace vitrine
