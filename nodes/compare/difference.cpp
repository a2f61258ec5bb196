// compare.difference: |a - b| * scale, as colour or through the magma heat-map ramp.
#include "shaders/compare/difference.h"
#include "core/graph/node.hpp"
#include "core/graph/registry.hpp"

namespace vitrine {
namespace {

NodeSchema schema() {
    NodeSchema s;
    s.type = "compare.difference";
    s.doc = "Absolute difference |a - b| per channel times scale; with false_color, the largest channel through "
            "the magma ramp (the same heat map as `vitrine compare` and FLIP).";
    s.inputs = {{"a", PortKind::Texture, {}, false, Usage::Sampled, "First image"},
                {"b",
                 PortKind::Texture,
                 {},
                 false,
                 Usage::Sampled,
                 "Second image (nearest texel at the same relative position when sizes differ)"}};
    OutputPort out;
    out.name = "color";
    out.format = VK_FORMAT_R16G16B16A16_SFLOAT;
    out.size = SizeRule::ofInput("a");
    out.doc = "Difference image, alpha 1";
    s.outputs = {out};
    s.params = {
        {"scale", ParamType::Float, 1.0, 0.0, 1.0e6, {}, "Multiplier of |a - b| (e.g. 10 to see small errors)"},
        {"false_color", ParamType::Bool, false, {}, {}, {}, "Show clamp(scale * max channel, 0, 1) as magma"},
    };
    return s;
}

class Difference final : public Node {
public:
    void setup(SetupContext& ctx) override { mPipeline = ctx.computePipeline("compare/difference.comp"); }
    void execute(ExecuteContext& ctx) override {
        const auto& p = ctx.params();
        gpu_types::DifferencePush push{};
        push.scale = p.getFloat("scale");
        push.falseColor = p.getBool("false_color") ? 1u : 0u;
        const ImageDesc& out = ctx.output("color").desc();
        ctx.dispatch(mPipeline, push, out.width, out.height);
    }

private:
    PipelineId mPipeline = 0;
};

const NodeRegistration kRegistration(schema(), [] { return std::make_unique<Difference>(); });

} // namespace
} // namespace vitrine
