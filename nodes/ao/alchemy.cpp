// ao.alchemy: Alchemy screen-space ambient obscurance (McGuire et al. 2011), MUSEUM_SPEC §5.
#include "shaders/ao/alchemy.h"
#include "core/graph/node.hpp"
#include "core/graph/registry.hpp"
#include "core/scene/gpu_scene.hpp"

#include <cmath>

namespace vitrine {
namespace {

NodeSchema schema() {
    NodeSchema s;
    s.type = "ao.alchemy";
    s.doc = "Alchemy ambient obscurance (McGuire, Osman, Bukowski, Hennessy 2011) from the G-buffer's view depth and "
            "normal: A = max(0, 1 - (2 sigma / s) sum r max(0, v.n - beta z) / (v.v + eps))^k over s points of a "
            "spiral of world radius r (rotated per pixel and per frame; samples farther than r, empty or off screen "
            "do not occlude). Full or half the G-buffer's resolution. Accumulate it with temporal.accumulate and feed "
            "lighting.deferred's `ao` (it multiplies the indirect terms by lerp(baseColor, 1, ao)).";
    s.inputs = {
        {"normal", PortKind::Texture, {}, false, Usage::Sampled,
         "G-buffer: octahedral normal, view depth (m), shininess (gbuffer.normal)"},
        {"camera", PortKind::Camera, {}, false, Usage::Sampled, "The frame's camera (positions from depth)"},
    };
    OutputPort ao;
    ao.name = "ao";
    ao.format = VK_FORMAT_R16_SFLOAT;
    ao.size = SizeRule::ofInput("normal");
    ao.doc = "Ambient visibility in r: 1 unoccluded, 0 fully occluded (1 where nothing was drawn)";
    s.outputs = {ao};
    s.params = {
        {"resolution", ParamType::Enum, "half", {}, {}, {"full", "half"}, "Of the G-buffer's size (half: rounded up)"},
        {"radius", ParamType::Float, 0.5, 0.01, 100.0, {}, "World radius r of the sampled disk (m)"},
        {"intensity", ParamType::Float, 0.15, 0.0, 100.0, {}, "sigma: strength of the obscurance (dimensionless)"},
        {"contrast", ParamType::Float, 1.0, 0.1, 8.0, {}, "k: the estimate is raised to this power"},
        {"bias", ParamType::Float, 0.002, 0.0, 1.0, {},
         "beta: v.n below beta x view depth does not occlude (m per m; absorbs the half-float depth's rounding)"},
        {"samples", ParamType::Int, 8, 1.0, 64.0, {}, "s: samples per pixel per frame"},
        {"temporal", ParamType::Bool, true, {}, {}, {},
         "Rotate the sample pattern every frame (for temporal.accumulate); off: the same pattern every frame"},
    };
    return s;
}

class Alchemy final : public Node {
public:
    void setup(SetupContext& ctx) override {
        mCamera = ctx.objectAs<CameraObject>("camera");
        if (ctx.params().getString("resolution") == "half") {
            const ImageDesc& in = ctx.input("normal");
            ImageDesc& out = ctx.output("ao");
            out.width = (in.width + 1) / 2;
            out.height = (in.height + 1) / 2;
        }
        mPipeline = ctx.computePipeline("ao/alchemy.comp");
    }
    void execute(ExecuteContext& ctx) override {
        const Params& p = ctx.params();
        const CameraFrame& cam = mCamera->current;
        const ImageDesc& normal = ctx.input("normal").desc();
        gpu_types::AlchemyPush push{};
        push.invViewProj = cam.invViewProj;
        push.cameraPos = glm::vec4(cam.state.position, 0.5f * static_cast<float>(normal.height) * std::abs(cam.proj[1][1]));
        // Cameras look down their local -Z; the view matrix's third row is +Z in world space.
        const glm::vec3 forward(-cam.state.view[0][2], -cam.state.view[1][2], -cam.state.view[2][2]);
        push.forward = glm::vec4(glm::normalize(forward), 0.0f);
        push.params = {p.getFloat("radius"), p.getFloat("intensity"), p.getFloat("bias"), p.getFloat("contrast")};
        push.samples = static_cast<uint32_t>(p.getInt("samples"));
        push.frame = p.getBool("temporal") ? ctx.frameIndex() : 0u;
        const ImageDesc& out = ctx.output("ao").desc();
        ctx.dispatch(mPipeline, push, out.width, out.height);
    }

private:
    std::shared_ptr<CameraObject> mCamera;
    PipelineId mPipeline = 0;
};

const NodeRegistration kRegistration(schema(), [] { return std::make_unique<Alchemy>(); });

} // namespace
} // namespace vitrine
