// pattern.zoneplate: an analytic, aliasing-prone test image with a supersampled ground truth.
#include "core/graph/node.hpp"
#include "core/graph/registry.hpp"
#include "core/scene/jitter.hpp"
#include "shaders/pattern/zoneplate.h"

namespace vitrine {
namespace {

NodeSchema schema() {
    NodeSchema s;
    s.type = "pattern.zoneplate";
    s.doc = "Fresnel zone plate whose frequency rises to max_frequency at the corners; supersample > 1 "
            "box-filters N x N samples per pixel, so a high N is the anti-aliasing ground truth.";
    OutputPort out;
    out.name = "color";
    out.format = VK_FORMAT_R32G32B32A32_SFLOAT;
    out.doc = "Grey zone plate in [0, 1]";
    s.outputs = {out};
    s.params = {
        {"max_frequency", ParamType::Float, 0.35, 0.0, 4.0, {}, "Cycles per pixel at the image corners (0.5 = Nyquist)"},
        {"supersample", ParamType::Int, 1, 1.0, 32.0, {}, "N: N x N stratified samples per pixel"},
        {"mode", ParamType::Enum, "binary", {}, {}, {"sine", "binary"},
         "sine: smooth cosine rings; binary: hard-edged rings (what edge anti-aliasing is for)"},
        {"jitter", ParamType::Enum, "off", {}, {}, scene::jitterPatternNames(),
         "Sub-pixel jitter per frame, the scene nodes' patterns (for aa.taa and aa.accumulate tests)"},
        {"jitter_grid", ParamType::Int, 0, 0.0, 64.0, {},
         "N of the stratified jitter; 0: the largest N with N^2 <= the frame count"},
    };
    return s;
}

class Zoneplate final : public Node {
public:
    void setup(SetupContext& ctx) override {
        mJitterGrid = scene::jitterGridFor(static_cast<uint32_t>(ctx.params().getInt("jitter_grid")), ctx.frame().frames);
        mPipeline = ctx.computePipeline("pattern/zoneplate.comp");
    }
    void execute(ExecuteContext& ctx) override {
        const auto& p = ctx.params();
        gpu_types::ZoneplatePush push{};
        push.maxFrequency = p.getFloat("max_frequency");
        push.supersample = static_cast<uint32_t>(p.getInt("supersample"));
        push.mode = static_cast<uint32_t>(p.getEnumIndex("mode"));
        push.samplePos = scene::jitterSample(static_cast<scene::JitterPattern>(p.getEnumIndex("jitter")), ctx.frameIndex(),
                                          mJitterGrid);
        const ImageDesc& out = ctx.output("color").desc();
        ctx.dispatch(mPipeline, push, out.width, out.height);
    }

private:
    PipelineId mPipeline = 0;
    uint32_t mJitterGrid = 1;
};

const NodeRegistration kRegistration(schema(), [] { return std::make_unique<Zoneplate>(); });

} // namespace
} // namespace vitrine
