// post.dof: optics-based bokeh depth of field after Kawase 2008/2012 (MUSEUM_SPEC §7): thin-lens CoC, layers,
// scatter for the pixels that matter, gather for the rest. Passes: shaders/post/dof_coc, dof_classify, dof_gather.
#include "shaders/post/dof.h"
#include "core/graph/node.hpp"
#include "core/graph/registry.hpp"
#include "core/scene/aperture.hpp"
#include "core/scene/gpu_scene.hpp"
#include "nodes/camera/camera_state.hpp"

#include <algorithm>
#include <cmath>
#include <string>

namespace vitrine {
namespace {

NodeSchema schema() {
    NodeSchema s;
    s.type = "post.dof";
    s.doc = "Bokeh depth of field from the thin-lens model (Kawase 2008/2012): the signed circle of confusion of every "
            "pixel from focal length, f-number, focus distance and sensor (params, the scene camera's lens, or a "
            "connected camera_state), optionally resolved over frames so TAA's jitter does not make it flicker; the "
            "frame's CoC range cut into up to 15 layers, each gathered at full resolution with an aperture-shaped kernel and "
            "composited far to near; out-of-focus bright points and bright edges scattered as sprites of the aperture "
            "(a polygon of the blade count, round wide open) from a capped list. Autofocus reads the depth at a point.";
    auto tex = [](const char* name, bool optional, const char* doc) {
        return InputPort{name, PortKind::Texture, {}, optional, Usage::Sampled, doc};
    };
    s.inputs = {
        tex("color", false, "Linear HDR colour"),
        tex("depth", false, "G-buffer hardware depth (reverse Z), same size as color"),
        {"camera", PortKind::Camera, {}, false, Usage::Sampled,
         "The frame's camera: projection (depth to distance) and, without params or camera_state, the lens"},
        {"camera_state", PortKind::Buffer, {}, true, Usage::Sampled,
         "camera.physical's state: f-number, focus distance, focal length, sensor and blades replace the params"},
        tex("coc_history", true,
            "This node's own coc@prev: the CoC is blended with it (coc_feedback), so jitter does not flicker it"),
        tex("velocity", true, "Screen motion in pixels (gbuffer.velocity), to reproject coc_history"),
    };
    auto storage = [](const char* name, VkFormat format, const char* doc) {
        OutputPort o;
        o.name = name;
        o.format = format;
        o.size = SizeRule::ofInput("color");
        o.usage = Usage::StorageReadWrite;
        o.doc = doc;
        return o;
    };
    OutputPort color;
    color.name = "color";
    color.formatFrom = "color";
    color.size = SizeRule::ofInput("color");
    color.doc = "The colour with depth of field";
    s.outputs = {
        color,
        storage("coc", VK_FORMAT_R32_SFLOAT,
                "Signed CoC diameter in pixels (negative in front of the focus plane), resolved when coc_history is "
                "connected (its history)"),
        storage("prepared", VK_FORMAT_R32G32B32A32_SFLOAT,
                "Internal: the colour left to gather after the sprites took theirs; alpha: the pixel's layer"),
        storage("tiles", VK_FORMAT_R32_UINT, "Internal: per 16x16 tile, a bit per layer present"),
        storage(
            "sprite_count", VK_FORMAT_R32_UINT,
            "Internal: 2x1, pixels that asked to scatter (the list keeps max_sprites); the largest |CoC| (float bits)"),
        storage("sprites", VK_FORMAT_R32G32B32A32_SFLOAT,
                "Internal: the scatter list, two texels a sprite (x, y, CoC; colour)"),
    };
    s.params = {
        {"f_number", ParamType::Float, 0.0, 0.0, 256.0, {}, "f-number N (aperture diameter f / N). 0: the scene camera's"},
        {"focus_distance", ParamType::Float, 0.0, 0.0, 1e6, {},
         "Distance of the plane in focus along the view axis (m). 0: the scene camera's"},
        {"autofocus", ParamType::Vec2, nlohmann::json::array({-1.0, -1.0}), {}, {}, {},
         "Screen point (0..1, y down) whose depth is the focus distance; negative: off (focus_distance)"},
        {"blades", ParamType::Int, -1, -1.0, 32.0, {}, "Aperture blades (0: a circle). -1: the scene camera's"},
        {"blade_roundness", ParamType::Float, 0.0, 0.0, 1.0, {},
         "0 straight blades (a polygon) .. 1 a circle, once stopped down a stop or more"},
        {"blade_rotation", ParamType::Float, 0.0, -360.0, 360.0, {},
         "Angle of the aperture's first corner in degrees, counter-clockwise from the image's +x"},
        {"wide_open_f_number", ParamType::Float, 1.4, 0.5, 256.0, {},
         "The lens's largest aperture: round at it, the blades' shape a stop down (core/scene/aperture.hpp)"},
        {"layers", ParamType::Int, 15, 3.0, 15.0, {}, "Layers the CoC range is cut into (the demo: up to 15)"},
        {"max_coc", ParamType::Float, 24.0, 1.0, 64.0, {}, "Largest CoC diameter in pixels (larger ones are clamped)"},
        {"scatter_ratio", ParamType::Float, 4.0, 1.0, 1e6, {},
         "A pixel scatters when its luminance exceeds its 8 neighbours' mean this many times"},
        {"scatter_min_coc", ParamType::Float, 3.0, 1.0, 64.0, {}, "... and its CoC diameter is at least this (pixels)"},
        {"max_sprites", ParamType::Int, 1024, 0.0, DOF_MAX_SPRITES, {},
         "Cap of the scatter list (the rest is gathered); 0: gather only"},
        {"coc_feedback", ParamType::Float, 0.9, 0.0, 0.99, {},
         "With coc_history: weight of the reprojected history (clamped to the 3x3 range of this frame's CoC)"},
    };
    return s;
}

class Dof final : public Node {
public:
    void setup(SetupContext& ctx) override {
        const Params& p = ctx.params();
        mCamera = ctx.objectAs<CameraObject>("camera");
        if (ctx.hasInput("camera_state")) mState = ctx.objectAs<CameraStateObject>("camera_state");
        const ImageDesc& color = ctx.input("color");
        const ImageDesc& depth = ctx.input("depth");
        if (color.width != depth.width || color.height != depth.height)
            ctx.failParam("max_coc", "color and depth must have the same size (got " + std::to_string(color.width) +
                                         "x" + std::to_string(color.height) + " and " + std::to_string(depth.width) +
                                         "x" + std::to_string(depth.height) + ")");
        if (p.getFloat("f_number") > 0.0f && p.getFloat("f_number") < p.getFloat("wide_open_f_number"))
            ctx.failParam("f_number", "f/" + std::to_string(p.getFloat("f_number")) +
                                          " is wider than the lens opens (wide_open_f_number)");
        const glm::vec2 af = p.getVec2("autofocus");
        if ((af.x >= 0.0f || af.y >= 0.0f) && (af.x < 0.0f || af.x > 1.0f || af.y < 0.0f || af.y > 1.0f))
            ctx.failParam("autofocus", "expected a screen point in [0, 1]^2, or negative for off");
        if (ctx.hasInput("coc_history") && !ctx.hasInput("velocity"))
            ctx.failParam("coc_feedback", "coc_history needs velocity (gbuffer.velocity) to reproject it");
        ImageDesc& tiles = ctx.output("tiles");
        tiles.width = (color.width + DOF_TILE - 1) / DOF_TILE;
        tiles.height = (color.height + DOF_TILE - 1) / DOF_TILE;
        ImageDesc& count = ctx.output("sprite_count");
        count.width = 2;
        count.height = 1;
        ImageDesc& sprites = ctx.output("sprites");
        sprites.width = 2 * std::max(1, p.getInt("max_sprites"));
        sprites.height = 1;
        mClear = ctx.computePipeline("post/dof_clear.comp");
        // With camera_state the f-number, and the aperture's roundness and area at it, are read on the GPU.
        const ShaderDefines defines = cameraExposureDefines(mState != nullptr);
        mCoc = ctx.computePipeline("post/dof_coc.comp", defines, mState ? 1 : 0);
        mClassify = ctx.computePipeline("post/dof_classify.comp");
        mGather = ctx.computePipeline("post/dof_gather.comp", defines, mState ? 1 : 0);
    }

    void execute(ExecuteContext& ctx) override {
        const Params& p = ctx.params();
        const CameraFrame& cam = mCamera->current;
        const scene::Camera& lens = cam.state.lens;
        float fNumber = p.getFloat("f_number") > 0.0f ? p.getFloat("f_number") : lens.fNumber;
        float focus = p.getFloat("focus_distance") > 0.0f ? p.getFloat("focus_distance") : lens.focusDistance;
        float focalMm = lens.focalLengthMm(), sensorMm = lens.sensorHeightMm;
        int bladesParam = p.getInt("blades");
        uint32_t blades = bladesParam >= 0 ? static_cast<uint32_t>(bladesParam) : lens.apertureBlades;
        float roundness = p.getFloat("blade_roundness"), rotation = glm::radians(p.getFloat("blade_rotation"));
        float wideOpen = p.getFloat("wide_open_f_number");
        if (mState) {
            const CameraState& s = mState->state;
            fNumber = 1.0f; // cocScale per unit 1 / f-number: dof_coc.comp divides by the camera's
            focus = s.focusDistanceM;
            focalMm = s.focalLengthMm;
            sensorMm = s.sensorHeightMm;
            blades = static_cast<uint32_t>(std::max(0, s.bladeCount));
            roundness = s.bladeRoundness;
            rotation = s.bladeRotation;
            wideOpen = s.wideOpenFNumber;
        }
        const ImageDesc& out = ctx.output("color").desc();
        const float f = focalMm * 1e-3f;
        const scene::ApertureShape shape = scene::apertureAt(blades, roundness, rotation, fNumber, wideOpen);

        gpu_types::DofPush push{};
        push.cocScale = f * f / fNumber / (sensorMm * 1e-3f) * static_cast<float>(out.height);
        push.focalLength = f;
        push.focusDistance = focus;
        push.maxCoc = p.getFloat("max_coc");
        push.depthA = cam.projNoJitter[2][2];
        push.depthB = cam.projNoJitter[3][2];
        const glm::vec2 af = p.getVec2("autofocus");
        push.autofocus = af.x >= 0.0f ? glm::min(af * glm::vec2(out.width, out.height), glm::vec2(out.width - 1, out.height - 1))
                                      : glm::vec2(-1.0f);
        push.blades = shape.blades;
        push.roundness = shape.roundness;
        push.rotation = shape.rotation;
        push.apertureArea = mState ? 0.0f : scene::apertureArea(shape); // the camera's, on the GPU
        push.layers = static_cast<uint32_t>(p.getInt("layers"));
        push.maxSprites = static_cast<uint32_t>(p.getInt("max_sprites"));
        push.scatterRatio = p.getFloat("scatter_ratio");
        push.scatterMinCoc = p.getFloat("scatter_min_coc");
        push.historyWeight = ctx.hasInput("coc_history") && ctx.inputValid("coc_history") ? p.getFloat("coc_feedback") : 0.0f;
        push.hasVelocity = ctx.hasInput("velocity") ? 1u : 0u;
        push.tilesX = (out.width + DOF_TILE - 1) / DOF_TILE;
        ctx.dispatch(mClear, push, 1, 1);
        ctx.computeBarrier();
        dispatchWithCamera(ctx, mState.get(), mCoc, push, out.width, out.height);
        ctx.computeBarrier();
        ctx.dispatch(mClassify, push, out.width, out.height);
        ctx.computeBarrier();
        dispatchWithCamera(ctx, mState.get(), mGather, push, out.width, out.height);
    }

private:
    std::shared_ptr<CameraObject> mCamera;
    std::shared_ptr<CameraStateObject> mState;
    PipelineId mClear = 0, mCoc = 0, mClassify = 0, mGather = 0;
};

const NodeRegistration kRegistration(schema(), [] { return std::make_unique<Dof>(); });

} // namespace
} // namespace vitrine
