// post.tonemap: exposure and a tone curve, applied to the finished HDR image.
#include "core/graph/node.hpp"
#include "core/graph/registry.hpp"
#include "nodes/camera/camera_state.hpp"
#include "shaders/post/tonemap.h"

#include <cmath>

namespace vitrine {
namespace {

NodeSchema schema() {
    NodeSchema s;
    s.type = "post.tonemap";
    s.doc = "Exposure (EV) then a tone curve: ACES fit or Khronos PBR Neutral for display, or an exactly invertible "
            "Reinhard curve.";
    s.inputs = {{"color", PortKind::Texture, {}, false, Usage::Sampled, "Linear HDR colour"},
                {"camera_state", PortKind::Buffer, {}, true, Usage::Sampled,
                 "camera.physical's state: when connected, its exposure replaces the `exposure` param"}};
    OutputPort out;
    out.name = "color";
    out.formatFrom = "color";
    out.size = SizeRule::ofInput("color");
    out.doc = "Tone-mapped linear colour in [0, 1] (or linear HDR when inverse)";
    s.outputs = {out};
    s.params = {
        {"exposure", ParamType::Float, 0.0, -24.0, 24.0, {},
         "Exposure in stops: colour is scaled by 2^exposure (ignored when camera_state is connected)"},
        {"operator", ParamType::Enum, "aces_fit", {}, {}, {"linear", "reinhard", "reinhard_max", "aces_fit", "pbr_neutral"},
         "Tone curve; reinhard and reinhard_max are exactly invertible. pbr_neutral: Khronos PBR Neutral (the glTF "
         "Sample Viewer's), which keeps base colours below 0.76 as they are (less the 0.04 of a dielectric's "
         "reflection) and rolls brighter colours off towards white without shifting their hue; aces_fit: the "
         "Narkowicz fit of ACES, which shifts saturated colours (orange to amber, blue to cyan)"},
        {"inverse", ParamType::Bool, false, {}, {}, {},
         "Undo the curve and the exposure (invertible operators only): the round trip TAA relies on"},
    };
    return s;
}

class Tonemap final : public Node {
public:
    void setup(SetupContext& ctx) override {
        const auto& p = ctx.params();
        const std::string op = p.getString("operator");
        if (p.getBool("inverse") && (op == "aces_fit" || op == "pbr_neutral"))
            ctx.failParam("inverse", op + " is not invertible here; use linear, reinhard or reinhard_max");
        if (ctx.hasInput("camera_state")) mCamera = ctx.objectAs<CameraStateObject>("camera_state");
        mPipeline = ctx.computePipeline("post/tonemap.comp", cameraExposureDefines(mCamera != nullptr), mCamera ? 1 : 0);
    }
    void execute(ExecuteContext& ctx) override {
        const auto& p = ctx.params();
        gpu_types::TonemapPush push{};
        push.exposureScale = mCamera ? 1.0f : std::exp2(p.getFloat("exposure")); // the shader reads the camera's
        push.op = static_cast<uint32_t>(p.getEnumIndex("operator"));
        push.inverse = p.getBool("inverse") ? 1u : 0u;
        const ImageDesc& out = ctx.output("color").desc();
        dispatchWithCamera(ctx, mCamera.get(), mPipeline, push, out.width, out.height);
    }

private:
    PipelineId mPipeline = 0;
    std::shared_ptr<CameraStateObject> mCamera;
};

const NodeRegistration kRegistration(schema(), [] { return std::make_unique<Tonemap>(); });

} // namespace
} // namespace vitrine
