// gbuffer.layered: rasterises the scene into the G-buffer of MUSEUM_SPEC §2, blending the material
// layers per pixel (each parameter by its own mask), with Toksvig-filtered shininess.
#include "core/base/error.hpp"
#include "core/gpu/context.hpp"
#include "core/gpu/raster.hpp"
#include "core/graph/registry.hpp"
#include "core/gpu/vk_check.hpp"
#include "core/scene/gpu_scene.hpp"
#include "nodes/bake/baked_lighting.hpp"

#include <memory>
#include <utility>

namespace vitrine {
namespace {

using gpu_types::SceneDrawPush;

OutputPort attachment(const char* name, VkFormat format, const char* doc, Usage usage = Usage::ColorAttachment) {
    OutputPort o;
    o.name = name;
    o.format = format;
    o.usage = usage;
    o.doc = doc;
    return o;
}

NodeSchema schema() {
    NodeSchema s;
    s.type = "gbuffer.layered";
    s.doc = "Deferred G-buffer (MUSEUM_SPEC §2): octahedral normal, linear depth, shininess, base colour, metallic, "
            "vertex AO, cavity, exact jitter-free velocity and emissive, from layered materials blended per pixel. "
            "Toksvig: normal-map mips are averaged without renormalising and the shortening becomes roughness.";
    s.pass = PassKind::Raster;
    s.inputs = {
        {"scene", PortKind::Scene, {}, false, Usage::Sampled, "The scene to draw (its camera is the frame's)"},
        {"lightmap", PortKind::Texture, {}, true, Usage::Sampled,
         "bake.lightmap's atlas: lightmapped instances write their baked diffuse into `emissive` (a = 1)"},
        {"baked", PortKind::Buffer, {}, true, Usage::Sampled, "bake.lightmap's `layout` (with `lightmap`)"},
    };
    s.outputs = {
        attachment("normal", VK_FORMAT_R16G16B16A16_SFLOAT,
                   "x, y: octahedral world normal; z: linear view depth (m); w: shininess"),
        attachment("base_color", VK_FORMAT_R8G8B8A8_UNORM, "rgb: base colour (linear); a: metallic"),
        attachment(
            "material", VK_FORMAT_R8G8B8A8_UNORM,
            "x: base colour alpha; y: 1 − KHR_materials_specular strength (0 without it); z: vertex AO; w: cavity"),
        attachment("velocity", VK_FORMAT_R16G16_SFLOAT,
                   "Screen motion in pixels, this frame minus last (camera and object, no jitter)"),
        attachment("emissive", VK_FORMAT_R16G16B16A16_SFLOAT,
                   "rgb: emissive radiance plus, where lightmapped, the baked diffuse (linear, cd/m²); a: 1 where "
                   "lightmapped, else 0, plus 2 × (32 × ⌊31 × clear coat + ½⌋ + ⌊31 × coat roughness + ½⌋)"),
        attachment("sheen", VK_FORMAT_R8G8B8A8_UNORM,
                   "rgb: KHR_materials_sheen colour (linear); a: sheen roughness (0 without a sheen: no lobe)"),
        attachment("depth", VK_FORMAT_D32_SFLOAT, "Hardware depth, reverse Z (1 near, 0 infinitely far)",
                   Usage::DepthAttachment),
    };
    s.params = {
        {"toksvig", ParamType::Bool, true, {}, {}, {}, "Reduce shininess by the averaged normal's length (off: plain normal mapping, for A/B)"},
    };
    return s;
}

class GbufferLayered final : public Node {
public:
    void setup(SetupContext& ctx) override {
        mScene = ctx.objectAs<SceneObject>("scene");
        mToksvig = ctx.params().getBool("toksvig");
        if (ctx.hasInput("lightmap") != ctx.hasInput("baked"))
            ctx.failParam("toksvig", "connect both lightmap and baked (bake.lightmap's lightmap and layout), or neither");
        if (ctx.hasInput("baked")) mBaked = ctx.objectAs<BakedLightingObject>("baked");
    }

    void execute(ExecuteContext& ctx) override {
        GpuScene& gpu = mScene->gpu(ctx.gpu(), ctx.shaders());
        if (!mCullBack) createPipelines(ctx, gpu);
        if (mBaked && !mLightmapSet) createLightmapSet(ctx);
        VkCommandBuffer cmd = ctx.cmd();
        const ImageDesc& size = ctx.output("normal").desc();
        VkClearValue zero{};
        std::vector<Attachment> colors;
        for (const char* port : {"normal", "base_color", "material", "velocity", "emissive", "sheen"})
            colors.push_back({ctx.output(port).view(), true, zero});
        beginRendering(cmd, {size.width, size.height}, colors, Attachment{ctx.output("depth").view(), true, zero});
        gpu.bindGeometry(cmd);
        VkDescriptorSet set = gpu.set();
        VkPipeline bound = VK_NULL_HANDLE;
        const auto& materials = mScene->scene().materials;
        const auto& primitives = mScene->scene().primitives;
        for (const GpuDraw& d : gpu.draws()) {
            const RasterPipeline& p = materials[d.material].doubleSided ? mCullNone : mCullBack;
            if (p.pipeline() != bound) {
                vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, p.pipeline());
                vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, p.layout(), 0, 1, &set, 0, nullptr);
                if (mLightmapSet)
                    vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, p.layout(), 1, 1, &mLightmapSet, 0,
                                            nullptr);
                bound = p.pipeline();
            }
            SceneDrawPush push{};
            push.instance = d.instance;
            push.material = d.material;
            push.flags = mToksvig ? 1u : 0u;
            if (mBaked && mBaked->hasLightmap(d.instance) && primitives[d.primitive].lightmapUvs) {
                push.flags |= 2u;
                push.lightmap = mBaked->lightmapScaleOffset[d.instance];
            }
            vkCmdPushConstants(cmd, p.layout(), VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT, 0, sizeof(push), &push);
            gpu.drawIndexed(cmd, d);
        }
        endRendering(cmd);
    }

    void releaseGpu() override {
        mCullBack = RasterPipeline();
        mCullNone = RasterPipeline();
        if (mContext) {
            VkDevice device = mContext->device();
            VkDescriptorSetLayout layout = std::exchange(mLightmapLayout, VK_NULL_HANDLE);
            VkDescriptorPool pool = std::exchange(mLightmapPool, VK_NULL_HANDLE);
            VkSampler sampler = std::exchange(mLightmapSampler, VK_NULL_HANDLE);
            mContext->destroyLater([device, layout, pool, sampler] {
                if (layout) vkDestroyDescriptorSetLayout(device, layout, nullptr);
                if (pool) vkDestroyDescriptorPool(device, pool, nullptr);
                if (sampler) vkDestroySampler(device, sampler, nullptr);
            });
            mLightmapSet = VK_NULL_HANDLE;
            mContext = nullptr;
        }
    }
    ~GbufferLayered() override { releaseGpu(); }

private:
    // Set 1 of the fragment shader: the lightmap atlas, bilinear and clamped (charts have gutters).
    void createLightmapLayout(Context& context) {
        mContext = &context;
        VkDevice device = context.device();
        VkDescriptorSetLayoutBinding b{0, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 1, VK_SHADER_STAGE_FRAGMENT_BIT, nullptr};
        VkDescriptorSetLayoutCreateInfo li{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
        li.bindingCount = 1;
        li.pBindings = &b;
        VK_CHECK(vkCreateDescriptorSetLayout(device, &li, nullptr, &mLightmapLayout));
    }

    void createLightmapSet(ExecuteContext& ctx) {
        VkDevice device = ctx.gpu().device();
        VkSamplerCreateInfo si{VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO};
        si.magFilter = si.minFilter = VK_FILTER_LINEAR;
        si.addressModeU = si.addressModeV = si.addressModeW = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE;
        VK_CHECK(vkCreateSampler(device, &si, nullptr, &mLightmapSampler));
        VkDescriptorPoolSize size{VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 1};
        VkDescriptorPoolCreateInfo pi{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
        pi.maxSets = 1;
        pi.poolSizeCount = 1;
        pi.pPoolSizes = &size;
        VK_CHECK(vkCreateDescriptorPool(device, &pi, nullptr, &mLightmapPool));
        VkDescriptorSetAllocateInfo ai{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
        ai.descriptorPool = mLightmapPool;
        ai.descriptorSetCount = 1;
        ai.pSetLayouts = &mLightmapLayout;
        VK_CHECK(vkAllocateDescriptorSets(device, &ai, &mLightmapSet));
        VkDescriptorImageInfo image{mLightmapSampler, ctx.input("lightmap").view(), VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL};
        VkWriteDescriptorSet w{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
        w.dstSet = mLightmapSet;
        w.dstBinding = 0;
        w.descriptorCount = 1;
        w.descriptorType = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER;
        w.pImageInfo = &image;
        vkUpdateDescriptorSets(device, 1, &w, 0, nullptr);
    }

    void createPipelines(ExecuteContext& ctx, GpuScene& gpu) {
        ShaderDefines defines = {{"VITRINE_SCENE_TEXTURES", std::to_string(std::max(1u, gpu.textureCount()))}};
        if (mBaked) {
            defines.push_back({"VITRINE_GBUFFER_LIGHTMAP", "1"});
            createLightmapLayout(ctx.gpu());
        }
        RasterPipelineDesc d;
        d.name = "gbuffer.layered";
        d.vertex = ctx.shaders().compile("gbuffer/layered.vert", defines);
        d.fragment = ctx.shaders().compile("gbuffer/layered.frag", defines);
        d.setLayouts = {gpu.setLayout()};
        if (mBaked) d.setLayouts.push_back(mLightmapLayout);
        d.pushConstantSize = sizeof(SceneDrawPush);
        d.vertexBindings = GpuScene::vertexBindings();
        d.vertexAttributes = GpuScene::vertexAttributes();
        for (const char* port : {"normal", "base_color", "material", "velocity", "emissive", "sheen"})
            d.colorFormats.push_back(ctx.output(port).desc().format);
        d.depthFormat = ctx.output("depth").desc().format;
        mCullBack = RasterPipeline(ctx.gpu(), d);
        d.cullMode = VK_CULL_MODE_NONE;
        mCullNone = RasterPipeline(ctx.gpu(), d);
    }

    std::shared_ptr<SceneObject> mScene;
    std::shared_ptr<BakedLightingObject> mBaked;
    bool mToksvig = true;
    RasterPipeline mCullBack, mCullNone;
    Context* mContext = nullptr;
    VkDescriptorSetLayout mLightmapLayout = VK_NULL_HANDLE;
    VkDescriptorPool mLightmapPool = VK_NULL_HANDLE;
    VkSampler mLightmapSampler = VK_NULL_HANDLE;
    VkDescriptorSet mLightmapSet = VK_NULL_HANDLE;
};

const NodeRegistration kRegistration(schema(), [] { return std::make_unique<GbufferLayered>(); });

} // namespace
} // namespace vitrine
