// gbuffer.temporal_filter: normals blended over time and shininess reduced Toksvig-style (MUSEUM_SPEC §5).
#include "shaders/gbuffer/temporal_filter.h"
#include "core/graph/node.hpp"
#include "core/graph/registry.hpp"

namespace vitrine {
namespace {

NodeSchema schema() {
    NodeSchema s;
    s.type = "gbuffer.temporal_filter";
    s.doc = "Temporal G-buffer filtering (MUSEUM_SPEC §5): the normal is blended with its history (reprojected by "
            "the velocity buffer, texels of other surfaces left out by view depth) without renormalising, and "
            "shininess is reduced from the blended normal's length by Toksvig's formula (common/brdf.glsl), against "
            "geometric specular aliasing on thin geometry and fine normal maps. Writes gbuffer.normal's layout for "
            "lighting.deferred; shininess never increases. Wiring: normal = gbuffer.normal, velocity = "
            "gbuffer.velocity, history = <this>.history@prev.";
    auto tex = [](const char* name, bool optional, const char* doc) {
        return InputPort{name, PortKind::Texture, {}, optional, Usage::Sampled, doc};
    };
    s.inputs = {
        tex("normal", false, "G-buffer: octahedral normal, view depth, shininess (gbuffer.normal)"),
        tex("velocity", true, "Screen motion in pixels, this frame minus last (gbuffer.velocity); none: static"),
        tex("history", false, "This node's own history@prev"),
    };
    OutputPort normal;
    normal.name = "normal";
    normal.format = VK_FORMAT_R16G16B16A16_SFLOAT;
    normal.size = SizeRule::ofInput("normal");
    normal.doc = "gbuffer.normal's layout: octahedral normal of the blended normal, view depth, reduced shininess";
    OutputPort history;
    history.name = "history";
    history.format = VK_FORMAT_R16G16B16A16_SFLOAT;
    history.size = SizeRule::ofInput("normal");
    history.doc = "The blended normal, not normalised (xyz, world), and the view depth (w; 0 where empty)";
    s.outputs = {normal, history};
    s.params = {
        {"feedback", ParamType::Float, 0.75, 0.0, 0.99, {},
         "Weight of the history in the normal's blend (0: no filtering; higher: steadier and slower)"},
        {"depth_tolerance", ParamType::Float, 0.05, 0.0, 1e6, {},
         "Relative view-depth difference beyond which a history texel is another surface"},
    };
    return s;
}

class TemporalFilter final : public Node {
public:
    void setup(SetupContext& ctx) override { mPipeline = ctx.computePipeline("gbuffer/temporal_filter.comp"); }
    void execute(ExecuteContext& ctx) override {
        const Params& p = ctx.params();
        gpu_types::GbufferFilterPush push{};
        push.feedback = p.getFloat("feedback");
        push.depthTolerance = p.getFloat("depth_tolerance");
        push.flags = (ctx.inputValid("history") ? GBUFFER_FILTER_HISTORY_VALID : 0u) |
                     (ctx.hasInput("velocity") ? GBUFFER_FILTER_VELOCITY : 0u);
        const ImageDesc& out = ctx.output("normal").desc();
        ctx.dispatch(mPipeline, push, out.width, out.height);
    }

private:
    PipelineId mPipeline = 0;
};

const NodeRegistration kRegistration(schema(), [] { return std::make_unique<TemporalFilter>(); });

} // namespace
} // namespace vitrine
