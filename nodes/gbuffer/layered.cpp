// gbuffer.layered: rasterises the scene into the G-buffer of MUSEUM_SPEC §2, blending the material
// layers per pixel (each parameter by its own mask), with Toksvig-filtered shininess.
#include "core/base/error.hpp"
#include "core/gpu/context.hpp"
#include "core/gpu/raster.hpp"
#include "core/graph/registry.hpp"
#include "core/scene/gpu_scene.hpp"

#include <memory>

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
    s.inputs = {{"scene", PortKind::Scene, {}, false, Usage::Sampled, "The scene to draw (its camera is the frame's)"}};
    s.outputs = {
        attachment("normal", VK_FORMAT_R16G16B16A16_SFLOAT, "x, y: octahedral world normal; z: linear view depth (m); w: shininess"),
        attachment("base_color", VK_FORMAT_R8G8B8A8_UNORM, "rgb: base colour (linear); a: metallic"),
        attachment("material", VK_FORMAT_R8G8B8A8_UNORM, "x: base colour alpha; y: clothness (reserved, 0); z: vertex AO; w: cavity"),
        attachment("velocity", VK_FORMAT_R16G16_SFLOAT, "Screen motion in pixels, this frame minus last (camera and object, no jitter)"),
        attachment("emissive", VK_FORMAT_B10G11R11_UFLOAT_PACK32, "Lightmap or emissive radiance (linear)"),
        attachment("depth", VK_FORMAT_D32_SFLOAT, "Hardware depth, reverse Z (1 near, 0 infinitely far)", Usage::DepthAttachment),
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
    }

    void execute(ExecuteContext& ctx) override {
        GpuScene& gpu = mScene->gpu(ctx.gpu(), ctx.shaders());
        if (!mCullBack) createPipelines(ctx, gpu);
        VkCommandBuffer cmd = ctx.cmd();
        const ImageDesc& size = ctx.output("normal").desc();
        VkClearValue zero{};
        std::vector<Attachment> colors;
        for (const char* port : {"normal", "base_color", "material", "velocity", "emissive"})
            colors.push_back({ctx.output(port).view(), true, zero});
        beginRendering(cmd, {size.width, size.height}, colors, Attachment{ctx.output("depth").view(), true, zero});
        gpu.bindGeometry(cmd);
        VkDescriptorSet set = gpu.set();
        VkPipeline bound = VK_NULL_HANDLE;
        const auto& materials = mScene->scene().materials;
        for (const GpuDraw& d : gpu.draws()) {
            const RasterPipeline& p = materials[d.material].doubleSided ? mCullNone : mCullBack;
            if (p.pipeline() != bound) {
                vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, p.pipeline());
                vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, p.layout(), 0, 1, &set, 0, nullptr);
                bound = p.pipeline();
            }
            SceneDrawPush push{};
            push.instance = d.instance;
            push.material = d.material;
            push.flags = mToksvig ? 1u : 0u;
            vkCmdPushConstants(cmd, p.layout(), VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT, 0, sizeof(push), &push);
            gpu.drawIndexed(cmd, d);
        }
        endRendering(cmd);
    }

    void releaseGpu() override {
        mCullBack = RasterPipeline();
        mCullNone = RasterPipeline();
    }

private:
    void createPipelines(ExecuteContext& ctx, GpuScene& gpu) {
        ShaderDefines defines = {{"VITRINE_SCENE_TEXTURES", std::to_string(std::max(1u, gpu.textureCount()))}};
        RasterPipelineDesc d;
        d.name = "gbuffer.layered";
        d.vertex = ctx.shaders().compile("gbuffer/layered.vert", defines);
        d.fragment = ctx.shaders().compile("gbuffer/layered.frag", defines);
        d.setLayouts = {gpu.setLayout()};
        d.pushConstantSize = sizeof(SceneDrawPush);
        d.vertexBindings = GpuScene::vertexBindings();
        d.vertexAttributes = GpuScene::vertexAttributes();
        for (const char* port : {"normal", "base_color", "material", "velocity", "emissive"})
            d.colorFormats.push_back(ctx.output(port).desc().format);
        d.depthFormat = ctx.output("depth").desc().format;
        mCullBack = RasterPipeline(ctx.gpu(), d);
        d.cullMode = VK_CULL_MODE_NONE;
        mCullNone = RasterPipeline(ctx.gpu(), d);
    }

    std::shared_ptr<SceneObject> mScene;
    bool mToksvig = true;
    RasterPipeline mCullBack, mCullNone;
};

const NodeRegistration kRegistration(schema(), [] { return std::make_unique<GbufferLayered>(); });

} // namespace
} // namespace vitrine
