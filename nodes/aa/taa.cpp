// aa.taa: temporal anti-aliasing after Karis 2014 (MUSEUM_SPEC §6), history through its own color@prev.
#include "shaders/aa/taa.h"
#include "core/graph/node.hpp"
#include "core/graph/registry.hpp"

#include <cmath>

namespace vitrine {
namespace {

NodeSchema schema() {
    NodeSchema s;
    s.type = "aa.taa";
    s.doc = "Temporal AA (Karis 2014): last frame's output reprojected by the velocity buffer with a Catmull-Rom "
            "fetch, skipped where the depth says it is another surface or the pixel moved too far, clamped or "
            "variance-clipped to the 3x3 neighbourhood in YCoCg, and blended with the current frame in the "
            "exactly invertible Reinhard-max tone curve (post.tonemap's reinhard_max), then back to linear HDR. "
            "With a jittered camera (scene jitter) static pixels converge to the supersampled image.";
    auto tex = [](const char* name, bool optional, const char* doc) {
        return InputPort{name, PortKind::Texture, {}, optional, Usage::Sampled, doc};
    };
    s.inputs = {
        tex("color", false, "This frame's HDR colour (rendered with the jittered camera)"),
        tex("history", false, "This node's own color@prev (last frame's output)"),
        tex("velocity", true, "Screen motion in pixels, this frame minus last (gbuffer.velocity); none: static"),
        tex("depth", true, "Linear view depth in z, 0 where empty (gbuffer.normal): the same-surface test"),
        tex("history_depth", true, "The same texture's @prev (gbuffer.normal@prev)"),
    };
    OutputPort color;
    color.name = "color";
    color.format = VK_FORMAT_R32G32B32A32_SFLOAT; // the history: a running mean and its sample count
    color.size = SizeRule::ofInput("color");
    color.doc = "Anti-aliased HDR colour (linear, before post); a: samples the history holds (capped at 4096)";
    OutputPort weight;
    weight.name = "weight";
    weight.format = VK_FORMAT_R16G16B16A16_SFLOAT;
    weight.size = SizeRule::ofInput("color");
    weight.doc = "Debug: the history's weight in the blend (rgb; 0 where it was rejected), a = 1";
    s.outputs = {color, weight};
    s.params = {
        {"feedback",
         ParamType::Float,
         0.9,
         0.0,
         1.0,
         {},
         "Largest weight of the history; until it is reached the blend is the running mean of the samples"},
        {"exposure",
         ParamType::Float,
         0.0,
         -24.0,
         24.0,
         {},
         "Stops applied before the blend's tone curve (as post.tonemap's exposure; the output stays unscaled)"},
        {"clamp",
         ParamType::Enum,
         "variance",
         {},
         {},
         {"none", "minmax", "variance"},
         "History rectification in YCoCg: none, clamp to the 3x3 min/max box, or clip toward the centre of the "
         "mean +- gamma sigma box (within min/max)"},
        {"gamma", ParamType::Float, 1.0, 0.25, 4.0, {}, "Variance clip: box half-size in standard deviations"},
        {"history_filter",
         ParamType::Enum,
         "catmull_rom",
         {},
         {},
         {"catmull_rom", "bilinear"},
         "Reprojected history fetch: Catmull-Rom (sharp) or bilinear (blurs under motion)"},
        {"max_velocity", ParamType::Float, 32.0, 0.0, 1e6, {}, "Pixels per frame beyond which the history is skipped"},
        {"depth_tolerance",
         ParamType::Float,
         0.05,
         0.0,
         1e6,
         {},
         "Relative view-depth difference beyond which the reprojected history is another surface (with depth)"},
        {"sharpen", ParamType::Float, 0.0, 0.0, 1.0, {}, "Unsharp mask of the current frame before the blend"},
    };
    return s;
}

class Taa final : public Node {
public:
    void setup(SetupContext& ctx) override {
        if (ctx.hasInput("depth") != ctx.hasInput("history_depth"))
            ctx.failParam("depth_tolerance", "connect both depth (gbuffer.normal) and history_depth "
                                             "(gbuffer.normal@prev), or neither");
        mPipeline = ctx.computePipeline("aa/taa.comp");
    }
    void execute(ExecuteContext& ctx) override {
        const auto& p = ctx.params();
        gpu_types::TaaPush push{};
        push.feedback = p.getFloat("feedback");
        push.exposureScale = std::exp2(p.getFloat("exposure"));
        push.gamma = p.getFloat("gamma");
        push.maxVelocity = p.getFloat("max_velocity");
        push.depthTolerance = p.getFloat("depth_tolerance");
        push.sharpen = p.getFloat("sharpen");
        push.clampMode = static_cast<uint32_t>(p.getEnumIndex("clamp"));
        push.historyFilter = static_cast<uint32_t>(p.getEnumIndex("history_filter"));
        push.flags = (ctx.inputValid("history") ? TAA_HISTORY_VALID : 0u) |
                     (ctx.hasInput("velocity") ? TAA_VELOCITY : 0u) |
                     (ctx.hasInput("depth") && ctx.inputValid("history_depth") ? TAA_DEPTH : 0u);
        const ImageDesc& out = ctx.output("color").desc();
        ctx.dispatch(mPipeline, push, out.width, out.height);
    }

private:
    PipelineId mPipeline = 0;
};

const NodeRegistration kRegistration(schema(), [] { return std::make_unique<Taa>(); });

} // namespace
} // namespace vitrine
