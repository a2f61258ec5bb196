// depth.hiz: the Hi-Z pyramid (min and max depth per texel, all levels) that ssr.hiz traverses [Uludag14].
#include "core/graph/registry.hpp"
#include "nodes/depth/mip_atlas.hpp"

namespace vitrine {
namespace {

NodeSchema schema() {
    NodeSchema s;
    s.type = "depth.hiz";
    s.doc = "Hi-Z pyramid of the reverse-Z hardware depth: per texel of every level the minimum (farthest) and "
            "maximum (nearest) depth of its footprint, down to 1x1, packed into one RG32F atlas (level 0 at the "
            "origin, levels 1.. in a row below; shaders/common/mip_atlas.glsl). Odd sizes: the last row and column "
            "cover three texels of the level below. Three levels per dispatch.";
    s.inputs = {{"depth", PortKind::Texture, {}, false, Usage::Sampled, "Hardware depth, reverse Z (gbuffer.depth)"}};
    OutputPort hiz;
    hiz.name = "hiz";
    hiz.format = VK_FORMAT_R32G32_SFLOAT;
    hiz.size = SizeRule::ofInput("depth");
    hiz.usage = Usage::StorageReadWrite;
    hiz.doc = "Atlas of all levels: r = min depth (farthest), g = max depth (nearest) of the footprint";
    s.outputs = {hiz};
    return s;
}

class Hiz final : public Node {
public:
    void setup(SetupContext& ctx) override {
        mWidth = ctx.input("depth").width;
        mHeight = ctx.input("depth").height;
        sizeMipAtlas(ctx.output("hiz"), mWidth, mHeight);
        mPipeline = ctx.computePipeline("depth/hiz.comp");
    }
    void execute(ExecuteContext& ctx) override { recordMipChain(ctx, mPipeline, mWidth, mHeight); }

private:
    uint32_t mWidth = 1, mHeight = 1;
    PipelineId mPipeline = 0;
};

const NodeRegistration kRegistration(schema(), [] { return std::make_unique<Hiz>(); });

} // namespace
} // namespace vitrine
