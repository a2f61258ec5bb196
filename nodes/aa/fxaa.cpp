// aa.fxaa: post-process anti-aliasing from one image (FXAA 3.11 quality).
#include "core/graph/node.hpp"
#include "core/graph/registry.hpp"
#include "shaders/aa/fxaa.h"

namespace vitrine {
namespace {

NodeSchema schema() {
    NodeSchema s;
    s.type = "aa.fxaa";
    s.doc = "FXAA 3.11 quality: finds luma edges, searches their ends and re-samples across them; "
            "also softens sub-pixel aliasing. No new samples: shimmers in motion (see aa.taa).";
    s.inputs = {{"color", PortKind::Texture, {}, false, Usage::Sampled, "Colour to anti-alias (linear)"}};
    OutputPort out;
    out.name = "color";
    out.formatFrom = "color";
    out.size = SizeRule::ofInput("color");
    out.doc = "Anti-aliased colour";
    s.outputs = {out};
    s.params = {
        {"subpix", ParamType::Float, 0.75, 0.0, 1.0, {}, "Sub-pixel aliasing removal (0 off, 1 softest)"},
        {"edge_threshold", ParamType::Float, 0.166, 0.0, 1.0, {}, "Minimum contrast relative to local max luma"},
        {"edge_threshold_min", ParamType::Float, 0.0833, 0.0, 1.0, {}, "Contrast below which dark pixels are skipped"},
        {"search_steps", ParamType::Int, 12, 1.0, 12.0, {}, "Steps of the edge-end search (quality presets 10-39)"},
    };
    return s;
}

class Fxaa final : public Node {
public:
    void setup(SetupContext& ctx) override { mPipeline = ctx.computePipeline("aa/fxaa.comp"); }
    void execute(ExecuteContext& ctx) override {
        const auto& p = ctx.params();
        gpu_types::FxaaPush push{};
        push.subpix = p.getFloat("subpix");
        push.edgeThreshold = p.getFloat("edge_threshold");
        push.edgeThresholdMin = p.getFloat("edge_threshold_min");
        push.searchSteps = static_cast<uint32_t>(p.getInt("search_steps"));
        const ImageDesc& out = ctx.output("color").desc();
        ctx.dispatch(mPipeline, push, out.width, out.height);
    }

private:
    PipelineId mPipeline = 0;
};

const NodeRegistration kRegistration(schema(), [] { return std::make_unique<Fxaa>(); });

} // namespace
} // namespace vitrine
