// debug.view: makes any texture viewable: one channel or all, a value range, false colour.
#include "core/graph/node.hpp"
#include "core/graph/registry.hpp"
#include "shaders/debug/view.h"

namespace vitrine {
namespace {

NodeSchema schema() {
    NodeSchema s;
    s.type = "debug.view";
    s.doc = "Shows any texture: pick channels, remap [min, max] to [0, 1], optionally through a false-colour ramp.";
    s.inputs = {{"texture", PortKind::Texture, {}, false, Usage::Sampled, "Texture to inspect"}};
    OutputPort out;
    out.name = "color";
    out.format = VK_FORMAT_R16G16B16A16_SFLOAT;
    out.size = SizeRule::ofInput("texture");
    out.doc = "Viewable colour (linear)";
    s.outputs = {out};
    s.params = {
        {"channel", ParamType::Enum, "rgb", {}, {}, {"rgba", "rgb", "r", "g", "b", "a", "luma"}, "Channels shown"},
        {"range", ParamType::Vec2, {0.0, 1.0}, {}, {}, {}, "Values mapped to 0 and 1"},
        {"false_color", ParamType::Bool, false, {}, {}, {}, "Map a single channel through a colour ramp"},
        {"scale", ParamType::Float, 1.0, 0.0625, 16.0, {}, "Output size relative to the input"},
    };
    return s;
}

class View final : public Node {
public:
    void setup(SetupContext& ctx) override {
        glm::vec2 range = ctx.params().getVec2("range");
        if (!(range.y > range.x)) ctx.failParam("range", "expected [min, max] with max > min");
        float scale = ctx.params().getFloat("scale");
        const ImageDesc& in = ctx.input("texture");
        ImageDesc& out = ctx.output("color");
        out.width = std::max(1u, static_cast<uint32_t>(in.width * scale + 0.5f));
        out.height = std::max(1u, static_cast<uint32_t>(in.height * scale + 0.5f));
        mPipeline = ctx.computePipeline("debug/view.comp");
    }
    void execute(ExecuteContext& ctx) override {
        const auto& p = ctx.params();
        gpu_types::ViewPush push{};
        glm::vec2 range = p.getVec2("range");
        push.rangeMin = range.x;
        push.rangeMax = range.y;
        push.channel = static_cast<uint32_t>(p.getEnumIndex("channel"));
        push.falseColor = p.getBool("false_color") ? 1u : 0u;
        const ImageDesc& out = ctx.output("color").desc();
        ctx.dispatch(mPipeline, push, out.width, out.height);
    }

private:
    PipelineId mPipeline = 0;
};

const NodeRegistration kRegistration(schema(), [] { return std::make_unique<View>(); });

} // namespace
} // namespace vitrine
