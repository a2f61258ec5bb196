// post.flare: lens-flare ghosts of bright sources, mirrored and scaled through the optical centre, and a ring ghost.
#include "shaders/post/flare.h"
#include "core/graph/node.hpp"
#include "core/graph/registry.hpp"
#include "nodes/post/bright_pass.hpp"

#include <cmath>

namespace vitrine {
namespace {

NodeSchema schema() {
    NodeSchema s;
    s.type = "post.flare";
    s.doc = "Lens flare on a bright pass downsampled by `downsample` (light above `threshold` after exposure): up to 8 "
            "ghosts, ghost i of a source at q centred at c + s_i (q - c) (c the image centre; s < 0 mirrors through "
            "it) with energy ghost_intensity x tint_i x the source's bright energy (tints in shaders/post/"
            "flare_ghosts.comp), and a ring ghost of radius halo_radius (fraction of the half-diagonal) around the "
            "source's mirror image 2c - q with energy halo_intensity x the source's. Added to the colour.";
    s.inputs = {
        {"color", PortKind::Texture, {}, false, Usage::Sampled, "Linear HDR colour"},
        {"camera_state",
         PortKind::Buffer,
         {},
         true,
         Usage::Sampled,
         "camera.physical's state: its exposure replaces the `exposure` param"},
    };
    OutputPort color;
    color.name = "color";
    color.formatFrom = "color";
    color.size = SizeRule::ofInput("color");
    color.doc = "Colour plus flare";
    OutputPort bright = brightPassOutput();
    OutputPort flare = bright;
    flare.name = "flare";
    flare.doc = "The flare alone (HDR), at the bright pass's size";
    s.outputs = {color, bright, flare};
    s.params = {
        {"ghost_scales",
         ParamType::Vec4,
         nlohmann::json::array({-0.4, -0.75, -1.1, 0.5}),
         -8.0,
         8.0,
         {},
         "Scales of ghosts 0..3 about the centre (0: none; negative: mirrored through the centre)"},
        {"ghost_scales2",
         ParamType::Vec4,
         nlohmann::json::array({-1.6, 0.0, 0.0, 0.0}),
         -8.0,
         8.0,
         {},
         "Scales of ghosts 4..7"},
        {"ghost_intensity",
         ParamType::Float,
         0.05,
         0.0,
         10.0,
         {},
         "Each ghost's energy relative to the source's bright energy (times its tint)"},
        {"halo_radius", ParamType::Float, 0.45, 0.0, 2.0, {}, "Ring ghost radius, fraction of the half-diagonal"},
        {"halo_intensity", ParamType::Float, 0.05, 0.0, 10.0, {}, "Ring ghost energy relative to the source's"},
        {"halo_taps", ParamType::Int, 48, 1.0, 256.0, {}, "Taps on the ring"},
    };
    prependBrightPassParams(s.params, "flares");
    return s;
}

class Flare final : public Node {
public:
    void setup(SetupContext& ctx) override {
        mFactor = sizeBrightPass(ctx, {"bright", "flare"});
        if (ctx.hasInput("camera_state")) mCamera = ctx.objectAs<CameraStateObject>("camera_state");
        mBright = ctx.computePipeline("post/flare_bright.comp", cameraExposureDefines(mCamera != nullptr), mCamera ? 1 : 0);
        mGhosts = ctx.computePipeline("post/flare_ghosts.comp");
        mComposite = ctx.computePipeline("post/flare.comp");
    }
    void execute(ExecuteContext& ctx) override {
        const auto& p = ctx.params();
        const ImageDesc& low = ctx.output("flare").desc();
        const ImageDesc& out = ctx.output("color").desc();
        gpu_types::FlarePush push{};
        push.scalesA = p.getVec4("ghost_scales");
        push.scalesB = p.getVec4("ghost_scales2");
        // The optical centre of the full image, in bright-pass pixels.
        push.centre = glm::vec2(0.5f * out.width, 0.5f * out.height) / static_cast<float>(mFactor);
        push.halfDiagonal = 0.5f * std::hypot(static_cast<float>(out.width), static_cast<float>(out.height)) /
                            static_cast<float>(mFactor);
        fillBrightPass(ctx, mFactor, push);
        push.ghostIntensity = p.getFloat("ghost_intensity");
        push.haloRadius = p.getFloat("halo_radius");
        push.haloIntensity = p.getFloat("halo_intensity");
        push.haloTaps = static_cast<uint32_t>(p.getInt("halo_taps"));
        dispatchWithCamera(ctx, mCamera.get(), mBright, push, low.width, low.height);
        ctx.computeBarrier();
        ctx.dispatch(mGhosts, push, low.width, low.height);
        ctx.computeBarrier();
        ctx.dispatch(mComposite, push, out.width, out.height);
    }

private:
    uint32_t mFactor = 4;
    std::shared_ptr<CameraStateObject> mCamera;
    PipelineId mBright = 0, mGhosts = 0, mComposite = 0;
};

const NodeRegistration kRegistration(schema(), [] { return std::make_unique<Flare>(); });

} // namespace
} // namespace vitrine
