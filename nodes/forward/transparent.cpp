// forward.transparent: alpha-blended and transmissive (thin glass) primitives drawn over the lit opaque colour,
// sorted back to front, depth-tested against the G-buffer's depth without writing it, and lit by the same terms
// as lighting.deferred (shaders/lighting/*.glsl).
#include "shaders/forward/transparent.h"
#include "core/base/error.hpp"
#include "core/gpu/context.hpp"
#include "core/gpu/descriptors.hpp"
#include "core/gpu/raster.hpp"
#include "core/graph/registry.hpp"
#include "core/scene/gpu_scene.hpp"
#include "nodes/bake/baked_lighting.hpp"
#include "nodes/depth/mip_atlas.hpp"
#include "nodes/lighting/multiscatter.hpp"
#include "nodes/lighting/punctual_lights.hpp"
#include "nodes/shadow/cascades.hpp"

#include <algorithm>
#include <array>
#include <cstring>
#include <memory>

namespace vitrine {
namespace {

using gpu_types::SceneDrawPush;
using gpu_types::TransparentUniforms;

NodeSchema schema() {
    NodeSchema s;
    s.type = "forward.transparent";
    s.doc =
        "Transparent surfaces (glTF alphaMode BLEND, KHR_materials_transmission as thin glass) over the lit opaque "
        "colour: sorted back to front per primitive, depth-tested against the G-buffer without writing depth, lit by "
        "lighting.deferred's terms (sun with cascaded shadows, point and spot lights, sky ambient and Fresnel "
        "reflection, emissive); glass tints what lies behind it (dual-source blending), attenuated through a "
        "KHR_materials_volume by Beer's law. With a `background` (color.pyramid of the opaque colour), transmission "
        "reads what lies behind from it as the glTF Sample Viewer does: refracted through the volume's thickness and "
        "blurred by roughness.";
    s.pass = PassKind::Raster;
    auto tex = [](const char* name, const char* doc, std::vector<VkFormat> formats = {}) {
        return InputPort{name, PortKind::Texture, std::move(formats), false, Usage::Sampled, doc};
    };
    s.inputs = {
        {"scene", PortKind::Scene, {}, false, Usage::Sampled, "The scene: its transparent primitives and lights"},
        tex("color", "The lit opaque colour (lighting.deferred's color, HDR)",
            {VK_FORMAT_R16G16B16A16_SFLOAT, VK_FORMAT_R32G32B32A32_SFLOAT}),
        {"depth",
         PortKind::Texture,
         {},
         false,
         Usage::DepthAttachment,
         "The G-buffer's depth (reverse Z): transparent surfaces behind it are hidden; not written"},
        tex("shadow_map", "shadow.directional's atlas"),
        {"cascades", PortKind::Buffer, {}, false, Usage::Sampled, "shadow.directional's cascades"},
        tex("sky_sh", "A sky node's `sh`: SH9 radiance, sun illuminance (lux) and direction"),
        tex("sky", "A sky node's cube map (reflections), or ibl.environment's prefiltered one (mips: rough "
                   "surfaces read the mip of their roughness)"),
        {"camera", PortKind::Camera, {}, false, Usage::Sampled, "The frame's camera (the sort's eye point)"},
        {"volume",
         PortKind::Texture,
         {},
         true,
         Usage::Sampled,
         "bake.lightmap's irradiance volume: the ambient terms lighting.deferred uses for what has no lightmap"},
        {"baked", PortKind::Buffer, {}, true, Usage::Sampled, "bake.lightmap's `layout` (with `volume`)"},
        {"background",
         PortKind::Texture,
         {},
         true,
         Usage::Sampled,
         "color.pyramid of `color` (the opaque colour of this frame, not a history): transmission then reads what "
         "lies behind from it, where the ray refracted through KHR_materials_volume's thickness leaves the volume "
         "(straight behind when thin-walled), blurred over the share of the screen the Sample Viewer's 1024^2 "
         "transmission framebuffer blurs (level log2(larger side) - 10 (1 - roughness x clamp(2 ior - 2, 0, 1))); "
         "transparent surfaces farther back are then not seen "
         "through glass. Without it, glass tints the pixel straight behind (dual-source blending), unblurred"},
        {"brdf_lut",
         PortKind::Texture,
         {},
         true,
         Usage::Sampled,
         "ibl.environment's (or ibl.capture's) split-sum BRDF LUT: the sky's and the volume's reflection are weighed "
         "by it (f0 A + f90 B), as lighting.deferred's with its brdf_lut, instead of Karis' analytic fit"},
    };
    OutputPort color;
    color.name = "color";
    color.size = SizeRule::ofInput("color");
    color.formatFrom = "color";
    color.usage = Usage::ColorAttachment;
    color.doc = "HDR radiance: the opaque colour with the transparent surfaces blended over it";
    s.outputs = {color};
    s.params = {
        {"sky_ambient",
         ParamType::Float,
         0.15,
         0.0,
         1.0,
         {},
         "As lighting.deferred's: fraction of the open sky's ambient reaching the surfaces"},
        {"shadows", ParamType::Bool, true, {}, {}, {}, "Sun shadows (off: the sun reaches everything)"},
        {"sun_scale", ParamType::Float, 1.0, 0.0, 100.0, {}, "Multiplier of the sky model's sun illuminance"},
        {"emissive_scale", ParamType::Float, 1.0, 0.0, 1e6, {}, "Multiplier of emission (and of unlit colours)"},
        {"multiscatter",
         ParamType::Enum,
         "off",
         {},
         {},
         {"off", "environment", "all"},
         "As lighting.deferred's: the GGX lobe's multiple scattering for every light (all), the sky's and the "
         "volume's alone (environment: the glTF Sample Viewer's model) or none (off)"},
        {"sort",
         ParamType::Enum,
         "back_to_front",
         {},
         {},
         {"back_to_front", "none"},
         "Draw order: primitives by the distance of their bounds' centre from the eye, farthest first; or the "
         "scene's order (for A/B)"},
    };
    return s;
}

// Whether the device filters `format` linearly (lavapipe does not filter RGBA32F: the sky's cube map is then read
// with the nearest texel, as the executor binds it for lighting.deferred).
bool linearFilterable(Context& ctx, VkFormat format) {
    VkFormatProperties props;
    vkGetPhysicalDeviceFormatProperties(ctx.physicalDevice(), format, &props);
    return (props.optimalTilingFeatures & VK_FORMAT_FEATURE_SAMPLED_IMAGE_FILTER_LINEAR_BIT) != 0;
}

// Set 0 of the pipelines (set 1 is the scene's): binding 0 the uniforms, 1-5 the sampled inputs. Without a
// volume, binding 5 holds sky_sh instead (the shader never reads it when the volume's counts are zero); without a
// background, binding 6 holds color (never read when the background flag is 0); without a brdf_lut, binding 7 holds
// sky_sh (never read when volumeCounts.w is 0).
constexpr std::array<const char*, 7> kSampled = {"shadow_map", "sky_sh",     "sky",     "color",
                                                 "volume",     "background", "brdf_lut"};
// The samplers of the node's DescriptorSets.
enum SamplerIndex : size_t { kLinear = 0, kNearest };

class Transparent final : public Node {
public:
    void setup(SetupContext& ctx) override {
        mScene = ctx.objectAs<SceneObject>("scene");
        mCamera = ctx.objectAs<CameraObject>("camera");
        mCascades = ctx.objectAs<ShadowCascadesObject>("cascades");
        mSort = ctx.params().getString("sort") == "back_to_front";
        if (ctx.hasInput("volume") != ctx.hasInput("baked"))
            ctx.failParam("sky_ambient", "connect both volume and baked (bake.lightmap's volume and layout), or neither");
        if (ctx.hasInput("baked")) mBaked = ctx.objectAs<BakedLightingObject>("baked");
        mBackground = ctx.hasInput("background");
        mLut = ctx.hasInput("brdf_lut");
        if (mBackground) {
            const ImageDesc& color = ctx.input("color");
            const ImageDesc& atlas = ctx.input("background");
            if (atlas.width != mipAtlasWidth(color.width, color.height) ||
                atlas.height != mipAtlasHeight(color.width, color.height))
                throw UserError("forward.transparent: input background is " + std::to_string(atlas.width) + "x" +
                                std::to_string(atlas.height) + ", not the mip atlas of color (" +
                                std::to_string(color.width) + "x" + std::to_string(color.height) +
                                "): connect a color.pyramid of the opaque colour");
        }
        warnLightCount(mScene->scene(), "forward.transparent");
    }

    void execute(ExecuteContext& ctx) override {
        GpuScene& gpu = mScene->gpu(ctx.gpu(), ctx.shaders());
        if (!mCopy) create(ctx, gpu);
        writeSet(ctx);

        VkCommandBuffer cmd = ctx.cmd();
        const ImageDesc& size = ctx.output("color").desc();
        beginRendering(cmd, {size.width, size.height}, {{ctx.output("color").view(), true, {}}},
                       Attachment{ctx.input("depth").view(), false, {}});
        VkDescriptorSet sets[2] = {mSet, gpu.set()};
        vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, mCopy.pipeline());
        vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, mCopy.layout(), 0, 2, sets, 0, nullptr);
        vkCmdDraw(cmd, 3, 1, 0, 0);

        gpu.bindGeometry(cmd);
        const auto& materials = mScene->scene().materials;
        VkPipeline bound = VK_NULL_HANDLE;
        for (const GpuDraw& d : ordered(gpu)) {
            // A double-sided primitive is drawn twice, its back faces first: a closed convex pane (a vitrine's
            // box) then blends in depth order within itself too.
            bool twoPasses = materials[d.material].doubleSided;
            for (const RasterPipeline* p : {twoPasses ? &mBackFaces : nullptr, &mFrontFaces}) {
                if (!p) continue;
                if (p->pipeline() != bound) {
                    vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, p->pipeline());
                    bound = p->pipeline();
                }
                SceneDrawPush push{};
                push.instance = d.instance;
                push.material = d.material;
                vkCmdPushConstants(cmd, p->layout(), VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT, 0,
                                   sizeof(push), &push);
                gpu.drawIndexed(cmd, d);
            }
        }
        endRendering(cmd);
    }

    void releaseGpu() override {
        mCopy = RasterPipeline();
        mFrontFaces = RasterPipeline();
        mBackFaces = RasterPipeline();
        mUniforms = GpuBuffer();
        mSets = DescriptorSets();
        mSet = VK_NULL_HANDLE;
        mDevice = VK_NULL_HANDLE;
    }

    ~Transparent() override { releaseGpu(); }

private:
    // This frame's transparent draws: farthest first by the distance from the eye to the centre of each
    // primitive's world bounds (posed), or the scene's order.
    std::vector<GpuDraw> ordered(const GpuScene& gpu) const {
        std::vector<GpuDraw> draws = gpu.transparentDraws();
        if (!mSort) return draws;
        const scene::Scene& s = mScene->scene();
        glm::vec3 eye = mCamera->current.state.position;
        std::vector<std::pair<float, GpuDraw>> keyed;
        for (const GpuDraw& d : draws) {
            const glm::mat4& world = d.instance < mScene->pose.instanceWorld.size()
                                         ? mScene->pose.instanceWorld[d.instance]
                                         : s.instances[d.instance].world;
            glm::vec3 centre = glm::vec3(world * glm::vec4(s.primitives[d.primitive].bounds.center(), 1.0f));
            keyed.push_back({glm::dot(centre - eye, centre - eye), d});
        }
        std::stable_sort(keyed.begin(), keyed.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
        for (size_t i = 0; i < keyed.size(); ++i)
            draws[i] = keyed[i].second;
        return draws;
    }

    void writeSet(ExecuteContext& ctx) {
        const Params& p = ctx.params();
        TransparentUniforms u{};
        u.params = {p.getFloat("sky_ambient"), p.getBool("shadows") ? 1.0f : 0.0f, p.getFloat("sun_scale"),
                    p.getFloat("emissive_scale")};
        u.shadow = mCascades->data;
        u.lights = packPunctualLights(*mScene);
        if (mBaked) {
            u.volumeOrigin = glm::vec4(mBaked->volumeOrigin, mBaked->volumeSpacing);
            u.volumeCounts = glm::uvec4(mBaked->volumeCounts, 0u);
        }
        u.volumeCounts.w = mLut ? 1u : 0u;
        if (mBackground) {
            const ImageDesc& color = ctx.input("color").desc();
            u.background = glm::uvec4(1u, color.width, color.height, mipAtlasLevels(color.width, color.height));
        }
        std::memcpy(mUniforms.mapped(), &u, sizeof(u));

        DescriptorWrites w(mSet);
        w.buffer(0, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, {mUniforms.buffer(), 0, sizeof(TransparentUniforms)});
        for (uint32_t i = 0; i < kSampled.size(); ++i) {
            const std::string name = kSampled[i];
            const std::string port = name == "volume" && !mBaked            ? "sky_sh"
                                     : name == "background" && !mBackground ? "color"
                                     : name == "brdf_lut" && !mLut          ? "sky_sh"
                                                                            : name;
            const GpuImage& image = ctx.input(port);
            // The background's levels are read bilinearly (shaders/common/mip_atlas.glsl).
            const bool linear =
                (name == "sky" || (name == "background" && mBackground) || (name == "brdf_lut" && mLut)) &&
                linearFilterable(ctx.gpu(), image.desc().format);
            w.image(
                i + 1, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER,
                {mSets.sampler(linear ? kLinear : kNearest), image.view(), VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL});
        }
        w.update(mDevice);
    }

    void create(ExecuteContext& ctx, GpuScene& gpu) {
        Context& c = ctx.gpu();
        if (!c.dualSourceBlend())
            throw UserError("forward.transparent needs the dualSrcBlend feature, which device '" + c.deviceInfo().name +
                            "' lacks");
        mDevice = c.device();
        VkDescriptorSetLayoutBinding b[1 + kSampled.size()];
        b[0] = {0, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, 1, VK_SHADER_STAGE_FRAGMENT_BIT, nullptr};
        for (uint32_t i = 0; i < kSampled.size(); ++i)
            b[i + 1] = {i + 1, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 1, VK_SHADER_STAGE_FRAGMENT_BIT, nullptr};
        // Linear filtering for the sky's cube map; everything else is read with texelFetch (and the shadow map's
        // depth format may not be filterable).
        // Linear between mips too: a sky from ibl.environment is read at the mip of the roughness.
        const SamplerDesc samplers[] = {{VK_FILTER_LINEAR, VK_SAMPLER_MIPMAP_MODE_LINEAR},
                                        {VK_FILTER_NEAREST, VK_SAMPLER_MIPMAP_MODE_NEAREST}}; // kLinear, kNearest
        mSets = DescriptorSets(c, b, 1, samplers, "forward.transparent.set");
        mSet = mSets.allocate();
        mUniforms = GpuBuffer(c, sizeof(TransparentUniforms), VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT, true,
                              "forward.transparent.uniforms");

        // The node's set is set 0 and the scene's set 1 (VITRINE_SCENE_SET), as in the ray tracers.
        ShaderDefines defines = {{"VITRINE_SCENE_TEXTURES", std::to_string(std::max(1u, gpu.textureCount()))},
                                 {"VITRINE_SCENE_SET", "1"}};
        for (auto& define : multiscatterDefines(ctx.params()))
            defines.push_back(define);
        RasterPipelineDesc d;
        d.setLayouts = {mSets.layout(), gpu.setLayout()};
        d.pushConstantSize = sizeof(SceneDrawPush);
        d.colorFormats = {ctx.output("color").desc().format};
        d.depthFormat = ctx.input("depth").desc().format;
        d.depthWrite = false;

        // The copy of the opaque colour: replaces the attachment (src × 1 + dst × 0).
        d.name = "forward.transparent.copy";
        d.vertex = ctx.shaders().compile("forward/fullscreen.vert");
        d.fragment = ctx.shaders().compile("forward/copy.frag");
        d.depthTest = false;
        d.cullMode = VK_CULL_MODE_NONE;
        VkPipelineColorBlendAttachmentState blend{};
        blend.blendEnable = VK_TRUE;
        blend.srcColorBlendFactor = VK_BLEND_FACTOR_ONE;
        blend.dstColorBlendFactor = VK_BLEND_FACTOR_SRC1_COLOR;
        blend.colorBlendOp = VK_BLEND_OP_ADD;
        blend.srcAlphaBlendFactor = VK_BLEND_FACTOR_ONE;
        blend.dstAlphaBlendFactor = VK_BLEND_FACTOR_SRC1_ALPHA;
        blend.alphaBlendOp = VK_BLEND_OP_ADD;
        d.blend = blend;
        mCopy = RasterPipeline(c, d);

        // The surfaces: dst' = outColor + dst × outTransmit (shaders/forward/transparent.frag).
        d.name = "forward.transparent";
        d.vertex = ctx.shaders().compile("gbuffer/layered.vert", defines);
        d.fragment = ctx.shaders().compile("forward/transparent.frag", defines);
        d.vertexBindings = GpuScene::vertexBindings();
        d.vertexAttributes = GpuScene::vertexAttributes();
        d.depthTest = true;
        d.cullMode = VK_CULL_MODE_BACK_BIT;
        blend.srcAlphaBlendFactor = VK_BLEND_FACTOR_ZERO; // alpha (1 from the lighting) stays
        blend.dstAlphaBlendFactor = VK_BLEND_FACTOR_ONE;
        d.blend = blend;
        mFrontFaces = RasterPipeline(c, d);
        d.cullMode = VK_CULL_MODE_FRONT_BIT;
        mBackFaces = RasterPipeline(c, d);
    }

    std::shared_ptr<SceneObject> mScene;
    std::shared_ptr<CameraObject> mCamera;
    std::shared_ptr<ShadowCascadesObject> mCascades;
    std::shared_ptr<BakedLightingObject> mBaked;
    bool mSort = true;
    bool mBackground = false;
    bool mLut = false; // brdf_lut connected
    VkDevice mDevice = VK_NULL_HANDLE;
    DescriptorSets mSets;
    VkDescriptorSet mSet = VK_NULL_HANDLE;
    GpuBuffer mUniforms;
    RasterPipeline mCopy, mFrontFaces, mBackFaces;
};

const NodeRegistration kRegistration(schema(), [] { return std::make_unique<Transparent>(); });

} // namespace
} // namespace vitrine
