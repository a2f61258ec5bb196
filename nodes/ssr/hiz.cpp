// ssr.hiz: Hi-Z screen-space cone-traced reflections [Uludag14] with the Museum demo's changes (MUSEUM_SPEC §5).
#include "shaders/ssr/hiz.h"
#include "core/base/error.hpp"
#include "core/graph/registry.hpp"
#include "core/scene/gpu_scene.hpp"
#include "nodes/depth/mip_atlas.hpp"

#include <algorithm>
#include <cmath>

namespace vitrine {
namespace {

NodeSchema schema() {
    NodeSchema s;
    s.type = "ssr.hiz";
    s.doc = "Screen-space reflections, the Museum demo's recipe: at reduced resolution, 1-4 rays per pixel by "
            "roughness, directions from GGX visible-normal sampling [Heitz18], each ray marched through depth.hiz's "
            "min/max pyramid with at most max_taps fetches [Uludag14], the hit's colour read from color.pyramid at "
            "the level of the ray's cone footprint (cone tracing), weighted by a confidence (screen-edge fade, "
            "back-face test, thickness test, ray-length fade). No spatial blur; temporal accumulation belongs "
            "between this node and ssr.composite.";
    auto tex = [](const char* name, const char* doc, bool optional = false, Usage usage = Usage::Sampled) {
        return InputPort{name, PortKind::Texture, {}, optional, usage, doc};
    };
    s.inputs = {
        tex("normal", "G-buffer: octahedral normal, view depth, shininess (gbuffer.normal)"),
        tex("depth", "Hardware depth, reverse Z (gbuffer.depth)"),
        tex("hiz", "depth.hiz of the same depth", false, Usage::StorageRead),
        tex("color", "color.pyramid of the lit colour (the same size as depth)"),
        tex("velocity",
            "gbuffer.velocity: when connected, hits are reprojected into the pyramid as last frame's colour (from "
            "the second frame on)",
            true),
        {"camera", PortKind::Camera, {}, false, Usage::Sampled, "The frame's camera"},
    };
    OutputPort out;
    out.name = "reflection";
    out.format = VK_FORMAT_R16G16B16A16_SFLOAT;
    out.size = SizeRule::ofInput("normal", 0.5f);
    out.doc = "Premultiplied: rgb = reflected radiance (the confidence-weighted mean of the rays that hit, before the "
              "BRDF) x a; a = confidence 0..1 (the mean over the rays; 0 where nothing was found). Premultiplied so "
              "that temporal.accumulate's mean and ssr.composite's bilinear upsampling are linear";
    s.outputs = {out};
    s.params = {
        {"resolution_scale", ParamType::Float, 0.5, 0.125, 1.0, {}, "Output size relative to the G-buffer"},
        {"max_taps",
         ParamType::Int,
         32,
         1.0,
         1024.0,
         {},
         "Hi-Z fetches per ray at most (rays leaving a floor at grazing angles need about 32 to reach what it "
         "reflects: the Museum's floor at 16 found most of its hits nowhere; at 32 it misses the columns' "
         "reflections below them, whose rays skim the floor a texel per fetch: museum.json sets 64)"},
        {"max_rays",
         ParamType::Int,
         4,
         1.0,
         4.0,
         {},
         "Rays per pixel at most (1 for mirrors, more as roughness grows)"},
        {"thickness", ParamType::Float, 0.3, 1e-4, 100.0, {}, "Depth (m) assumed behind every visible surface"},
        {"max_distance", ParamType::Float, 30.0, 0.01, 1e5, {}, "Ray length (m); the last quarter fades out"},
        {"edge_fade",
         ParamType::Float,
         0.05,
         1e-4,
         0.5,
         {},
         "Fraction of the screen over which hits fade at its edges"},
        {"max_roughness",
         ParamType::Float,
         0.7,
         0.01,
         1.0,
         {},
         "Roughness beyond which there is no SSR (fading over the last quarter)"},
        {"cone_scale",
         ParamType::Float,
         1.0,
         0.0,
         4.0,
         {},
         "Scale of the cone whose footprint at the hit picks the colour pyramid's level: 1 is the GGX lobe's share "
         "of each ray (half-angle tan 1.29 alpha / sqrt(rays)) [Uludag14]; 0 reads level 0 and leaves the lobe to "
         "the rays and the temporal accumulation. Each ray is already a sample of the lobe, so the full cone blurs "
         "by the lobe twice, and isotropically where a grazing lobe is long and thin (museum.json: 0.5)"},
    };
    return s;
}

class SsrHiz final : public Node {
public:
    void setup(SetupContext& ctx) override {
        mCamera = ctx.objectAs<CameraObject>("camera");
        const ImageDesc& depth = ctx.input("depth");
        ImageDesc atlas;
        sizeMipAtlas(atlas, depth.width, depth.height);
        for (const char* port : {"hiz", "color"}) {
            const ImageDesc& in = ctx.input(port);
            if (in.width != atlas.width || in.height != atlas.height)
                throw UserError(std::string("ssr.hiz: input ") + port + " is " + std::to_string(in.width) + "x" +
                                std::to_string(in.height) + ", expected the mip atlas of the " +
                                std::to_string(depth.width) + "x" + std::to_string(depth.height) + " depth (" +
                                std::to_string(atlas.width) + "x" + std::to_string(atlas.height) + "): connect " +
                                (std::string(port) == "hiz" ? "depth.hiz" : "color.pyramid") +
                                " of an image of the depth's size");
        }
        float scale = ctx.params().getFloat("resolution_scale");
        ImageDesc& out = ctx.output("reflection");
        out.width = std::max(1u, static_cast<uint32_t>(std::lround(depth.width * scale)));
        out.height = std::max(1u, static_cast<uint32_t>(std::lround(depth.height * scale)));
        mLevels = mipAtlasLevels(depth.width, depth.height);
        mPipeline = ctx.computePipeline("ssr/hiz.comp");
    }

    void execute(ExecuteContext& ctx) override {
        const Params& p = ctx.params();
        const CameraFrame& cam = mCamera->current;
        const ImageDesc& depth = ctx.input("depth").desc();
        gpu_types::SsrUniforms u{};
        u.viewProj = cam.viewProj;
        u.invViewProj = cam.invViewProj;
        u.cameraPos = glm::vec4(cam.state.position, cam.state.lens.znear);
        glm::vec3 forward = -glm::normalize(glm::vec3(cam.state.world[2]));
        u.cameraFwd = glm::vec4(forward, std::abs(cam.proj[1][1]));
        u.depthParams = {cam.proj[2][2], cam.proj[3][2], cam.proj[2][3], cam.proj[3][3]};
        u.params = {p.getFloat("thickness"), p.getFloat("max_distance"), p.getFloat("edge_fade"),
                    p.getFloat("max_roughness")};
        u.size = {static_cast<int>(depth.width), static_cast<int>(depth.height), static_cast<int>(mLevels),
                  static_cast<int>(mLevels)};
        bool reproject = ctx.hasInput("velocity") && ctx.frameIndex() > 0;
        u.config = {static_cast<uint32_t>(p.getInt("max_taps")), static_cast<uint32_t>(p.getInt("max_rays")),
                    reproject ? SSR_VELOCITY : 0u, ctx.frameIndex()};
        u.cone = {p.getFloat("cone_scale"), 0.0f, 0.0f, 0.0f};
        ctx.setUniforms(u);
        const ImageDesc& out = ctx.output("reflection").desc();
        ctx.dispatch(mPipeline, nullptr, 0, out.width, out.height);
    }

private:
    std::shared_ptr<CameraObject> mCamera;
    uint32_t mLevels = 1;
    PipelineId mPipeline = 0;
};

const NodeRegistration kRegistration(schema(), [] { return std::make_unique<SsrHiz>(); });

} // namespace
} // namespace vitrine
