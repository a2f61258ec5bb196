// post.streaks: star streaks (diffraction spikes) of bright sources, from the aperture's blade count and f-number.
#include "shaders/post/streaks.h"
#include "core/graph/node.hpp"
#include "core/graph/registry.hpp"
#include "nodes/camera/camera_state.hpp"
#include "nodes/post/bright_pass.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace vitrine {
namespace {

NodeSchema schema() {
    NodeSchema s;
    s.type = "post.streaks";
    s.doc = "Star streaks on a bright pass downsampled by `downsample` (light above `threshold` after exposure): an "
            "aperture of n straight blades diffracts light into n spikes when n is even (opposite edges share a "
            "direction) and 2n when n is odd. Each spike fades as exp(-3 t / L); L = length x frame height x N / 8 and "
            "the energy strength x N / 8 (N the f-number): stopping down lengthens the star without changing its "
            "brightness next to the source. With camera_state: blades, rotation, f-number and exposure from it, and "
            "no star wide open (the blades are out of the way), full one stop down.";
    s.inputs = {
        {"color", PortKind::Texture, {}, false, Usage::Sampled, "Linear HDR colour"},
        {"camera_state",
         PortKind::Buffer,
         {},
         true,
         Usage::Sampled,
         "camera.physical's state: replaces blades, rotation, f_number and exposure"},
    };
    OutputPort color;
    color.name = "color";
    color.formatFrom = "color";
    color.size = SizeRule::ofInput("color");
    color.doc = "Colour plus streaks";
    OutputPort bright = brightPassOutput();
    OutputPort streaks = bright;
    streaks.name = "streaks";
    streaks.doc = "The streaks alone (HDR), at the bright pass's size";
    s.outputs = {color, bright, streaks};
    s.params = {
        {"blades", ParamType::Int, 6, 0.0, 32.0, {}, "Aperture blades (0: a round aperture, no streaks)"},
        {"rotation", ParamType::Float, 0.0, -360.0, 360.0, {}, "Angle of the first spike in degrees"},
        {"f_number", ParamType::Float, 8.0, 0.5, 64.0, {}, "Aperture: spike length and energy grow with it"},
        {"length",
         ParamType::Float,
         0.08,
         0.0,
         2.0,
         {},
         "3 e-folding lengths of a spike at f/8, fraction of the frame height"},
        {"strength", ParamType::Float, 0.3, 0.0, 10.0, {}, "Streak energy / the source's bright energy at f/8"},
        {"max_samples", ParamType::Int, 48, 1.0, 256.0, {}, "Most taps per spike (one per bright-pass pixel up to it)"},
    };
    prependBrightPassParams(s.params, "streaks");
    return s;
}

class Streaks final : public Node {
public:
    void setup(SetupContext& ctx) override {
        mFactor = sizeBrightPass(ctx, {"bright", "streaks"});
        if (ctx.hasInput("camera_state")) mCamera = ctx.objectAs<CameraStateObject>("camera_state");
        const ShaderDefines defines = cameraExposureDefines(mCamera != nullptr);
        mBright = ctx.computePipeline("post/streaks_bright.comp", defines, mCamera ? 1 : 0);
        mSpikes = ctx.computePipeline("post/streaks_spikes.comp", defines, mCamera ? 1 : 0);
        mComposite = ctx.computePipeline("post/streaks.comp");
    }
    void execute(ExecuteContext& ctx) override {
        const auto& p = ctx.params();
        const ImageDesc& low = ctx.output("streaks").desc();
        const ImageDesc& out = ctx.output("color").desc();
        int blades = p.getInt("blades");
        float rotation = p.getFloat("rotation") * static_cast<float>(std::numbers::pi / 180.0);
        float fNumber = p.getFloat("f_number");
        float gate = 1.0f;
        if (mCamera) {
            // The f-number (and the gate that follows from it) is the camera's, which the spikes' shader reads on
            // the GPU: length and strength go per unit f-number, the sample count as its cap.
            const CameraState& s = mCamera->state;
            blades = s.bladeCount;
            rotation = s.bladeRotation;
            fNumber = 1.0f;
        }
        gpu_types::StreaksPush push{};
        fillBrightPass(ctx, mFactor, push);
        push.count = blades <= 0 ? 0u : static_cast<uint32_t>(blades % 2 == 0 ? blades : 2 * blades);
        push.rotation = rotation;
        push.spikeLength =
            p.getFloat("length") * static_cast<float>(out.height) / static_cast<float>(mFactor) * fNumber / 8.0f;
        push.strength = p.getFloat("strength") * fNumber / 8.0f * gate;
        push.samples = mCamera ? static_cast<uint32_t>(p.getInt("max_samples"))
                               : static_cast<uint32_t>(std::clamp(static_cast<int>(std::ceil(push.spikeLength)), 1,
                                                                  p.getInt("max_samples")));
        dispatchWithCamera(ctx, mCamera.get(), mBright, push, low.width, low.height);
        ctx.computeBarrier();
        dispatchWithCamera(ctx, mCamera.get(), mSpikes, push, low.width, low.height);
        ctx.computeBarrier();
        ctx.dispatch(mComposite, push, out.width, out.height);
    }

private:
    uint32_t mFactor = 4;
    std::shared_ptr<CameraStateObject> mCamera;
    PipelineId mBright = 0, mSpikes = 0, mComposite = 0;
};

const NodeRegistration kRegistration(schema(), [] { return std::make_unique<Streaks>(); });

} // namespace
} // namespace vitrine
