// post.grain: film grain whose strength and size follow the ISO, new every frame, in display-referred space.
#include "core/graph/node.hpp"
#include "core/graph/registry.hpp"
#include "nodes/camera/camera_state.hpp"
#include "shaders/post/grain.h"

#include <algorithm>
#include <cmath>

namespace vitrine {
namespace {

NodeSchema schema() {
    NodeSchema s;
    s.type = "post.grain";
    s.doc = "Film grain on the display-referred image (after the tone mapper and grading): zero-mean Gaussian grain in "
            "sRGB-encoded values, cubic B-spline-filtered lattice noise, new every frame; standard deviation "
            "strength·√(ISO/100), size size·(ISO/100)^¼ (pixels at 1080 lines).";
    s.inputs = {{"color", PortKind::Texture, {}, false, Usage::Sampled, "Display-linear colour in [0, 1] (post.tonemap's output)"},
                {"camera_state", PortKind::Buffer, {}, true, Usage::Sampled,
                 "camera.physical's state: when connected, its ISO replaces the `iso` param"}};
    OutputPort out;
    out.name = "color";
    out.formatFrom = "color";
    out.size = SizeRule::ofInput("color");
    out.doc = "The colour with grain (display-linear)";
    s.outputs = {out};
    s.params = {
        {"iso", ParamType::Float, 100.0, 25.0, 409600.0, {}, "ISO (ignored when camera_state is connected)"},
        {"strength", ParamType::Float, 0.01, 0.0, 1.0, {},
         "Standard deviation of the grain at ISO 100, in sRGB-encoded units; it grows as √(ISO/100)"},
        {"size", ParamType::Float, 1.0, 0.1, 64.0, {},
         "Grain lattice spacing at ISO 100, in pixels of a 1080-line frame (scaled with the frame height); it grows "
         "as (ISO/100)^¼"},
        {"seed", ParamType::Int, 0, 0.0, 2147483647.0, {}, "Mixed with the frame index into the grain's hash"},
    };
    return s;
}

uint32_t mix(uint32_t a, uint32_t b) {
    uint32_t h = a * 0x9E3779B9u ^ (b + 0x7F4A7C15u + (a << 6) + (a >> 2));
    h ^= h >> 16;
    h *= 0x85EBCA6Bu;
    h ^= h >> 13;
    return h;
}

class Grain final : public Node {
public:
    void setup(SetupContext& ctx) override {
        if (ctx.hasInput("camera_state")) mCamera = ctx.objectAs<CameraStateObject>("camera_state");
        mPipeline = ctx.computePipeline("post/grain.comp", cameraExposureDefines(mCamera != nullptr), mCamera ? 1 : 0);
    }
    void execute(ExecuteContext& ctx) override {
        const Params& p = ctx.params();
        const ImageDesc& out = ctx.output("color").desc();
        gpu_types::GrainPush push{};
        if (mCamera) {
            // The shader scales these by the camera's ISO, which it reads on the GPU.
            push.sigma = p.getFloat("strength");
            push.size = p.getFloat("size") * float(out.height) / 1080.0f;
        } else {
            const float iso = p.getFloat("iso");
            push.sigma = p.getFloat("strength") * std::sqrt(iso / 100.0f);
            push.size = std::max(0.5f, p.getFloat("size") * std::pow(iso / 100.0f, 0.25f) * float(out.height) / 1080.0f);
        }
        push.seed = mix(ctx.frameIndex(), static_cast<uint32_t>(p.getInt("seed")));
        dispatchWithCamera(ctx, mCamera.get(), mPipeline, push, out.width, out.height);
    }

private:
    PipelineId mPipeline = 0;
    std::shared_ptr<CameraStateObject> mCamera;
};

const NodeRegistration kRegistration(schema(), [] { return std::make_unique<Grain>(); });

} // namespace
} // namespace vitrine
