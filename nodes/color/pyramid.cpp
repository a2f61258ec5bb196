// color.pyramid: a box-filtered mip chain of a colour image (last frame's lit colour) for ssr.hiz's cone tracing.
#include "core/base/error.hpp"
#include "core/graph/registry.hpp"
#include "nodes/depth/mip_atlas.hpp"

namespace vitrine {
namespace {

NodeSchema schema() {
    NodeSchema s;
    s.type = "color.pyramid";
    s.doc = "Mip chain of a colour image for glossy screen-space lookups (ssr.hiz samples it at the mip of a "
            "reflection cone's footprint): each level the box-filtered mean of the one below, down to 1x1, packed "
            "into one RGBA16F atlas like depth.hiz's. Meant for last frame's lit colour (x.color@prev, so "
            "reflections see reflections); until that history exists (the first frame) `fallback` (this frame's "
            "colour before reflections) stands in.";
    s.inputs = {{"color", PortKind::Texture, {}, false, Usage::Sampled, "Colour to filter, usually an @prev history"},
                {"fallback", PortKind::Texture, {}, true, Usage::Sampled,
                 "Used while `color` reads a history not yet written; its size is the pyramid's level 0 (without "
                 "it, the frame's)"}};
    OutputPort pyramid;
    pyramid.name = "pyramid";
    pyramid.format = VK_FORMAT_R16G16B16A16_SFLOAT;
    pyramid.size = SizeRule::frame(); // resized in setup()
    pyramid.usage = Usage::StorageReadWrite;
    pyramid.doc = "Atlas of all levels (rgb mean, a = 1)";
    s.outputs = {pyramid};
    return s;
}

class Pyramid final : public Node {
public:
    // `color` may read an @prev history, whose description is unknown at setup: the level-0 size is the
    // fallback's, else the frame's, and execute() checks that `color` has it.
    void setup(SetupContext& ctx) override {
        if (ctx.hasInput("fallback")) {
            mWidth = ctx.input("fallback").width;
            mHeight = ctx.input("fallback").height;
        } else {
            mWidth = ctx.frame().width;
            mHeight = ctx.frame().height;
        }
        sizeMipAtlas(ctx.output("pyramid"), mWidth, mHeight);
        mPipeline = ctx.computePipeline("color/pyramid.comp");
    }
    void execute(ExecuteContext& ctx) override {
        const ImageDesc& in = ctx.input("color").desc();
        if (in.width != mWidth || in.height != mHeight)
            throw UserError("color.pyramid: input color is " + std::to_string(in.width) + "x" +
                            std::to_string(in.height) + ", expected " + std::to_string(mWidth) + "x" +
                            std::to_string(mHeight) + " (the size of fallback, else of the frame)");
        int fallback = !ctx.inputValid("color") && ctx.hasInput("fallback") ? 1 : 0;
        recordMipChain(ctx, mPipeline, mWidth, mHeight, fallback);
    }

private:
    uint32_t mWidth = 1, mHeight = 1;
    PipelineId mPipeline = 0;
};

const NodeRegistration kRegistration(schema(), [] { return std::make_unique<Pyramid>(); });

} // namespace
} // namespace vitrine
