// ibl.localized: localized cube-map reflections (MUSEUM_SPEC §4). Each probe's influence volume is drawn as a
// proxy (box or sphere) depth-tested against the G-buffer, so only the pixels inside it are shaded; the probes'
// radiance along the reflection is blended L = Σ C_i w_i / Σ w_i with the two accumulation schemes of the demo
// (param `blend`), optionally parallax-corrected, and resolved to split-sum specular, a diffuse approximation and
// a count of the probes that shaded each pixel. Pixels outside every volume fall back to the sky.
#include "shaders/ibl/localized.h"
#include "core/base/error.hpp"
#include "core/gpu/context.hpp"
#include "core/gpu/descriptors.hpp"
#include "core/gpu/raster.hpp"
#include "core/gpu/vk_check.hpp"
#include "core/graph/registry.hpp"
#include "core/scene/gpu_scene.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <utility>

namespace vitrine {
namespace {

using gpu_types::LocalizedProbe;
using gpu_types::LocalizedUniforms;

constexpr uint32_t kBoxVertices = 36;     // shaders/ibl/localized.vert
constexpr uint32_t kSphereVertices = 768; // 16 x 8 cells x 6

NodeSchema schema() {
    NodeSchema s;
    s.type = "ibl.localized";
    s.doc = "Localized cube-map reflections (MUSEUM_SPEC §4): each reflection probe's influence volume (box or "
            "sphere proxy, depth-tested against the G-buffer) shades the pixels inside it with its prefiltered "
            "cube (mip by roughness); overlapping probes blend L = Σ C w / Σ w with w = fade ramp × 16^priority "
            "(blend \"a\": one RGBA16F pass; \"b\": R16_UNORM weights, then a normalised pass); optional parallax "
            "correction [Lagarde12]. Outputs split-sum specular L (f0 A + B), a diffuse approximation and the "
            "probe count; pixels outside every volume take the sky (as lighting.deferred without a volume).";
    s.pass = PassKind::Raster;
    auto tex = [](const char* name, const char* doc) {
        return InputPort{name, PortKind::Texture, {}, false, Usage::Sampled, doc};
    };
    s.inputs = {
        tex("normal", "G-buffer: octahedral normal, view depth, shininess"),
        tex("base_color", "G-buffer: base colour, metallic"),
        {"depth",
         PortKind::Texture,
         {VK_FORMAT_D32_SFLOAT},
         false,
         Usage::DepthRead,
         "G-buffer hardware depth (reverse Z): the proxies' depth test and the pixels' positions; not written"},
        {"camera", PortKind::Camera, {}, false, Usage::Sampled, "The frame's camera"},
        {"scene", PortKind::Scene, {}, false, Usage::Sampled, "The scene: its reflection probes (Scene::probes)"},
        {"cubes",
         PortKind::Texture,
         {},
         false,
         Usage::Sampled,
         "ibl.capture's prefiltered cube-map array: probe i is layers [6i, 6i + 6), mip m = roughness m / (mips - 1)"},
        tex("brdf_lut", "ibl.capture's split-sum BRDF LUT: (NoV, roughness) -> (A, B), specular = f0 A + B"),
        tex("sky", "A sky node's cubemap (the fallback outside every probe)"),
        tex("sky_sh", "A sky node's `sh` (the fallback's diffuse and rough specular)"),
    };
    auto out = [](const char* name, VkFormat format, const char* doc) {
        OutputPort o;
        o.name = name;
        o.format = format;
        o.size = SizeRule::ofInput("normal");
        o.usage = Usage::ColorAttachment;
        o.doc = doc;
        return o;
    };
    s.outputs = {
        out("specular", VK_FORMAT_R16G16B16A16_SFLOAT,
            "Indirect specular L (f0 A + B) before occlusion (lighting.deferred's ibl_specular)"),
        out("diffuse", VK_FORMAT_R16G16B16A16_SFLOAT,
            "Indirect diffuse: diffuse albedo x the blended probes' roughest mip along the normal (for what has "
            "neither lightmap nor irradiance volume; lighting.deferred's ibl_diffuse)"),
        out("count", VK_FORMAT_R16_SFLOAT, "Debug: how many probes shaded each pixel"),
        out("radiance", VK_FORMAT_R16G16B16A16_SFLOAT,
            "Debug: the blended probe radiance L along the reflection (0 where the sky stands in)"),
        out("radiance_sum", VK_FORMAT_R16G16B16A16_SFLOAT,
            "Intermediate: the volume passes' accumulation (a: Σ C w, Σ w; b: Σ C w / W, Σ w / W)"),
        out("irradiance_sum", VK_FORMAT_R16G16B16A16_SFLOAT, "Intermediate: the same for the diffuse lookup"),
        out("weights", VK_FORMAT_R16_UNORM, "Intermediate (blend b): the first pass's Σ w, scaled into [0, 1]"),
    };
    s.params = {
        {"blend",
         ParamType::Enum,
         "b",
         {},
         {},
         {"a", "b"},
         "a: one additive pass of (C w, w) into RGBA16F, divided afterwards (small C w underflow half floats); "
         "b: Σ w into R16_UNORM first, then a pass adding C w / Σ w (the demo's precision fix)"},
        {"parallax",
         ParamType::Bool,
         false,
         {},
         {},
         {},
         "Box/sphere-projected lookup [Lagarde12]: the reflected ray meets the probe's proxy (its projection box, "
         "else its influence volume) and the cube is read towards that point from the capture point. Exact for mirrors "
         "whose surroundings lie on the proxy, approximate for rough surfaces (the demo shipped without it)"},
        {"dominant_direction",
         ParamType::Bool,
         true,
         {},
         {},
         {},
         "Read a rough lobe's prefiltered cube along its dominant direction [Lagarde14, 4.9.3], bent from the mirror "
         "direction towards the normal as roughness grows: mix(n, r, s (sqrt(s) + a)), a = roughness^2, s = 1 - a. "
         "Off: the mirror direction (the demo)"},
        {"sky_fallback",
         ParamType::Float,
         0.15,
         0.0,
         1.0,
         {},
         "Scale of the sky's ambient where no probe applies (as lighting.deferred's sky_ambient: a stand-in for "
         "occlusion)"},
        {"multiscatter",
         ParamType::Bool,
         false,
         {},
         {},
         {},
         "The probes' reflection (and the sky's where no probe applies) compensated for the GGX lobe's multiple "
         "scattering, as lighting.deferred's multiscatter environment / all (common/brdf.glsl ggxMultiscatter)"},
    };
    return s;
}

// A conservative bound on how many volumes overlap at any point: 1 + the most bounding spheres any one probe's
// bounding sphere meets (a point inside k volumes lies in k mutually intersecting spheres).
int maxOverlap(const std::vector<scene::ReflectionProbe>& probes) {
    auto radius = [](const scene::ReflectionProbe& p) {
        return p.shape == scene::ProbeShape::Sphere ? p.halfExtents.x : glm::length(p.halfExtents);
    };
    int most = 0;
    for (const auto& a : probes) {
        int k = 0;
        for (const auto& b : probes)
            if (glm::length(a.center - b.center) < radius(a) + radius(b)) ++k; // counts a itself
        most = std::max(most, k);
    }
    return std::max(most, 1);
}

// Binding numbers of the node's descriptor set (shaders/ibl/localized*.frag).
enum Binding : uint32_t {
    kUniforms = 0,
    kDepth,
    kNormal,
    kBaseColor,
    kCubes,
    kWeights,
    kRadianceSum,
    kIrradianceSum,
    kBrdfLut,
    kSky,
    kSkySh,
    kBindingCount
};

// The samplers of the node's DescriptorSets.
enum SamplerIndex : size_t { kLinear = 0, kNearest };

class Localized final : public Node {
public:
    void setup(SetupContext& ctx) override {
        mScene = ctx.objectAs<SceneObject>("scene");
        mCamera = ctx.objectAs<CameraObject>("camera");
        mBlendB = ctx.params().getString("blend") == "b";
        const auto& probes = mScene->scene().probes;
        if (probes.size() > IBL_LOCALIZED_MAX_PROBES)
            ctx.failParam("blend", "scene '" + mScene->scene().name + "' has " + std::to_string(probes.size()) +
                                       " reflection probes; ibl.localized draws at most " +
                                       std::to_string(IBL_LOCALIZED_MAX_PROBES));
        const ImageDesc& cubes = ctx.input("cubes");
        if (!probes.empty() && (!cubes.cube || cubes.layers < 6 * probes.size()))
            ctx.failParam("blend", "input `cubes` must be a cube-map array with 6 layers per probe (" +
                                       std::to_string(6 * probes.size()) + " for scene '" + mScene->scene().name +
                                       "'), got " + std::to_string(cubes.layers) + " layers" +
                                       (cubes.cube ? "" : ", not cube-compatible"));
        packProbes();
    }

    void execute(ExecuteContext& ctx) override {
        if (!mResolve) create(ctx);
        writeSet(ctx);
        VkCommandBuffer cmd = ctx.cmd();
        const ImageDesc& size = ctx.output("specular").desc();
        VkExtent2D extent{size.width, size.height};
        Attachment depth{ctx.input("depth").view(), false, {}, true};
        auto target = [&](const char* port) { return Attachment{ctx.output(port).view(), true, {}}; };

        if (!mBlendB) {
            // Blend a: one pass, Σ C w and Σ w in half floats. The weight target is not used: cleared for debug views.
            beginRendering(cmd, extent, {target("weights")}, std::nullopt);
            endRendering(cmd);
            beginRendering(cmd, extent, {target("radiance_sum"), target("irradiance_sum"), target("count")}, depth);
            drawProbes(cmd, mAccumulate);
            endRendering(cmd);
        } else {
            // Blend b: Σ w first, then each probe's C w / Σ w read back from it.
            beginRendering(cmd, extent, {target("weights"), target("count")}, depth);
            drawProbes(cmd, mWeights);
            endRendering(cmd);
            ctx.changeUsage("weights", Usage::Sampled);
            beginRendering(cmd, extent, {target("radiance_sum"), target("irradiance_sum")}, depth);
            drawProbes(cmd, mNormalized);
            endRendering(cmd);
        }
        ctx.changeUsage("radiance_sum", Usage::Sampled);
        ctx.changeUsage("irradiance_sum", Usage::Sampled);
        beginRendering(cmd, extent, {target("specular"), target("diffuse"), target("radiance")}, std::nullopt);
        vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, mResolve.pipeline());
        vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, mResolve.layout(), 0, 1, &mSet, 0, nullptr);
        vkCmdDraw(cmd, 3, 1, 0, 0);
        endRendering(cmd);
    }

    void releaseGpu() override {
        mAccumulate = RasterPipeline();
        mWeights = RasterPipeline();
        mNormalized = RasterPipeline();
        mResolve = RasterPipeline();
        mUniforms = GpuBuffer();
        mSets = DescriptorSets();
        mSet = VK_NULL_HANDLE;
        if (mDevice) {
            releaseCubeView();
            mDevice = VK_NULL_HANDLE;
        }
    }

    ~Localized() override { releaseGpu(); }

private:
    // Probe data in the shaders' layout. Weights are scaled so that they stay in range: by 16^-maxPriority in
    // both blends (one probe's w <= 1: C w cannot overflow half floats), and for b also by 1 / (the most volumes
    // that can overlap), so that Σ w fits R16_UNORM without clamping. The scale cancels in Σ C w / Σ w; a lone
    // priority-0 probe keeps its fade weight exactly (the seed's precision example).
    void packProbes() {
        const auto& probes = mScene->scene().probes;
        int top = probes.empty() ? 0 : probes[0].priority;
        for (const auto& p : probes)
            top = std::max(top, p.priority);
        float scale = mBlendB ? 1.0f / static_cast<float>(maxOverlap(probes)) : 1.0f;
        mProbes.clear();
        for (const auto& p : probes) {
            LocalizedProbe g{};
            bool sphere = p.shape == scene::ProbeShape::Sphere;
            g.center = glm::vec4(p.center, sphere ? 1.0f : 0.0f);
            glm::mat3 r = glm::mat3_cast(glm::normalize(p.rotation));
            g.axisX = glm::vec4(r[0], p.halfExtents.x);
            g.axisY = glm::vec4(r[1], p.halfExtents.y);
            g.axisZ = glm::vec4(r[2], p.halfExtents.z);
            g.capture = glm::vec4(p.position, p.fade);
            g.weight = glm::vec4(scale, static_cast<float>(p.priority - top), 0.0f, 0.0f);
            bool proxy = !sphere && p.hasProjection();
            g.proxyCenter = glm::vec4(proxy ? p.projectionCenter : p.center, 0.0f);
            g.proxyHalf = glm::vec4(proxy ? p.projectionHalfExtents : p.halfExtents, 0.0f);
            mProbes.push_back(g);
        }
    }

    void drawProbes(VkCommandBuffer cmd, const RasterPipeline& pipeline) {
        vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, pipeline.pipeline());
        vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, pipeline.layout(), 0, 1, &mSet, 0, nullptr);
        for (uint32_t i = 0; i < mProbes.size(); ++i)
            vkCmdDraw(cmd, mProbes[i].center.w > 0.5f ? kSphereVertices : kBoxVertices, 1, 0, i);
    }

    void writeSet(ExecuteContext& ctx) {
        const Params& p = ctx.params();
        auto* u = static_cast<LocalizedUniforms*>(mUniforms.mapped());
        const CameraFrame& cam = mCamera->current;
        u->viewProj = cam.viewProj;
        u->invViewProj = cam.invViewProj;
        u->cameraPos = glm::vec4(cam.state.position, static_cast<float>(mProbes.size()));
        u->params = {mBlendB ? 1.0f : 0.0f, p.getBool("parallax") ? 1.0f : 0.0f, p.getFloat("sky_fallback"),
                     p.getBool("dominant_direction") ? 1.0f : 0.0f};
        std::copy(mProbes.begin(), mProbes.end(), u->probes);

        struct Image {
            Binding binding;
            const GpuImage* image;
            VkImageLayout layout;
        };
        const VkImageLayout read = VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL;
        const std::array<Image, kBindingCount - 1> images = {{
            {kDepth, &ctx.input("depth"), VK_IMAGE_LAYOUT_DEPTH_STENCIL_READ_ONLY_OPTIMAL},
            {kNormal, &ctx.input("normal"), read},
            {kBaseColor, &ctx.input("base_color"), read},
            {kCubes, &ctx.input("cubes"), read},
            {kWeights, &ctx.output("weights"), read},
            {kRadianceSum, &ctx.output("radiance_sum"), read},
            {kIrradianceSum, &ctx.output("irradiance_sum"), read},
            {kBrdfLut, &ctx.input("brdf_lut"), read},
            {kSky, &ctx.input("sky"), read},
            {kSkySh, &ctx.input("sky_sh"), read},
        }};
        DescriptorWrites w(mSet);
        w.buffer(kUniforms, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, {mUniforms.buffer(), 0, sizeof(LocalizedUniforms)});
        for (size_t i = 0; i < images.size(); ++i) {
            // Cubes and the LUT are filtered (between mips too); the rest is read with texelFetch, and the sky at its
            // texels where its format is not filterable (RGBA32F on lavapipe), as the executor binds it.
            bool linear = (images[i].binding == kCubes || images[i].binding == kBrdfLut || images[i].binding == kSky) &&
                          filterable(ctx.gpu(), images[i].image->desc().format);
            VkImageView view = images[i].binding == kCubes ? cubeArrayView(*images[i].image) : images[i].image->view();
            w.image(images[i].binding, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER,
                    {mSets.sampler(linear ? kLinear : kNearest), view, images[i].layout});
        }
        w.update(mDevice);
    }

    // The cubes as a cube-map array: a 6-layer input (one probe) has a plain cube view, so the node makes its own.
    VkImageView cubeArrayView(const GpuImage& cubes) {
        if (cubes.desc().layers > 6) return cubes.view();
        if (mCubeView && mCubeViewImage == cubes.image()) return mCubeView;
        releaseCubeView();
        VkImageViewCreateInfo info{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
        info.image = cubes.image();
        info.viewType = VK_IMAGE_VIEW_TYPE_CUBE_ARRAY;
        info.format = cubes.desc().format;
        info.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, cubes.desc().mipLevels, 0, cubes.desc().layers};
        VK_CHECK(vkCreateImageView(mDevice, &info, nullptr, &mCubeView));
        mCubeViewImage = cubes.image();
        return mCubeView;
    }

    void releaseCubeView() {
        if (!mCubeView) return;
        VkDevice device = mDevice;
        VkImageView view = std::exchange(mCubeView, VK_NULL_HANDLE);
        mContext->destroyLater([device, view] { vkDestroyImageView(device, view, nullptr); });
        mCubeViewImage = VK_NULL_HANDLE;
    }

    static bool filterable(Context& ctx, VkFormat format) {
        VkFormatProperties props;
        vkGetPhysicalDeviceFormatProperties(ctx.physicalDevice(), format, &props);
        return (props.optimalTilingFeatures & VK_FORMAT_FEATURE_SAMPLED_IMAGE_FILTER_LINEAR_BIT) != 0;
    }

    void create(ExecuteContext& ctx) {
        Context& c = ctx.gpu();
        mContext = &c;
        mDevice = c.device();
        std::array<VkDescriptorSetLayoutBinding, kBindingCount> b{};
        for (uint32_t i = 0; i < kBindingCount; ++i)
            b[i] = {i, i == kUniforms ? VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER : VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER,
                    1, VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT, nullptr};
        const SamplerDesc samplers[] = {{VK_FILTER_LINEAR, VK_SAMPLER_MIPMAP_MODE_LINEAR},
                                        {VK_FILTER_NEAREST, VK_SAMPLER_MIPMAP_MODE_NEAREST}}; // kLinear, kNearest
        mSets = DescriptorSets(c, b, 1, samplers, "ibl.localized.set");
        mSet = mSets.allocate();
        mUniforms =
            GpuBuffer(c, sizeof(LocalizedUniforms), VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT, true, "ibl.localized.uniforms");

        // Volume passes: back faces of the proxies (one fragment per covered pixel, the camera inside a volume
        // included), passing where the G-buffer's surface is not behind them (reverse Z: proxy depth <= surface
        // depth); depth clamped so that no far plane clips a volume; additive blending of every target.
        RasterPipelineDesc d;
        d.setLayouts = {mSets.layout()};
        d.vertex = ctx.shaders().compile("ibl/localized.vert");
        d.depthFormat = ctx.input("depth").desc().format;
        d.depthTest = true;
        d.depthWrite = false;
        d.depthCompare = VK_COMPARE_OP_LESS_OR_EQUAL;
        d.depthClamp = true;
        d.cullMode = VK_CULL_MODE_FRONT_BIT;
        VkPipelineColorBlendAttachmentState add{};
        add.blendEnable = VK_TRUE;
        add.srcColorBlendFactor = add.dstColorBlendFactor = VK_BLEND_FACTOR_ONE;
        add.srcAlphaBlendFactor = add.dstAlphaBlendFactor = VK_BLEND_FACTOR_ONE;
        add.colorBlendOp = add.alphaBlendOp = VK_BLEND_OP_ADD;
        add.colorWriteMask =
            VK_COLOR_COMPONENT_R_BIT | VK_COLOR_COMPONENT_G_BIT | VK_COLOR_COMPONENT_B_BIT | VK_COLOR_COMPONENT_A_BIT;
        d.blend = add;
        auto format = [&](const char* port) { return ctx.output(port).desc().format; };
        auto pass = [&](int index, const char* name, std::vector<VkFormat> formats) {
            d.name = name;
            d.fragment = ctx.shaders().compile("ibl/localized.frag", {{"IBL_PASS", std::to_string(index)}});
            d.colorFormats = std::move(formats);
            return RasterPipeline(c, d);
        };
        if (mBlendB) {
            mWeights = pass(1, "ibl.localized.weights", {format("weights"), format("count")});
            mNormalized = pass(2, "ibl.localized.normalized", {format("radiance_sum"), format("irradiance_sum")});
        } else {
            mAccumulate = pass(0, "ibl.localized.accumulate",
                               {format("radiance_sum"), format("irradiance_sum"), format("count")});
        }

        d.name = "ibl.localized.resolve";
        d.vertex = ctx.shaders().compile("forward/fullscreen.vert");
        ShaderDefines resolveDefines;
        if (ctx.params().getBool("multiscatter")) resolveDefines.push_back({"VITRINE_MULTISCATTER_ENVIRONMENT", "1"});
        d.fragment = ctx.shaders().compile("ibl/localized_resolve.frag", resolveDefines);
        d.colorFormats = {format("specular"), format("diffuse"), format("radiance")};
        d.depthFormat = VK_FORMAT_UNDEFINED;
        d.depthTest = false;
        d.depthClamp = false;
        d.cullMode = VK_CULL_MODE_NONE;
        d.blend.reset();
        mResolve = RasterPipeline(c, d);
    }

    std::shared_ptr<SceneObject> mScene;
    std::shared_ptr<CameraObject> mCamera;
    bool mBlendB = true;
    std::vector<LocalizedProbe> mProbes;
    Context* mContext = nullptr;
    VkDevice mDevice = VK_NULL_HANDLE;
    DescriptorSets mSets;
    VkDescriptorSet mSet = VK_NULL_HANDLE;
    GpuBuffer mUniforms;
    VkImageView mCubeView = VK_NULL_HANDLE; // see cubeArrayView()
    VkImage mCubeViewImage = VK_NULL_HANDLE;
    RasterPipeline mAccumulate, mWeights, mNormalized, mResolve;
};

const NodeRegistration kRegistration(schema(), [] { return std::make_unique<Localized>(); });

} // namespace
} // namespace vitrine
