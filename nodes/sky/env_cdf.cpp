// sky.env_cdf: the luminance CDF of a sky cube map, for importance-sampling the sky as a light
// (render.pathtrace; shaders/pathtrace/sampling.glsl reads it).
#include "core/graph/node.hpp"
#include "core/graph/registry.hpp"

#include <string>

namespace vitrine {
namespace {

constexpr uint32_t kMaxFaceSize = 512; // shaders/sky/env_cdf.comp keeps 6 x 512 row totals in shared memory

NodeSchema schema() {
    NodeSchema s;
    s.type = "sky.env_cdf";
    s.doc = "Importance-sampling table of a sky cube map: texels weighted by luminance x solid angle, a CDF per "
            "texel row and one over the rows (layout in shaders/sky/env_cdf.comp). Rebuilt every frame on the GPU "
            "(one workgroup; a 64² cube takes a few ms on lavapipe), so it follows a sky that changes.";
    s.inputs = {{"sky",
                 PortKind::Texture,
                 {VK_FORMAT_R32G32B32A32_SFLOAT, VK_FORMAT_R16G16B16A16_SFLOAT},
                 false,
                 Usage::Sampled,
                 "A sky node's cube map (cd/m²)"}};
    OutputPort cdf;
    cdf.name = "cdf";
    cdf.format = VK_FORMAT_R32_SFLOAT;
    cdf.size = SizeRule::absolute(1, 1); // (N + 1) x (6N + 1), set in setup() from the cube's face size N
    cdf.doc = "R32F (N+1) x (6N+1): per-row CDFs, the row CDF in column N, the total weight at (0, 6N)";
    s.outputs = {cdf};
    return s;
}

class EnvCdf final : public Node {
public:
    void setup(SetupContext& ctx) override {
        const ImageDesc& sky = ctx.input("sky");
        if (!sky.cube || sky.width > kMaxFaceSize)
            ctx.failParam("sky", "expected a cube map of at most " + std::to_string(kMaxFaceSize) + "² per face");
        ImageDesc& out = ctx.output("cdf");
        out.width = sky.width + 1;
        out.height = 6 * sky.width + 1;
        mPipeline = ctx.computePipeline("sky/env_cdf.comp");
    }
    void execute(ExecuteContext& ctx) override { ctx.dispatch(mPipeline, nullptr, 0, 64, 1); }

private:
    PipelineId mPipeline = 0;
};

const NodeRegistration kRegistration(schema(), [] { return std::make_unique<EnvCdf>(); });

} // namespace
} // namespace vitrine
