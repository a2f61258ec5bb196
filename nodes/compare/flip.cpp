// compare.flip: the LDR-FLIP error map of two display-referred images, on the GPU.
#include "shaders/compare/flip.h"
#include "core/base/error.hpp"
#include "core/compare/flip_kernels.hpp"
#include "core/compare/metrics.hpp"
#include "core/graph/node.hpp"
#include "core/graph/registry.hpp"

#include <cstdio>
#include <string>

namespace vitrine {
namespace {

NodeSchema schema() {
    NodeSchema s;
    s.type = "compare.flip";
    s.doc = "LDR-FLIP (HPG 2020) per pixel: the same colour (CSF, Hunt, HyAB) and feature (edges, points) pipeline "
            "and kernels as the CPU metric of `vitrine compare`. Inputs are tone-mapped linear RGB in [0, 1].";
    s.inputs = {{"reference", PortKind::Texture, {}, false, Usage::Sampled, "Reference image (display-referred)"},
                {"test",
                 PortKind::Texture,
                 {},
                 false,
                 Usage::Sampled,
                 "Test image (nearest texel at the same relative position when sizes differ)"}};
    OutputPort error;
    error.name = "error";
    error.format = VK_FORMAT_R32G32B32A32_SFLOAT;
    error.size = SizeRule::ofInput("reference");
    error.doc = "FLIP error in [0, 1] in R, G and B; alpha 1";
    OutputPort color;
    color.name = "color";
    color.format = VK_FORMAT_R16G16B16A16_SFLOAT;
    color.size = SizeRule::ofInput("reference");
    color.doc = "The error through the magma colour map (linear RGB), as the FLIP paper shows it";
    s.outputs = {error, color};
    s.params = {
        {"pixels_per_degree",
         ParamType::Float,
         compare::kDefaultPixelsPerDegree,
         1.0,
         200.0,
         {},
         "Viewing condition: pixels per degree of visual angle (67: a 0.7 m 4K monitor at 0.7 m)"},
    };
    return s;
}

std::string glslArray(const compare::detail::Kernel& kernel) {
    std::string s = "float[](";
    char buffer[32];
    for (size_t i = 0; i < kernel.size(); ++i) {
        std::snprintf(buffer, sizeof buffer, "%s%.9g", i ? ", " : "", kernel[i]);
        s += buffer;
    }
    return s + ")";
}

class Flip final : public Node {
public:
    void setup(SetupContext& ctx) override {
        const compare::detail::FlipKernels k = compare::detail::makeKernels(ctx.params().getFloat("pixels_per_degree"));
        // The shader is written for the paper's CSFs: one Gaussian for Y and Cx, two for Cz, and feature kernels no
        // wider than the CSF's.
        if (k.csf[0].size() != 1 || k.csf[1].size() != 1 || k.csf[2].size() != 2 ||
            k.featureGauss.size() > k.csf[0][0].kernel.size())
            throw InternalError("compare.flip: the FLIP kernels no longer have the shape flip.comp expects");
        mWeights = glm::vec4(k.csf[0][0].weight, k.csf[1][0].weight, k.csf[2][0].weight, k.csf[2][1].weight);
        const ShaderDefines defines = {
            {"FLIP_CSF_RADIUS", std::to_string(k.csf[0][0].kernel.size() / 2)},
            {"FLIP_FEATURE_RADIUS", std::to_string(k.featureGauss.size() / 2)},
            {"FLIP_KERNEL_Y", glslArray(k.csf[0][0].kernel)},
            {"FLIP_KERNEL_CX", glslArray(k.csf[1][0].kernel)},
            {"FLIP_KERNEL_CZ0", glslArray(k.csf[2][0].kernel)},
            {"FLIP_KERNEL_CZ1", glslArray(k.csf[2][1].kernel)},
            {"FLIP_KERNEL_GAUSS", glslArray(k.featureGauss)},
            {"FLIP_KERNEL_EDGE", glslArray(k.edge)},
            {"FLIP_KERNEL_POINT", glslArray(k.point)},
        };
        mPipeline = ctx.computePipeline("compare/flip.comp", defines);
    }
    void execute(ExecuteContext& ctx) override {
        gpu_types::FlipPush push{};
        push.csfWeights = mWeights;
        const ImageDesc& out = ctx.output("error").desc();
        ctx.dispatch(mPipeline, push, out.width, out.height);
    }

private:
    PipelineId mPipeline = 0;
    glm::vec4 mWeights{0.0f};
};

const NodeRegistration kRegistration(schema(), [] { return std::make_unique<Flip>(); });

} // namespace
} // namespace vitrine
