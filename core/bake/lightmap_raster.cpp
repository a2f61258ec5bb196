#include "core/bake/lightmap_raster.hpp"

#include "core/base/error.hpp"
#include "core/gpu/context.hpp"
#include "core/gpu/raster.hpp"
#include "core/gpu/transfer.hpp"
#include "core/scene/gpu_scene.hpp"
#include "shaders/scene/scene.h"

#include <cmath>

namespace vitrine::bake {

LightmapTexels rasterizeLightmapTexels(Context& ctx, ShaderCompiler& shaders, GpuScene& gpu,
                                       const scene::Scene& scene, const LightmapAtlas& atlas) {
    if (atlas.width == 0 || atlas.height == 0) throw InternalError("rasterizeLightmapTexels: empty atlas");
    ImageDesc desc;
    desc.width = atlas.width;
    desc.height = atlas.height;
    desc.format = VK_FORMAT_R32G32B32A32_SFLOAT;
    desc.usage = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
    GpuImage position(ctx, desc, "lightmap.texel_position"), normal(ctx, desc, "lightmap.texel_normal");

    RasterPipelineDesc d;
    d.name = "lightmap texels";
    const ShaderDefines defines = {{"VITRINE_SCENE_TEXTURES", std::to_string(std::max(1u, gpu.textureCount()))}};
    d.vertex = shaders.compile("bake/lightmap_texels.vert", defines);
    d.fragment = shaders.compile("bake/lightmap_texels.frag", defines);
    d.setLayouts = {gpu.setLayout()};
    d.pushConstantSize = sizeof(gpu_types::SceneDrawPush);
    d.vertexBindings = GpuScene::vertexBindings();
    d.vertexAttributes = GpuScene::vertexAttributes();
    d.colorFormats = {desc.format, desc.format};
    d.cullMode = VK_CULL_MODE_NONE; // charts may be mirrored in uv space
    d.depthTest = false;
    d.depthWrite = false;
    RasterPipeline pipeline(ctx, d);

    ctx.immediate([&](VkCommandBuffer cmd) {
        for (const GpuImage* image : {&position, &normal})
            imageBarrier(cmd, image->image(), 0, 1, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
                       VK_PIPELINE_STAGE_2_NONE, VK_ACCESS_2_NONE, VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT,
                       VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT);
        VkClearValue zero{};
        beginRendering(cmd, {atlas.width, atlas.height}, {{position.view(), true, zero}, {normal.view(), true, zero}},
                       std::nullopt);
        vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, pipeline.pipeline());
        VkDescriptorSet set = gpu.set();
        vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, pipeline.layout(), 0, 1, &set, 0, nullptr);
        gpu.bindGeometry(cmd);
        for (const GpuDraw& draw : gpu.draws()) {
            const int32_t region = atlas.regionOfInstance.at(draw.instance);
            if (region < 0 || !scene.primitives[draw.primitive].lightmapUvs) continue;
            gpu_types::SceneDrawPush push{};
            push.lightmap = atlas.regions[region].scaleOffset;
            push.instance = draw.instance;
            push.material = draw.material;
            push.pad = static_cast<uint32_t>(region);
            vkCmdPushConstants(cmd, pipeline.layout(), VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT, 0,
                               sizeof(push), &push);
            gpu.drawIndexed(cmd, draw);
        }
        endRendering(cmd);
        for (const GpuImage* image : {&position, &normal})
            imageBarrier(cmd, image->image(), 0, 1, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                       VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT, VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT,
                       VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_READ_BIT);
    });

    const Image p = readImage(ctx, position, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL);
    const Image n = readImage(ctx, normal, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL);
    LightmapTexels t;
    t.width = atlas.width;
    t.height = atlas.height;
    const size_t count = size_t(t.width) * t.height;
    t.irradiance.assign(count, glm::vec3(0.0f));
    t.position.resize(count);
    t.normal.resize(count);
    t.region.resize(count);
    for (uint32_t y = 0; y < t.height; ++y)
        for (uint32_t x = 0; x < t.width; ++x) {
            const size_t i = t.index(x, y);
            const float* pp = p.at(int(x), int(y));
            const float* nn = n.at(int(x), int(y));
            t.position[i] = glm::vec3(pp[0], pp[1], pp[2]);
            t.normal[i] = glm::vec3(nn[0], nn[1], nn[2]);
            t.region[i] = static_cast<int32_t>(std::lround(pp[3])) - 1;
        }
    return t;
}

} // namespace vitrine::bake
