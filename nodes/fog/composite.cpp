// fog.composite: fog.volumetric's low-resolution march, upsampled by depth and applied to the colour.
#include "core/graph/registry.hpp"
#include "core/scene/gpu_scene.hpp"
#include "shaders/fog/composite.h"

namespace vitrine {
namespace {

NodeSchema schema() {
    NodeSchema s;
    s.type = "fog.composite";
    s.doc = "Applies volumetric fog to the colour: colour x transmittance + in-scattered radiance, from fog.volumetric's "
            "low-resolution march (or a temporal accumulation of it) upsampled with a joint bilateral filter on "
            "distance, so fog never bleeds across a depth edge.";
    auto tex = [](const char* name, const char* doc) {
        return InputPort{name, PortKind::Texture, {}, false, Usage::Sampled, doc};
    };
    s.inputs = {
        tex("color", "HDR colour to fog (linear radiance)"),
        tex("depth", "G-buffer hardware depth (reverse Z), full resolution"),
        tex("scatter", "fog.volumetric's `scatter` (in-scattering rgb, transmittance a), any resolution"),
        tex("distance", "fog.volumetric's `distance` (same size as scatter)"),
        {"camera", PortKind::Camera, {}, false, Usage::Sampled, "The frame's camera"},
    };
    OutputPort color;
    color.name = "color";
    color.formatFrom = "color";
    color.size = SizeRule::ofInput("color");
    color.doc = "The fogged colour";
    s.outputs = {color};
    s.params = {
        {"depth_sigma", ParamType::Float, 0.05, 0.001, 1.0, {},
         "Relative distance difference at which a low-resolution sample's weight falls to exp(-1/2)"},
    };
    return s;
}

class Composite final : public Node {
public:
    void setup(SetupContext& ctx) override {
        mCamera = ctx.objectAs<CameraObject>("camera");
        const ImageDesc& color = ctx.input("color");
        const ImageDesc& depth = ctx.input("depth");
        if (color.width != depth.width || color.height != depth.height)
            ctx.failParam("depth_sigma", "color and depth must have the same size (got " + std::to_string(color.width) +
                                             "x" + std::to_string(color.height) + " and " +
                                             std::to_string(depth.width) + "x" + std::to_string(depth.height) + ")");
        const ImageDesc& scatter = ctx.input("scatter");
        const ImageDesc& distance = ctx.input("distance");
        if (scatter.width != distance.width || scatter.height != distance.height)
            ctx.failParam("depth_sigma", "scatter and distance must have the same size (fog.volumetric's two outputs)");
        mPipeline = ctx.computePipeline("fog/composite.comp");
    }

    void execute(ExecuteContext& ctx) override {
        const CameraFrame& cam = mCamera->current;
        gpu_types::FogCompositePush push{};
        push.invViewProj = cam.invViewProj;
        push.cameraPos = glm::vec4(cam.state.position, 0.0f);
        push.depthSigma = ctx.params().getFloat("depth_sigma");
        const ImageDesc& out = ctx.output("color").desc();
        ctx.dispatch(mPipeline, push, out.width, out.height);
    }

private:
    std::shared_ptr<CameraObject> mCamera;
    PipelineId mPipeline = 0;
};

const NodeRegistration kRegistration(schema(), [] { return std::make_unique<Composite>(); });

} // namespace
} // namespace vitrine
