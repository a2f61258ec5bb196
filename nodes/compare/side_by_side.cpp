// compare.side_by_side: a | b in one image, twice as wide as a.
#include "shaders/compare/side_by_side.h"
#include "core/graph/node.hpp"
#include "core/graph/registry.hpp"

namespace vitrine {
namespace {

NodeSchema schema() {
    NodeSchema s;
    s.type = "compare.side_by_side";
    s.doc = "a on the left, b on the right, each at a's size: the output is 2x as wide as a.";
    s.inputs = {{"a", PortKind::Texture, {}, false, Usage::Sampled, "Left image"},
                {"b",
                 PortKind::Texture,
                 {},
                 false,
                 Usage::Sampled,
                 "Right image (nearest texel at the same relative position when its size differs from a's)"}};
    OutputPort out;
    out.name = "color";
    out.formatFrom = "a";
    out.size = SizeRule::ofInput("a");
    out.doc = "a | b, 2 x a's width, a's height and format";
    s.outputs = {out};
    s.params = {
        {"separator_width",
         ParamType::Int,
         0,
         0.0,
         32.0,
         {},
         "Pixels of seam line drawn on each side of the middle (0: none, the halves are exact copies)"},
        {"separator_color", ParamType::Vec4, {1.0, 1.0, 1.0, 1.0}, {}, {}, {}, "Linear RGBA of the seam line"},
    };
    return s;
}

class SideBySide final : public Node {
public:
    void setup(SetupContext& ctx) override {
        ctx.output("color").width = 2 * ctx.input("a").width;
        mPipeline = ctx.computePipeline("compare/side_by_side.comp");
    }
    void execute(ExecuteContext& ctx) override {
        const auto& p = ctx.params();
        gpu_types::SideBySidePush push{};
        push.separatorColor = p.getVec4("separator_color");
        push.separatorWidth = static_cast<uint32_t>(p.getInt("separator_width"));
        const ImageDesc& out = ctx.output("color").desc();
        ctx.dispatch(mPipeline, push, out.width, out.height);
    }

private:
    PipelineId mPipeline = 0;
};

const NodeRegistration kRegistration(schema(), [] { return std::make_unique<SideBySide>(); });

} // namespace
} // namespace vitrine
