// post.motion_blur: reconstruction-filter motion blur from the velocity buffer (McGuire et al. 2012).
#include "shaders/post/motion_blur.h"
#include "core/graph/node.hpp"
#include "core/graph/registry.hpp"
#include "nodes/camera/camera_state.hpp"

#include <algorithm>

namespace vitrine {
namespace {

NodeSchema schema() {
    NodeSchema s;
    s.type = "post.motion_blur";
    s.doc = "Motion blur by McGuire et al. 2012's reconstruction filter: the largest velocity per tile (tile_size "
            "pixels), its 3 x 3 neighbourhood maximum, then per pixel `samples` taps along that velocity, split by a "
            "soft depth test into occluders (blurry things in front, weighted by how much of the shutter they cover "
            "the pixel) and the pixel's own layer (box filter over its own blur). The blur spans |velocity| x scale "
            "pixels centred on the pixel (scale: the fraction of a frame the shutter is open), or, with "
            "shutter_driven, |velocity| x shutter x fps.";
    auto tex = [](const char* name, const char* doc) {
        return InputPort{name, PortKind::Texture, {}, false, Usage::Sampled, doc};
    };
    s.inputs = {
        tex("color", "Linear HDR colour"),
        tex("velocity", "Screen motion in pixels, this frame minus last (gbuffer.velocity), the colour's size"),
        tex("depth", "Linear view depth in z, 0 where empty (gbuffer.normal), the colour's size"),
        {"camera_state",
         PortKind::Buffer,
         {},
         true,
         Usage::Sampled,
         "camera.physical's state: its shutter time replaces the `shutter` param (with shutter_driven)"},
    };
    OutputPort color;
    color.name = "color";
    color.formatFrom = "color";
    color.size = SizeRule::ofInput("color");
    color.doc = "Motion-blurred colour";
    OutputPort tileMax;
    tileMax.name = "tile_max";
    tileMax.format = VK_FORMAT_R16G16_SFLOAT;
    tileMax.usage = Usage::StorageReadWrite;
    tileMax.doc = "Per tile, the largest half-velocity (pixels) in it";
    OutputPort neighborMax = tileMax;
    neighborMax.name = "neighbor_max";
    neighborMax.doc = "Per tile, the largest tile_max of its 3 x 3 neighbourhood";
    s.outputs = {color, tileMax, neighborMax};
    s.params = {
        {"scale",
         ParamType::Float,
         0.5,
         0.0,
         4.0,
         {},
         "Blur length / velocity: the fraction of a frame interval the shutter is open (0.5: a 180-degree shutter); "
         "unused with shutter_driven"},
        {"shutter_driven",
         ParamType::Bool,
         false,
         {},
         {},
         {},
         "Blur length = velocity x shutter time x fps (the camera's shutter from camera_state, else `shutter`)"},
        {"shutter",
         ParamType::Float,
         1.0 / 48.0,
         1e-5,
         10.0,
         {},
         "Shutter time in seconds (shutter_driven without camera_state)"},
        {"fps", ParamType::Float, 24.0, 1.0, 1000.0, {}, "Frame rate of the velocity buffer (the scene's fps)"},
        {"tile_size",
         ParamType::Int,
         20,
         2.0,
         64.0,
         {},
         "K: tile side in pixels; also the largest half-length of a blur (longer ones are clamped)"},
        {"samples", ParamType::Int, 15, 1.0, 64.0, {}, "S: taps per pixel along the neighbourhood's velocity"},
        {"soft_z",
         ParamType::Float,
         0.1,
         1e-4,
         100.0,
         {},
         "Metres of depth over which a tap turns from 'same layer' to 'in front'"},
        {"dither",
         ParamType::Bool,
         true,
         {},
         {},
         {},
         "Jitter the taps per pixel and frame (noise instead of banding; off for exact tests)"},
    };
    return s;
}

class MotionBlur final : public Node {
public:
    void setup(SetupContext& ctx) override {
        const ImageDesc& color = ctx.input("color");
        for (const char* port : {"velocity", "depth"}) {
            const ImageDesc& d = ctx.input(port);
            if (d.width != color.width || d.height != color.height)
                ctx.failParam("tile_size", std::string(port) + " must have the colour's size (" +
                                               std::to_string(color.width) + "x" + std::to_string(color.height) +
                                               "), got " + std::to_string(d.width) + "x" + std::to_string(d.height));
        }
        mTile = static_cast<uint32_t>(ctx.params().getInt("tile_size"));
        for (const char* port : {"tile_max", "neighbor_max"}) {
            ImageDesc& t = ctx.output(port);
            t.width = (color.width + mTile - 1) / mTile;
            t.height = (color.height + mTile - 1) / mTile;
        }
        // Shutter-driven by a camera: the shutter is the camera's, which the shaders read on the GPU.
        if (ctx.params().getBool("shutter_driven") && ctx.hasInput("camera_state"))
            mCamera = ctx.objectAs<CameraStateObject>("camera_state");
        const ShaderDefines defines = cameraExposureDefines(mCamera != nullptr);
        mTilesPipeline = ctx.computePipeline("post/motion_blur_tiles.comp", defines, mCamera ? 1 : 0);
        mNeighborsPipeline = ctx.computePipeline("post/motion_blur_neighbors.comp");
        mGatherPipeline = ctx.computePipeline("post/motion_blur.comp", defines, mCamera ? 1 : 0);
    }
    void execute(ExecuteContext& ctx) override {
        const auto& p = ctx.params();
        float scale = p.getFloat("scale");
        if (p.getBool("shutter_driven")) {
            float shutter = mCamera ? 1.0f : p.getFloat("shutter");
            scale = shutter * p.getFloat("fps");
        }
        gpu_types::MotionBlurPush push{};
        push.halfScale = 0.5f * scale;
        push.maxRadius = static_cast<float>(mTile);
        push.tileSize = static_cast<int>(mTile);
        push.samples = static_cast<uint32_t>(p.getInt("samples"));
        push.softZ = p.getFloat("soft_z");
        push.dither = p.getBool("dither") ? 1.0f : 0.0f;
        push.frame = ctx.frameIndex();
        const ImageDesc& tiles = ctx.output("tile_max").desc();
        dispatchWithCamera(ctx, mCamera.get(), mTilesPipeline, push, tiles.width, tiles.height);
        ctx.computeBarrier();
        ctx.dispatch(mNeighborsPipeline, nullptr, 0, tiles.width, tiles.height); // no push constants
        ctx.computeBarrier();
        const ImageDesc& out = ctx.output("color").desc();
        dispatchWithCamera(ctx, mCamera.get(), mGatherPipeline, push, out.width, out.height);
    }

private:
    std::shared_ptr<CameraStateObject> mCamera;
    uint32_t mTile = 20;
    PipelineId mTilesPipeline = 0, mNeighborsPipeline = 0, mGatherPipeline = 0;
};

const NodeRegistration kRegistration(schema(), [] { return std::make_unique<MotionBlur>(); });

} // namespace
} // namespace vitrine
