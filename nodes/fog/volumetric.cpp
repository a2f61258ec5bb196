// fog.volumetric: the low-resolution ray march of the volumetric fog (sun shafts through the shadow map, sky
// ambient); fog.composite applies it to the colour.
#include "core/graph/registry.hpp"
#include "core/scene/gpu_scene.hpp"
#include "nodes/shadow/cascades.hpp"
#include "shaders/fog/volumetric.h"

#include <algorithm>
#include <cmath>

namespace vitrine {
namespace {

NodeSchema schema() {
    NodeSchema s;
    s.type = "fog.volumetric";
    s.doc = "Volumetric fog (MUSEUM_SPEC §5), the march: at low resolution, from the camera to the G-buffer's surface "
            "through a medium of density sigma (optionally falling off with height), in-scattering the sun "
            "(Henyey-Greenstein phase, visibility from shadow.directional's cascades: light shafts) and the sky's SH "
            "radiance convolved with the same phase as ambient. Outputs in-scattered radiance + transmittance and the "
            "distance marched; fog.composite upsamples them by depth onto the colour (a temporal.accumulate may sit "
            "between the two).";
    auto tex = [](const char* name, const char* doc, bool optional = false) {
        return InputPort{name, PortKind::Texture, {}, optional, Usage::Sampled, doc};
    };
    s.inputs = {
        tex("depth", "G-buffer hardware depth (reverse Z): where each ray ends"),
        tex("shadow_map", "shadow.directional's atlas (without it the sun lights all the air)", true),
        {"cascades", PortKind::Buffer, {}, true, Usage::Sampled, "shadow.directional's cascades"},
        tex("sky_sh", "A sky node's `sh`: SH9 radiance (ambient in-scattering), sun illuminance and direction"),
        {"camera", PortKind::Camera, {}, false, Usage::Sampled, "The frame's camera"},
    };
    OutputPort scatter;
    scatter.name = "scatter";
    scatter.size = SizeRule::ofInput("depth");
    scatter.doc = "Low resolution: in-scattered radiance towards the camera (rgb, cd/m²) and transmittance to the "
                  "surface (a)";
    OutputPort distance;
    distance.name = "distance";
    distance.format = VK_FORMAT_R32_SFLOAT;
    distance.size = SizeRule::ofInput("depth");
    distance.doc = "Low resolution: the distance (m) from the camera to the surface each pixel marched to (1e6: sky), "
                   "for fog.composite's depth-aware upsample";
    s.outputs = {scatter, distance};
    s.params = {
        {"density", ParamType::Float, 0.01, 0.0, 10.0, {},
         "Extinction coefficient sigma (1/m) at height_reference; scattering albedo 1 (all extinction is scattering)"},
        {"anisotropy", ParamType::Float, 0.5, -0.95, 0.95, {},
         "Henyey-Greenstein g: > 0 scatters forward (shafts brighten looking toward the sun), 0 isotropic"},
        {"height_falloff", ParamType::Float, 0.0, 0.0, 10.0, {},
         "Density falls off as exp(-falloff (y - height_reference)) (1/m); 0: homogeneous"},
        {"height_reference", ParamType::Float, 0.0, -1e4, 1e4, {}, "Height (world y, m) where the density is `density`"},
        {"steps", ParamType::Int, 32, 1.0, 256.0, {}, "March steps per pixel (equal steps from camera to surface)"},
        {"resolution", ParamType::Float, 0.5, 0.125, 1.0, {}, "March resolution relative to the depth input"},
        {"sun_scale", ParamType::Float, 1.0, 0.0, 100.0, {}, "Multiplier of the sky model's sun illuminance"},
        {"ambient_scale", ParamType::Float, 0.15, 0.0, 10.0, {},
         "Multiplier of the sky's ambient in-scattering (a stand-in for the occlusion of the sky indoors)"},
        {"shadows", ParamType::Bool, true, {}, {}, {}, "Sun visibility from the shadow map (off: the sun lights all air)"},
        {"max_distance", ParamType::Float, 50.0, 0.1, 1e4, {}, "Distance (m) marched where the G-buffer is empty (sky)"},
        {"jitter", ParamType::Enum, "pixel", {}, {}, {"pixel", "off"},
         "Start of the march within the first step: pixel = interleaved gradient noise moved by the golden ratio each "
         "frame (for temporal accumulation), off = the middle of each step"},
    };
    return s;
}

class Volumetric final : public Node {
public:
    void setup(SetupContext& ctx) override {
        mCamera = ctx.objectAs<CameraObject>("camera");
        if (ctx.hasInput("shadow_map") != ctx.hasInput("cascades"))
            ctx.failParam("shadows", "connect both shadow_map and cascades of a shadow.directional node, or neither");
        if (ctx.hasInput("cascades")) mCascades = ctx.objectAs<ShadowCascadesObject>("cascades");
        const ImageDesc& depth = ctx.input("depth");
        const float scale = ctx.params().getFloat("resolution");
        for (const char* port : {"scatter", "distance"}) {
            ImageDesc& out = ctx.output(port);
            out.width = std::max(1u, static_cast<uint32_t>(std::ceil(depth.width * scale)));
            out.height = std::max(1u, static_cast<uint32_t>(std::ceil(depth.height * scale)));
        }
        mPipeline = ctx.computePipeline("fog/volumetric.comp");
    }

    void execute(ExecuteContext& ctx) override {
        const Params& p = ctx.params();
        const CameraFrame& cam = mCamera->current;
        gpu_types::FogMarchUniforms u{};
        u.invViewProj = cam.invViewProj;
        u.cameraPos = glm::vec4(cam.state.position, p.getFloat("max_distance"));
        u.cameraFwd = glm::vec4(glm::normalize(cam.state.orientation * glm::vec3(0.0f, 0.0f, -1.0f)), 0.0f);
        u.medium = {p.getFloat("density"), p.getFloat("height_falloff"), p.getFloat("height_reference"),
                    p.getFloat("anisotropy")};
        const bool shadows = p.getBool("shadows") && mCascades;
        const bool jitter = p.getString("jitter") == "pixel";
        u.lighting = {p.getFloat("sun_scale"), p.getFloat("ambient_scale"), shadows ? 1.0f : 0.0f, jitter ? -1.0f : 0.5f};
        const ImageDesc& depth = ctx.input("depth").desc();
        u.march = {static_cast<uint32_t>(p.getInt("steps")), depth.width, depth.height, ctx.frameIndex()};
        if (mCascades) u.shadow = mCascades->data;
        else u.shadow.params = {1.0f, 1.0f, 0.0f, 0.0f};
        ctx.setUniforms(u);
        const ImageDesc& out = ctx.output("scatter").desc();
        ctx.dispatch(mPipeline, nullptr, 0, out.width, out.height);
    }

private:
    std::shared_ptr<CameraObject> mCamera;
    std::shared_ptr<ShadowCascadesObject> mCascades;
    PipelineId mPipeline = 0;
};

const NodeRegistration kRegistration(schema(), [] { return std::make_unique<Volumetric>(); });

} // namespace
} // namespace vitrine
