// temporal.accumulate: temporal super-sampling of a noisy screen-space signal (SSR, fog, AO; MUSEUM_SPEC §5), history
// through its own color@prev and samples@prev.
#include "shaders/temporal/accumulate.h"
#include "core/graph/node.hpp"
#include "core/graph/registry.hpp"

namespace vitrine {
namespace {

NodeSchema schema() {
    NodeSchema s;
    s.type = "temporal.accumulate";
    s.doc = "Temporal super-sampling (MUSEUM_SPEC §5) for any RGBA signal at any resolution (SSR radiance + confidence, "
            "fog, AO): its own last output is reprojected by the velocity buffer (bilinear) and blended with this "
            "frame as the running mean of at most max_samples frames. The history's sample count restarts where the "
            "reprojected point left the screen or last frame's depth there is another surface (disocclusion), and "
            "shrinks where the velocity differs from last frame's there [Sousa13] and where the luminance differs "
            "from the history's. Wiring: color = the signal; history = <this>.color@prev; history_samples = "
            "<this>.samples@prev; velocity = gbuffer.velocity, history_velocity = gbuffer.velocity@prev; depth = "
            "gbuffer.normal, history_depth = gbuffer.normal@prev. The input may be smaller than the G-buffer: each "
            "input pixel reads the G-buffer texel under its centre and velocities are scaled to its pixels.";
    auto tex = [](const char* name, bool optional, const char* doc) {
        return InputPort{name, PortKind::Texture, {}, optional, Usage::Sampled, doc};
    };
    s.inputs = {
        tex("color", false, "This frame's signal, all four channels accumulated (e.g. radiance + confidence in a); any "
                            "size, any float or UNORM format"),
        tex("history", false, "This node's own color@prev"),
        tex("history_samples", false, "This node's own samples@prev"),
        tex("velocity", true, "Screen motion in pixels of its own size, this frame minus last (gbuffer.velocity); none: "
                              "static"),
        tex("history_velocity", true, "The velocity's @prev (gbuffer.velocity@prev): Sousa13's velocity-difference "
                                      "rejection (needs velocity)"),
        tex("depth", true, "Linear view depth in z, 0 where empty (gbuffer.normal), the velocity's size: disocclusion"),
        tex("history_depth", true, "The depth's @prev (gbuffer.normal@prev)"),
    };
    OutputPort color;
    color.name = "color";
    color.format = VK_FORMAT_R16G16B16A16_SFLOAT;
    color.size = SizeRule::ofInput("color");
    color.doc = "The accumulated signal (all four channels), the input's size";
    OutputPort samples;
    samples.name = "samples";
    samples.format = VK_FORMAT_R16_SFLOAT;
    samples.size = SizeRule::ofInput("color");
    samples.doc = "Samples the output holds (1 after a restart, at most max_samples); read back as history_samples";
    s.outputs = {color, samples};
    s.params = {
        {"max_samples", ParamType::Int, 8, 1.0, 64.0, {},
         "Most frames averaged (the demo: a few to a dozen); once reached, the history's weight stays (N - 1) / N"},
        {"velocity_weight", ParamType::Float, 0.5, 0.0, 1e3, {},
         "Sousa13: the history's samples x max(0, 1 - velocity_weight |v - v_prev|), |.| in velocity-buffer pixels "
         "(with history_velocity)"},
        {"depth_tolerance", ParamType::Float, 0.05, 0.0, 1e6, {},
         "Relative view-depth difference beyond which last frame's surface is another one (with depth)"},
        {"luminance_weight", ParamType::Float, 0.0, 0.0, 1.0, {},
         "The history's samples x (1 - luminance_weight |L - L_history| / max(L, L_history, luminance_floor)); 0: off "
         "(a noisy signal such as AO needs the history it would reject)"},
        {"luminance_floor", ParamType::Float, 1e-3, 1e-8, 1e9, {},
         "Luminance below which differences are measured against this value (the signal's units)"},
    };
    return s;
}

class TemporalAccumulate final : public Node {
public:
    void setup(SetupContext& ctx) override {
        if (ctx.hasInput("depth") != ctx.hasInput("history_depth"))
            ctx.failParam("depth_tolerance", "connect both depth (gbuffer.normal) and history_depth "
                                             "(gbuffer.normal@prev), or neither");
        if (ctx.hasInput("history_velocity") && !ctx.hasInput("velocity"))
            ctx.failParam("velocity_weight", "history_velocity needs velocity (gbuffer.velocity) too");
        if (ctx.hasInput("velocity") && ctx.hasInput("depth")) {
            const ImageDesc& v = ctx.input("velocity");
            const ImageDesc& d = ctx.input("depth");
            if (v.width != d.width || v.height != d.height)
                ctx.failParam("depth_tolerance", "velocity (" + std::to_string(v.width) + "x" +
                                                     std::to_string(v.height) + ") and depth (" +
                                                     std::to_string(d.width) + "x" + std::to_string(d.height) +
                                                     ") must be the same size (both the G-buffer's)");
        }
        mPipeline = ctx.computePipeline("temporal/accumulate.comp");
    }
    void execute(ExecuteContext& ctx) override {
        const auto& p = ctx.params();
        gpu_types::TemporalAccumulatePush push{};
        push.maxSamples = static_cast<float>(p.getInt("max_samples"));
        push.velocityWeight = p.getFloat("velocity_weight");
        push.depthTolerance = p.getFloat("depth_tolerance");
        push.luminanceWeight = p.getFloat("luminance_weight");
        push.luminanceFloor = p.getFloat("luminance_floor");
        const bool history = ctx.inputValid("history") && ctx.inputValid("history_samples");
        push.flags = (history ? TEMPORAL_HISTORY_VALID : 0u) | (ctx.hasInput("velocity") ? TEMPORAL_VELOCITY : 0u) |
                     (ctx.hasInput("history_velocity") && ctx.inputValid("history_velocity") ? TEMPORAL_VELOCITY_HISTORY
                                                                                             : 0u) |
                     (ctx.hasInput("depth") && ctx.inputValid("history_depth") ? TEMPORAL_DEPTH : 0u);
        const ImageDesc& out = ctx.output("color").desc();
        ctx.dispatch(mPipeline, push, out.width, out.height);
    }

private:
    PipelineId mPipeline = 0;
};

const NodeRegistration kRegistration(schema(), [] { return std::make_unique<TemporalAccumulate>(); });

} // namespace
} // namespace vitrine
