// ibl.environment: the sky as one distant probe for split-sum IBL [Karis13]: its cube map prefiltered with the GGX
// lobe of each mip's roughness (shaders/ibl/prefilter.comp, as ibl.capture prefilters the probes) and the split-sum
// BRDF LUT (shaders/ibl/brdf_lut.comp). lighting.deferred and forward.transparent read a `sky` with mips as such a
// chain (shaders/lighting/ambient.glsl), and lighting.deferred weighs it by the LUT when `brdf_lut` is connected.
#include "nodes/ibl/cube_mips.hpp"

#include "core/base/error.hpp"
#include "core/gpu/context.hpp"
#include "core/gpu/descriptors.hpp"
#include "core/gpu/transfer.hpp"
#include "core/graph/node.hpp"
#include "core/graph/registry.hpp"
#include "core/shading/cubemap.hpp"
#include "core/shading/sh.hpp"
#include "shaders/ibl/capture.h"
#include "shaders/sky/sky.h"

#include <array>
#include <bit>
#include <cmath>

namespace vitrine {
namespace {

NodeSchema schema() {
    NodeSchema s;
    s.type = "ibl.environment";
    s.doc = "The sky as a distant environment for split-sum IBL [Karis13] (MUSEUM_SPEC §4 for the sky): mip m of "
            "`cubemap` is the sky convolved with the GGX lobe of roughness m / (mips - 1) by filtered importance "
            "sampling (mip 0 the sky itself, sun disk included), mips 1 and up without the sun's disk (the sun is lit "
            "analytically, so a rough lobe must not reflect it again); `brdf_lut` is the split-sum BRDF LUT. Connect "
            "`cubemap` to lighting.deferred's and forward.transparent's `sky` (a sky with mips is read at the mip of "
            "the surface's roughness) and `brdf_lut` to lighting.deferred's. Computed on the first frame.";
    auto tex = [](const char* name, const char* doc) {
        return InputPort{name, PortKind::Texture, {}, false, Usage::Sampled, doc, true};
    };
    s.inputs = {
        tex("sky", "A sky node's cube map (sky.procedural, sky.hdri: 6 layers, faces of a power-of-two size)"),
        tex("sky_sh", "The same sky node's `sh`: the sun's direction and angular radius (its disk is left out of mips "
                      "1 and up, filled with the SH radiance there)"),
    };
    OutputPort cube;
    cube.name = "cubemap";
    // Half floats: filtered linearly, between mips too, where lavapipe does not filter RGBA32F (the sky node's
    // cube is read with the nearest texel there); clamped at the largest half, above what its readers keep.
    cube.format = VK_FORMAT_R16G16B16A16_SFLOAT;
    cube.size = SizeRule::absolute(64, 64);
    cube.persistent = true;
    cube.readBack = true;
    cube.doc = "Prefiltered sky radiance (cd/m², RGBA16F cube map, clamped at 65504): mip m is GGX roughness "
               "m / (mips - 1) (shaders/ibl/ibl_common.glsl), mip 0 the sky as given";
    OutputPort lut;
    lut.name = "brdf_lut";
    lut.format = VK_FORMAT_R32G32_SFLOAT;
    lut.size = SizeRule::absolute(64, 64);
    lut.persistent = true;
    lut.doc = "Split-sum BRDF LUT: texel (NoV, roughness) = (A, B), specular albedo f0 A + f90 B (ibl_common.glsl)";
    s.outputs = {cube, lut};
    s.params = {
        {"mips", ParamType::Int, 0, 0.0, 12.0, {}, "Mip levels (roughness steps); 0: down to 1x1"},
        {"samples", ParamType::Int, 512, 1.0, 4096.0, {}, "GGX samples per prefiltered texel"},
        {"lut_size", ParamType::Int, 64, 8.0, 1024.0, {}, "BRDF LUT size (lut_size x lut_size)"},
        {"lut_samples", ParamType::Int, 4096, 16.0, 16384.0, {}, "GGX samples per LUT texel"},
    };
    return s;
}

class Environment final : public Node {
public:
    void setup(SetupContext& ctx) override {
        const Params& p = ctx.params();
        const ImageDesc& sky = ctx.input("sky");
        if (!sky.cube || sky.layers != 6)
            throw UserError("ibl.environment: input 'sky' must be a cube map (6 layers), got " +
                            std::to_string(sky.layers) + " layer(s)");
        mSize = sky.width;
        if (!std::has_single_bit(mSize))
            throw UserError("ibl.environment: input 'sky' must have faces of a power-of-two size (its mip chain is "
                            "box-filtered), got " +
                            std::to_string(mSize));
        const uint32_t fullChain = std::bit_width(mSize);
        mMips = p.getInt("mips") ? static_cast<uint32_t>(p.getInt("mips")) : fullChain;
        if (mMips > fullChain)
            ctx.failParam("mips", "at most " + std::to_string(fullChain) + " mips for a sky of " +
                                      std::to_string(mSize) + "² faces, got " + std::to_string(mMips));
        ImageDesc& cube = ctx.output("cubemap");
        cube.width = cube.height = mSize;
        cube.mipLevels = mMips;
        cube.layers = 6;
        cube.cube = true;
        mLutSize = static_cast<uint32_t>(p.getInt("lut_size"));
        ImageDesc& lut = ctx.output("brdf_lut");
        lut.width = lut.height = mLutSize;
        mSamples = static_cast<uint32_t>(p.getInt("samples"));
        mLutSamples = static_cast<uint32_t>(p.getInt("lut_samples"));
        mLutPipeline = ctx.computePipeline("ibl/brdf_lut.comp");
        mPrefilterPipeline = ctx.computePipeline("ibl/prefilter.comp", {{"PREFILTER_CLAMP_TO_HALF", "1"}}, 1);
    }

    void execute(ExecuteContext& ctx) override {
        if (mDone) return; // persistent outputs: one prefilter serves every frame
        gpu_types::IblBrdfLutPush lut{mLutSize, mLutSamples, 0, 0};
        ctx.dispatch(mLutPipeline, &lut, sizeof(lut), mLutSize, mLutSize);

        // Run what was recorded so far (the sky), so its faces can be read back.
        ctx.splitSubmission();
        std::vector<Image> faces;
        for (uint32_t f = 0; f < 6; ++f)
            faces.push_back(readImage(ctx.gpu(), ctx.input("sky"), VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, 0, f));
        const Image sh = readImage(ctx.gpu(), ctx.input("sky_sh"), VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);

        ImageDesc d;
        d.width = d.height = mSize;
        d.layers = 6;
        d.cube = true;
        d.cubeArray = true; // prefilter.comp reads a cube-map array
        d.format = VK_FORMAT_R32G32B32A32_SFLOAT;
        d.usage = VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT;
        mWithSun = GpuImage(ctx.gpu(), d, "ibl.environment.sky");
        uploadCubeMips(ctx.gpu(), mWithSun, {faces});
        const uint32_t sourceMips = std::bit_width(mSize);
        d.mipLevels = sourceMips;
        mSource = GpuImage(ctx.gpu(), d, "ibl.environment.source");
        removeSun(faces, sh);
        uploadCubeMips(ctx.gpu(), mSource, boxMips(std::move(faces), sourceMips));

        resetPrefilterSets(ctx.gpu(), mSets, "ibl.environment.prefilter");
        const std::array<VkDescriptorSetLayout, 1> layouts = {mSets.layout()};
        for (uint32_t m = 0; m < mMips; ++m) {
            // Mip 0 is the mirror: the sky as given, its sun disk with it (what a mirror shows, as without mips).
            const VkDescriptorSet set = prefilterMipSet(ctx.gpu(), mSets, (m == 0 ? mWithSun : mSource).view(),
                                                        ctx.output("cubemap").mipView(m));
            gpu_types::IblPrefilterPush push{};
            push.size = mSize >> m;
            push.layers = 6;
            push.samples = mSamples;
            push.sourceSize = mSize;
            push.roughness = mMips > 1 ? float(m) / float(mMips - 1) : 0.0f;
            push.sourceMips = float(m == 0 ? 1 : sourceMips);
            ctx.dispatchWithSets(mPrefilterPipeline, &push, sizeof(push), push.size, push.size * 6, layouts,
                                 std::array<VkDescriptorSet, 1>{set});
        }
        mDone = true;
    }

    void releaseGpu() override {
        mDone = false;
        mSets = DescriptorSets();
        mSource = GpuImage();
        mWithSun = GpuImage();
    }

private:
    // The sun is lit analytically (lighting.deferred's sun, the path tracer's next-event estimation); its disk in the
    // cube map would be reflected a second time by every rough lobe. Texels within its angular radius plus three
    // texels (as sky.procedural draws it) take the SH radiance there, the sky without the sun.
    void removeSun(std::vector<Image>& faces, const Image& sh) const {
        const float* info = sh.at(SKY_TEXEL_SUN_INFO, 0);
        const float* dir = sh.at(SKY_TEXEL_SUN_DIRECTION, 0);
        const glm::dvec3 toSun(dir[0], dir[1], dir[2]);
        if (glm::length(toSun) < 0.5 || info[1] <= 0.0f) return; // no sun
        shading::Sh9 coefficients;
        for (int i = 0; i < 9; ++i)
            coefficients.c[i] = glm::dvec3(sh.at(i, 0)[0], sh.at(i, 0)[1], sh.at(i, 0)[2]);
        const double cutoff = std::cos(double(info[1]) + 3.0 / double(mSize));
        const glm::dvec3 sun = glm::normalize(toSun);
        for (int f = 0; f < 6; ++f)
            for (int y = 0; y < int(mSize); ++y)
                for (int x = 0; x < int(mSize); ++x) {
                    const glm::dvec3 d = shading::cubeTexelDirection(f, x, y, int(mSize));
                    if (glm::dot(d, sun) < cutoff) continue;
                    const glm::dvec3 l = glm::max(shading::shRadiance(coefficients, d), glm::dvec3(0.0));
                    float* t = faces[f].at(x, y);
                    t[0] = float(l.x), t[1] = float(l.y), t[2] = float(l.z);
                }
    }

    uint32_t mSize = 64, mMips = 7, mLutSize = 64, mSamples = 512, mLutSamples = 4096;
    bool mDone = false;
    PipelineId mLutPipeline = 0, mPrefilterPipeline = 0;
    DescriptorSets mSets;
    GpuImage mSource, mWithSun;
};

const NodeRegistration kRegistration(schema(), [] { return std::make_unique<Environment>(); });

} // namespace
} // namespace vitrine
