// reference.substitute: a lit colour with one of its terms replaced by another estimate of it (a ray-traced twin's),
// for the museum_rt_* variants.
#include "core/graph/node.hpp"
#include "core/graph/registry.hpp"

namespace vitrine {
namespace {

NodeSchema schema() {
    NodeSchema s;
    s.type = "reference.substitute";
    s.doc = "color - technique + twin, clamped at 0: the lit colour with a term the real-time chain put in it "
            "(e.g. ssr.composite's specular_indirect) replaced by a ray-traced twin's estimate of the same term "
            "(e.g. reference.reflections' color). The three images have the same size; alpha is color's.";
    auto tex = [](const char* name, const char* doc) {
        return InputPort{name, PortKind::Texture, {}, false, Usage::Sampled, doc};
    };
    s.inputs = {
        tex("color", "Lit HDR colour that includes the technique's term"),
        tex("technique", "The term as the real-time chain computed it (inside color)"),
        tex("twin", "The same term from its ray-traced twin (reference.*'s color)"),
    };
    OutputPort color;
    color.name = "color";
    color.formatFrom = "color";
    color.size = SizeRule::ofInput("color");
    color.doc = "HDR colour with the twin's term in place of the technique's";
    s.outputs = {color};
    return s;
}

class Substitute final : public Node {
public:
    void setup(SetupContext& ctx) override { mPipeline = ctx.computePipeline("reference/substitute.comp"); }
    void execute(ExecuteContext& ctx) override {
        const ImageDesc& out = ctx.output("color").desc();
        ctx.dispatch(mPipeline, nullptr, 0, out.width, out.height);
    }

private:
    PipelineId mPipeline = 0;
};

const NodeRegistration kRegistration(schema(), [] { return std::make_unique<Substitute>(); });

} // namespace
} // namespace vitrine
