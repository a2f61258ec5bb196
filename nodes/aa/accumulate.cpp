// aa.accumulate: the supersampled ground truth of anti-aliasing, as the mean of N x N stratified jittered frames.
#include "shaders/aa/accumulate.h"
#include "core/graph/node.hpp"
#include "core/graph/registry.hpp"
#include "core/scene/gpu_scene.hpp"

#include <string>

namespace vitrine {
namespace {

NodeSchema schema() {
    NodeSchema s;
    s.type = "aa.accumulate";
    s.doc = "Ground truth for anti-aliasing: the mean of the first N x N frames of a static shot rendered with the "
            "stratified jitter (scene jitter: stratified, jitter_grid N) is exactly the box-filtered N x N "
            "supersampled image, at any resolution, without a larger render target. Later frames keep the mean.";
    s.inputs = {
        {"color",
         PortKind::Texture,
         {},
         false,
         Usage::Sampled,
         "This frame's colour, rendered with the stratified jitter"},
        {"history", PortKind::Texture, {}, false, Usage::Sampled, "This node's own color@prev"},
        {"camera",
         PortKind::Camera,
         {},
         true,
         Usage::Sampled,
         "The scene's camera: checks that its jitter is the stratified N x N one (patterns have none)"},
    };
    OutputPort out;
    out.name = "color";
    out.format = VK_FORMAT_R32G32B32A32_SFLOAT;
    out.size = SizeRule::ofInput("color");
    out.doc = "Mean of the frames so far (of all N x N once frame N^2 - 1 has run)";
    s.outputs = {out};
    s.params = {
        {"grid",
         ParamType::Int,
         0,
         0.0,
         64.0,
         {},
         "N: N x N sub-pixel samples, one per frame (the graph needs N^2 frames). 0: the largest N with N^2 <= the "
         "graph's frame count (16 frames: 4 x 4; --frames 256: 16 x 16)"},
    };
    return s;
}

class Accumulate final : public Node {
public:
    void setup(SetupContext& ctx) override {
        const uint32_t n = scene::jitterGridFor(static_cast<uint32_t>(ctx.params().getInt("grid")), ctx.frame().frames);
        mSamples = n * n;
        if (ctx.frame().frames < mSamples)
            ctx.failParam("grid", "needs " + std::to_string(mSamples) + " frames (N x N) but the graph runs " +
                                      std::to_string(ctx.frame().frames) + "; set frame.frames (or --frames) to " +
                                      std::to_string(mSamples) + " or more");
        if (ctx.hasInput("camera")) {
            auto camera = ctx.objectAs<CameraObject>("camera");
            if (camera->jitterPattern != scene::JitterPattern::Stratified || camera->jitterGrid != n)
                ctx.failParam("grid", "the camera's jitter must be the stratified one with the same grid: set the "
                                      "scene's params jitter to \"stratified\" and jitter_grid to " +
                                          std::to_string(n));
        }
        mPipeline = ctx.computePipeline("aa/accumulate.comp");
    }
    void execute(ExecuteContext& ctx) override {
        gpu_types::AccumulatePush push{};
        push.index = ctx.frameIndex();
        push.samples = mSamples;
        const ImageDesc& out = ctx.output("color").desc();
        ctx.dispatch(mPipeline, push, out.width, out.height);
    }

private:
    PipelineId mPipeline = 0;
    uint32_t mSamples = 1;
};

const NodeRegistration kRegistration(schema(), [] { return std::make_unique<Accumulate>(); });

} // namespace
} // namespace vitrine
