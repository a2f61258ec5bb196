// shadow.directional: the sun's shadow map, as up to four cascades fitted to the view frustum
// (practical split scheme), stabilised by bounding spheres and texel snapping, in one 2x2 atlas.
#include "core/gpu/context.hpp"
#include "core/gpu/raster.hpp"
#include "core/graph/registry.hpp"
#include "core/scene/gpu_scene.hpp"
#include "nodes/shadow/cascades.hpp"

#include <glm/gtc/matrix_transform.hpp>

#include <algorithm>
#include <cmath>

namespace vitrine {
namespace {

using gpu_types::SceneDrawPush;

NodeSchema schema() {
    NodeSchema s;
    s.type = "shadow.directional";
    s.doc = "Sun shadow map: cascades fitted to the camera frustum (practical split scheme), each stabilised by a "
            "bounding sphere and texel snapping, rendered into a 2x2 depth atlas; lighting filters it with PCF.";
    s.pass = PassKind::Raster;
    s.inputs = {{"scene", PortKind::Scene, {}, false, Usage::Sampled, "Shadow casters and the sun direction"},
                {"camera", PortKind::Camera, {}, false, Usage::Sampled, "The view the cascades are fitted to"}};
    OutputPort map;
    map.name = "shadow_map";
    map.format = VK_FORMAT_D32_SFLOAT;
    map.usage = Usage::DepthAttachment;
    map.size = SizeRule::absolute(2048, 2048);
    map.doc = "Depth atlas, 2x2 tiles of `resolution` (cascade c in tile (c % 2, c / 2))";
    OutputPort cascades;
    cascades.name = "cascades";
    cascades.kind = PortKind::Buffer;
    cascades.doc = "Per-frame cascade matrices, splits and filter parameters (shaders/shadow/cascades.h)";
    s.outputs = {map, cascades};
    s.params = {
        {"resolution", ParamType::Int, 1024, 64.0, 8192.0, {}, "Texels per cascade edge (the atlas is twice that)"},
        {"cascades", ParamType::Int, 4, 1.0, 4.0, {}, "Number of cascades"},
        {"distance", ParamType::Float, 60.0, 1.0, 10000.0, {}, "View depth covered by the cascades (m)"},
        {"split_lambda", ParamType::Float, 0.75, 0.0, 1.0, {}, "0: uniform splits, 1: logarithmic"},
        {"depth_bias", ParamType::Float, 1.0, 0.0, 100.0, {}, "Constant depth bias (rasteriser units)"},
        {"slope_bias", ParamType::Float, 1.5, 0.0, 100.0, {}, "Slope-scaled depth bias"},
        {"normal_offset", ParamType::Float, 1.5, 0.0, 16.0, {}, "Receiver offset along the normal, in shadow texels"},
        {"pcf_radius", ParamType::Float, 1.5, 0.0, 8.0, {}, "Filter radius in texels (0: one bilinear-weighted tap)"},
    };
    return s;
}

class Directional final : public Node {
public:
    void setup(SetupContext& ctx) override {
        const Params& p = ctx.params();
        mScene = ctx.objectAs<SceneObject>("scene");
        mCamera = ctx.objectAs<CameraObject>("camera");
        mResolution = static_cast<uint32_t>(p.getInt("resolution"));
        ImageDesc& out = ctx.output("shadow_map");
        out.width = out.height = 2 * mResolution;
        mOut = std::make_shared<ShadowCascadesObject>();
        ctx.setObject("cascades", mOut);
        mCount = p.getInt("cascades");
        mDistance = p.getFloat("distance");
        mLambda = p.getFloat("split_lambda");
        mDepthBias = p.getFloat("depth_bias");
        mSlopeBias = p.getFloat("slope_bias");
        mNormalOffset = p.getFloat("normal_offset");
        mPcf = p.getFloat("pcf_radius");
    }

    void execute(ExecuteContext& ctx) override {
        GpuScene& gpu = mScene->gpu(ctx.gpu(), ctx.shaders());
        if (!mPipeline) createPipeline(ctx, gpu);
        fitCascades();
        VkCommandBuffer cmd = ctx.cmd();
        VkClearValue one{};
        one.depthStencil.depth = 1.0f;
        beginRendering(cmd, {2 * mResolution, 2 * mResolution}, {}, Attachment{ctx.output("shadow_map").view(), true, one});
        vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, mPipeline.pipeline());
        VkDescriptorSet set = gpu.set();
        vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, mPipeline.layout(), 0, 1, &set, 0, nullptr);
        vkCmdSetDepthBias(cmd, mDepthBias, 0.0f, mSlopeBias);
        gpu.bindGeometry(cmd);
        for (int c = 0; c < mCount; ++c) {
            VkViewport vp{static_cast<float>((c % 2) * mResolution), static_cast<float>((c / 2) * mResolution),
                          static_cast<float>(mResolution), static_cast<float>(mResolution), 0.0f, 1.0f};
            VkRect2D scissor{{static_cast<int32_t>(vp.x), static_cast<int32_t>(vp.y)}, {mResolution, mResolution}};
            vkCmdSetViewport(cmd, 0, 1, &vp);
            vkCmdSetScissor(cmd, 0, 1, &scissor);
            SceneDrawPush push{};
            push.viewProj = mLightViewProj[c];
            for (const GpuDraw& d : gpu.draws()) {
                push.instance = d.instance;
                push.material = d.material;
                vkCmdPushConstants(cmd, mPipeline.layout(), VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT, 0,
                                   sizeof(push), &push);
                gpu.drawIndexed(cmd, d);
            }
        }
        endRendering(cmd);
    }

    void releaseGpu() override { mPipeline = RasterPipeline(); }

private:
    void createPipeline(ExecuteContext& ctx, GpuScene& gpu) {
        RasterPipelineDesc d;
        d.name = "shadow.directional";
        d.vertex = ctx.shaders().compile("shadow/depth.vert",
                                         {{"VITRINE_SCENE_TEXTURES", std::to_string(std::max(1u, gpu.textureCount()))}});
        d.setLayouts = {gpu.setLayout()};
        d.pushConstantSize = sizeof(SceneDrawPush);
        d.vertexBindings = GpuScene::vertexBindings();
        d.vertexAttributes = {GpuScene::vertexAttributes()[0]};
        d.depthFormat = VK_FORMAT_D32_SFLOAT;
        d.depthCompare = VK_COMPARE_OP_LESS_OR_EQUAL;
        d.cullMode = VK_CULL_MODE_NONE; // thin walls and open meshes cast from both sides
        d.depthBias = true;
        mPipeline = RasterPipeline(ctx.gpu(), d);
    }

    // Practical split scheme [Zhang06]; each cascade's frustum slice is wrapped in a sphere (so its size
    // does not change as the camera turns) and its centre snapped to whole texels in light space (so
    // edges do not crawl as the camera moves).
    void fitCascades() {
        const scene::Scene& s = mScene->scene();
        const CameraFrame& cam = mCamera->current;
        glm::vec3 toSun = glm::normalize(s.hasSun ? s.sun.toSun : glm::vec3(0.3f, 1.0f, 0.2f));
        const float znear = std::max(cam.state.lens.znear, 0.01f);
        const float zfar = std::max(mDistance, znear * 2.0f);
        const float aspect = static_cast<float>(cam.width) / static_cast<float>(cam.height);
        const float ty = std::tan(0.5f * cam.state.lens.yfov), tx = ty * aspect;
        const glm::mat4& world = cam.state.world;
        const glm::vec3 eye(world[3]), right(world[0]), up(world[1]), fwd(-world[2]);
        glm::vec3 lightUp = std::abs(toSun.y) > 0.99f ? glm::vec3(1.0f, 0.0f, 0.0f) : glm::vec3(0.0f, 1.0f, 0.0f);
        const float sceneRadius = s.bounds.empty() ? 100.0f : 0.5f * glm::length(s.bounds.extent());
        const glm::vec3 sceneCenter = s.bounds.empty() ? glm::vec3(0.0f) : s.bounds.center();

        gpu_types::ShadowCascades& out = mOut->data;
        out = {};
        float previous = znear;
        for (int c = 0; c < mCount; ++c) {
            float i = static_cast<float>(c + 1) / static_cast<float>(mCount);
            float logSplit = znear * std::pow(zfar / znear, i);
            float uniSplit = znear + (zfar - znear) * i;
            float split = mLambda * logSplit + (1.0f - mLambda) * uniSplit;
            // Bounding sphere of the slice [previous, split] (corners at both depths).
            glm::vec3 centre(0.0f);
            glm::vec3 corners[8];
            int k = 0;
            for (float d : {previous, split})
                for (float sx : {-1.0f, 1.0f})
                    for (float sy : {-1.0f, 1.0f}) {
                        corners[k] = eye + d * (fwd + sx * tx * right + sy * ty * up);
                        centre += corners[k++];
                    }
            centre /= 8.0f;
            float radius = 0.0f;
            for (const glm::vec3& p : corners) radius = std::max(radius, glm::length(p - centre));
            radius = std::ceil(radius * 16.0f) / 16.0f;

            // Light view through the centre; depth spans the whole scene so off-slice casters still cast.
            glm::mat4 lightView = glm::lookAt(glm::vec3(0.0f), -toSun, lightUp);
            glm::vec3 lc = glm::vec3(lightView * glm::vec4(centre, 1.0f));
            const float texel = 2.0f * radius / static_cast<float>(mResolution);
            lc.x = std::floor(lc.x / texel) * texel;
            lc.y = std::floor(lc.y / texel) * texel;
            float sceneDepth = -(lightView * glm::vec4(sceneCenter, 1.0f)).z;
            float zNear = sceneDepth - sceneRadius - 1.0f, zFar = sceneDepth + sceneRadius + 1.0f;
            glm::mat4 proj = glm::orthoRH_ZO(lc.x - radius, lc.x + radius, lc.y - radius, lc.y + radius, zNear, zFar);
            mLightViewProj[c] = proj * lightView;
            // NDC xy in [-1, 1] -> this cascade's tile of the atlas.
            glm::mat4 tile(1.0f);
            tile[0][0] = 0.25f;
            tile[1][1] = 0.25f;
            tile[3] = glm::vec4(0.25f + 0.5f * static_cast<float>(c % 2), 0.25f + 0.5f * static_cast<float>(c / 2), 0.0f, 1.0f);
            out.worldToShadow[c] = tile * mLightViewProj[c];
            out.splits[c] = split;
            out.texelWorld[c] = texel;
            previous = split;
        }
        out.params = {static_cast<float>(mCount), static_cast<float>(2 * mResolution), 0.0f, mNormalOffset};
        out.lightDir = glm::vec4(toSun, mPcf);
    }

    std::shared_ptr<SceneObject> mScene;
    std::shared_ptr<CameraObject> mCamera;
    std::shared_ptr<ShadowCascadesObject> mOut;
    RasterPipeline mPipeline;
    glm::mat4 mLightViewProj[4]{};
    uint32_t mResolution = 1024;
    int mCount = 4;
    float mDistance = 60.0f, mLambda = 0.75f, mDepthBias = 1.0f, mSlopeBias = 1.5f, mNormalOffset = 1.5f, mPcf = 1.5f;
};

const NodeRegistration kRegistration(schema(), [] { return std::make_unique<Directional>(); });

} // namespace
} // namespace vitrine
