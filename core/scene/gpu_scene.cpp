#include "core/scene/gpu_scene.hpp"

#include "core/accel/gpu_bvh.hpp"
#include "core/accel/scene_bvh.hpp"
#include "core/bake/cache.hpp"
#include "core/base/error.hpp"
#include "core/base/log.hpp"
#include "core/gpu/context.hpp"
#include "core/gpu/pipeline.hpp"
#include "core/gpu/transfer.hpp"
#include "core/gpu/vk_check.hpp"
#include "core/shader/compiler.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>

namespace vitrine {

using namespace gpu_types;

gpu_types::GpuCamera CameraFrame::gpu() const {
    GpuCamera c{};
    c.view = state.view;
    c.proj = proj;
    c.viewProj = viewProj;
    c.invViewProj = invViewProj;
    c.viewProjNoJitter = viewProjNoJitter;
    c.prevViewProjNoJitter = prevViewProjNoJitter;
    c.position = glm::vec4(state.position, 1.0f);
    c.params = {state.lens.znear, state.lens.zfar, static_cast<float>(width), static_cast<float>(height)};
    c.jitter = {jitter, prevJitter};
    c.time = {static_cast<float>(time), static_cast<float>(frame), 0.0f, vertexJitterThreshold};
    return c;
}

SceneObject::SceneObject(std::shared_ptr<const scene::Scene> scene) : mScene(std::move(scene)) {}

SceneObject::~SceneObject() = default;

void SceneObject::releaseGpu() {
    for (auto& b : mGpuBvh)
        b.reset();
    mGpu.reset();
}

GpuBvh& SceneObject::bvh(Context& ctx, bool transparent) {
    const int i = transparent ? 1 : 0;
    if (!mGpuBvh[i]) {
        if (!mBvh[i]) {
            accel::SceneBvh::CacheStatus status;
            accel::BvhBuildOptions options;
            options.transparent = transparent;
            mBvh[i] = std::make_unique<accel::SceneBvh>(
                accel::SceneBvh::loadOrBuild(*mScene, BakeCache(defaultCacheDir()), options, &status));
            mBvhFromCache = status.fromCache;
            const std::string what = transparent ? "BVH with transparent surfaces" : "BVH";
            if (status.fromCache)
                logInfo("scene '" + mScene->name + "': " + what + " loaded from the bake cache");
            else
                logInfo("scene '" + mScene->name + "': " + what + " built in " +
                        std::to_string(static_cast<int>(mBvh[i]->buildMs())) + " ms");
            if (!status.fromCache && !status.stored)
                logWarning("scene '" + mScene->name + "': could not write the BVH to the bake cache under " +
                           defaultCacheDir().string());
        }
        if (!mBvh[i]->deformedLevels().empty()) mBvh[i]->refit(*mScene, deformation().posedVertices(pose));
        mGpuBvh[i] = std::make_unique<GpuBvh>(ctx, *mBvh[i], mScene->name);
        mGpuBvh[i]->update(pose);
    }
    return *mGpuBvh[i];
}

const scene::Deformation& SceneObject::deformation() const {
    if (!mDeformation) mDeformation = std::make_unique<scene::Deformation>(*mScene);
    return *mDeformation;
}

void SceneObject::reposeBvh(const scene::ScenePose& p) {
    std::vector<scene::Vertex> posed; // posed once for both BVHs
    for (int i = 0; i < 2; ++i) {
        if (!mGpuBvh[i]) continue;
        if (!mBvh[i]->deformedLevels().empty()) {
            if (posed.empty()) posed = deformation().posedVertices(p);
            mBvh[i]->refit(*mScene, posed);
        }
        mGpuBvh[i]->update(p);
    }
}

const StorageBufferSet& GpuScene::geometrySet() {
    if (!mGeometrySet) {
        const TexelPool pool = packTexelPool(mScene);
        const auto& table = pool.table;
        const auto& texels = pool.texels;
        mTexelTable = uploadBuffer(mCtx, table.data(), table.size() * sizeof(table[0]), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                                   mScene.name + ".texel_table");
        mTexels = uploadBuffer(mCtx, texels.data(), texels.size() * 4, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                               mScene.name + ".texels");
        const VkBuffer buffers[4] = {mVertices.buffer(), mIndices.buffer(), mTexelTable.buffer(), mTexels.buffer()};
        mGeometrySet = StorageBufferSet(mCtx, buffers, VK_SHADER_STAGE_COMPUTE_BIT, mScene.name + ".geometry");
    }
    return mGeometrySet;
}

GpuScene& SceneObject::gpu() const {
    if (!mGpu) throw InternalError("the scene '" + mScene->name + "' was used on the GPU before its node uploaded it");
    return *mGpu;
}

namespace {

using Clock = std::chrono::steady_clock;

GpuTexRef texRef(const scene::TextureRef& ref, uint32_t channel = 0) {
    GpuTexRef r{};
    r.info = {ref.texture, static_cast<int>(ref.uvSet), static_cast<int>(channel), 0};
    glm::mat3 m = ref.transform.matrix(); // column-major: m[col][row]
    r.row0 = {m[0][0], m[1][0], m[2][0], 0.0f};
    r.row1 = {m[0][1], m[1][1], m[2][1], 0.0f};
    return r;
}

VkFilter toVk(scene::Filter f) { return f == scene::Filter::Nearest ? VK_FILTER_NEAREST : VK_FILTER_LINEAR; }
VkSamplerAddressMode toVk(scene::Wrap w) {
    switch (w) {
    case scene::Wrap::ClampToEdge: return VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE;
    case scene::Wrap::MirroredRepeat: return VK_SAMPLER_ADDRESS_MODE_MIRRORED_REPEAT;
    default: return VK_SAMPLER_ADDRESS_MODE_REPEAT;
    }
}

uint32_t mipCount(uint32_t w, uint32_t h) {
    return 1 + static_cast<uint32_t>(std::floor(std::log2(static_cast<double>(std::max(w, h)))));
}

} // namespace

void packMaterials(const scene::Scene& scene, std::vector<GpuMaterial>& materials, std::vector<GpuLayer>& layers) {
    materials.clear();
    layers.clear();
    for (const scene::Material& m : scene.materials) {
        GpuMaterial g{};
        g.info = {static_cast<uint32_t>(layers.size()), static_cast<uint32_t>(m.layers.size()),
                  static_cast<uint32_t>(m.alphaMode), m.doubleSided ? 1u : 0u};
        g.emissive = glm::vec4(m.emissiveFactor * m.emissiveStrength, m.alphaCutoff);
        g.emissiveRef = texRef(m.emissiveTexture);
        float r = m.ior == 0.0f ? 1.0f : (m.ior - 1.0f) / (m.ior + 1.0f); // KHR_materials_ior: 0 means F0 = 1
        g.optics = {m.transmission, r * r, m.unlit ? 1.0f : 0.0f, m.thickness};
        g.specular = glm::vec4(m.specularColor, m.specular);
        g.specularRef = texRef(m.specularTexture, 3);
        g.specularColorRef = texRef(m.specularColorTexture);
        g.clearcoat = {m.clearcoat, m.clearcoatRoughness, m.clearcoatNormal.scale, 0.0f};
        g.clearcoatRef = texRef(m.clearcoatTexture, 0);
        g.clearcoatRoughnessRef = texRef(m.clearcoatRoughnessTexture, 1);
        g.clearcoatNormalRef = texRef(m.clearcoatNormal.texture);
        g.sheen = glm::vec4(m.sheenColor, m.sheenRoughness);
        g.sheenColorRef = texRef(m.sheenColorTexture);
        g.sheenRoughnessRef = texRef(m.sheenRoughnessTexture, 3);
        g.volume = glm::vec4(m.attenuationColor, std::isinf(m.attenuationDistance) ? 0.0f : m.attenuationDistance);
        g.thicknessRef = texRef(m.thicknessTexture, 1);
        materials.push_back(g);
        for (size_t li = 0; li < m.layers.size(); ++li) {
            const scene::MaterialLayer& l = m.layers[li];
            GpuLayer gl{};
            gl.albedo = l.albedo.factor;
            gl.scalars0 = {l.normal.scale, l.shininess.factor, l.shininess.atZero, l.metallic.factor};
            gl.scalars1 = {l.metallic.atZero, l.cavity.factor, l.cavity.atZero, li == 0 ? 1.0f : l.mask.factor};
            gl.bits = {li == 0 ? scene::kLayerAll : l.overrides, 0u, 0u, 0u};
            gl.refs[VITRINE_REF_ALBEDO] = texRef(l.albedo.texture);
            gl.refs[VITRINE_REF_NORMAL] = texRef(l.normal.texture);
            gl.refs[VITRINE_REF_SHININESS] = texRef(l.shininess.texture, l.shininess.channel);
            gl.refs[VITRINE_REF_METALLIC] = texRef(l.metallic.texture, l.metallic.channel);
            gl.refs[VITRINE_REF_CAVITY] = texRef(l.cavity.texture, l.cavity.channel);
            gl.refs[VITRINE_REF_MASK] = li == 0 ? texRef({}) : texRef(l.mask.texture, l.mask.channel);
            layers.push_back(gl);
        }
    }
}

TexelPool packTexelPool(const scene::Scene& scene) {
    TexelPool pool;
    auto& texels = pool.texels;
    auto& table = pool.table;
    // The texel pool: every image once (textures may share one), in the layout of texelFetch's RGBA8 (r in
    // the low byte), and per texture a uvec4 (first texel, width, height, bits: see scene.h TEXEL_*).
    std::vector<uint32_t> imageStart(scene.images.size(), ~0u);
    for (const scene::Texture& tex : scene.textures) {
        const scene::TextureImage& img = scene.images[tex.image];
        if (imageStart[tex.image] == ~0u) {
            imageStart[tex.image] = static_cast<uint32_t>(texels.size());
            texels.resize(texels.size() + static_cast<size_t>(img.width) * img.height);
            std::memcpy(texels.data() + imageStart[tex.image], img.pixels.data(),
                        static_cast<size_t>(img.width) * img.height * 4);
        }
        auto wrap = [](scene::Wrap w) {
            return w == scene::Wrap::ClampToEdge ? VITRINE_TEXEL_CLAMP
                   : w == scene::Wrap::MirroredRepeat ? VITRINE_TEXEL_MIRROR
                                                      : VITRINE_TEXEL_REPEAT;
        };
        uint32_t bits = (tex.colorSpace() == scene::ColorSpace::Srgb ? VITRINE_TEXEL_SRGB : 0u) |
                        (tex.sampler.magFilter == scene::Filter::Nearest ? VITRINE_TEXEL_NEAREST : 0u) |
                        wrap(tex.sampler.wrapU) << VITRINE_TEXEL_WRAP_U_SHIFT |
                        wrap(tex.sampler.wrapV) << VITRINE_TEXEL_WRAP_V_SHIFT;
        table.push_back({imageStart[tex.image], img.width, img.height, bits});
    }
    if (table.empty()) table.push_back({0, 1, 1, 0});
    if (texels.empty()) texels.push_back(0xffffffffu);
    return pool;
}

GpuScene::GpuScene(Context& ctx, ShaderCompiler& shaders, const scene::Scene& scene, float anisotropy)
    : mCtx(ctx), mScene(scene), mAnisotropy(anisotropy), mDeformation(scene) {
    auto start = Clock::now();
    try {
        const size_t vbytes = scene.vertices.size() * sizeof(scene::Vertex);
        const size_t ibytes = scene.indices.size() * sizeof(uint32_t);
        if (mDeformation.any() && vbytes > 0) {
            // Animated morph weights or joints: update() re-poses the vertices in place, in host-visible memory.
            mVertices = GpuBuffer(ctx, vbytes, VK_BUFFER_USAGE_VERTEX_BUFFER_BIT | VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                                  true, scene.name + ".vertices");
            std::memcpy(mVertices.mapped(), scene.vertices.data(), vbytes);
            mPrevPositions = GpuBuffer(ctx, scene.vertices.size() * sizeof(glm::vec4),
                                       VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, true, scene.name + ".prev_positions");
            auto* prev = static_cast<glm::vec4*>(mPrevPositions.mapped());
            for (size_t v = 0; v < scene.vertices.size(); ++v)
                prev[v] = glm::vec4(scene.vertices[v].position, 1.0f);
            mPosed = scene.vertices;
        } else {
            mVertices = uploadBuffer(ctx, scene.vertices.data(), vbytes,
                                     VK_BUFFER_USAGE_VERTEX_BUFFER_BIT | VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                                     scene.name + ".vertices");
        }
        mIndices = uploadBuffer(ctx, scene.indices.data(), ibytes,
                                VK_BUFFER_USAGE_INDEX_BUFFER_BIT | VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, scene.name + ".indices");
        mStats.geometryBytes = vbytes + ibytes;

        std::vector<GpuMaterial> materials;
        std::vector<GpuLayer> layers;
        packMaterials(scene, materials, layers);
        mMaterials = uploadBuffer(ctx, materials.data(), materials.size() * sizeof(GpuMaterial),
                                  VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, scene.name + ".materials");
        mLayers = uploadBuffer(ctx, layers.data(), layers.size() * sizeof(GpuLayer), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT,
                               scene.name + ".layers");
        if (!mPrevPositions.buffer())
            mPrevPositions = GpuBuffer(ctx, sizeof(glm::vec4), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, true,
                                       scene.name + ".prev_positions"); // nothing deforms: never read
        mInstances = GpuBuffer(ctx, std::max<size_t>(1, scene.instances.size()) * sizeof(GpuInstance),
                               VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, true, scene.name + ".instances");
        mCamera = GpuBuffer(ctx, sizeof(GpuCamera), VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT, true, scene.name + ".camera");
        std::memset(mInstances.mapped(), 0, mInstances.size());
        std::memset(mCamera.mapped(), 0, mCamera.size());

        for (uint32_t i = 0; i < scene.instances.size(); ++i) {
            const scene::Mesh& mesh = scene.meshes[scene.instances[i].mesh];
            for (uint32_t p = mesh.firstPrimitive; p < mesh.firstPrimitive + mesh.primitiveCount; ++p)
            {
                uint32_t material = scene.primitives[p].material;
                (scene.materials[material].transparent() ? mTransparentDraws : mDraws).push_back({i, p, material});
            }
        }
        // Grouped by material, then instance: fewer state changes, and a stable order.
        std::stable_sort(mDraws.begin(), mDraws.end(), [](const GpuDraw& a, const GpuDraw& b) { return a.material < b.material; });

        uploadTextures(shaders);
        createDescriptors();
    } catch (...) {
        releaseHandles();
        throw;
    }
    mStats.uploadMs = std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

GpuScene::~GpuScene() { releaseHandles(); }

void GpuScene::releaseHandles() {
    VkDevice device = mCtx.device();
    std::vector<VkSampler> samplers = std::move(mSamplers);
    VkDescriptorSetLayout layout = std::exchange(mSetLayout, VK_NULL_HANDLE);
    VkDescriptorPool pool = std::exchange(mPool, VK_NULL_HANDLE);
    mCtx.destroyLater([device, samplers, layout, pool] {
        for (VkSampler s : samplers) vkDestroySampler(device, s, nullptr);
        if (layout) vkDestroyDescriptorSetLayout(device, layout, nullptr);
        if (pool) vkDestroyDescriptorPool(device, pool, nullptr);
    });
}

void GpuScene::uploadTextures(ShaderCompiler& shaders) {
    const scene::Scene& scene = mScene;
    VkPhysicalDeviceFeatures supported{};
    vkGetPhysicalDeviceFeatures(mCtx.physicalDevice(), &supported);
    // Auto (< 0): 8x on GPUs; off on CPU devices, where lavapipe's software anisotropic filtering costs
    // minutes per frame.
    float aniso = mAnisotropy >= 0.0f ? mAnisotropy
                                      : (mCtx.deviceInfo().type == VK_PHYSICAL_DEVICE_TYPE_CPU ? 1.0f : 8.0f);
    const float maxAniso = supported.samplerAnisotropy ? std::clamp(aniso, 1.0f, mCtx.properties().limits.maxSamplerAnisotropy) : 1.0f;

    std::vector<uint32_t> normalMaps;
    std::vector<GpuBuffer> staging;
    for (uint32_t t = 0; t < scene.textures.size(); ++t) {
        const scene::Texture& tex = scene.textures[t];
        const scene::TextureImage& img = scene.images[tex.image];
        ImageDesc d;
        d.width = img.width;
        d.height = img.height;
        d.mipLevels = tex.sampler.mipFilter == scene::MipFilter::None ? 1 : mipCount(img.width, img.height);
        d.format = tex.colorSpace() == scene::ColorSpace::Srgb ? VK_FORMAT_R8G8B8A8_SRGB : VK_FORMAT_R8G8B8A8_UNORM;
        d.usage = VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
        if (tex.usage == scene::TextureUsage::Normal) {
            d.usage |= VK_IMAGE_USAGE_STORAGE_BIT;
            normalMaps.push_back(t);
        }
        mTextures.emplace_back(mCtx, d, scene.name + ".tex." + tex.name);
        for (uint32_t m = 0, w = d.width, h = d.height; m < d.mipLevels; ++m, w = std::max(1u, w / 2), h = std::max(1u, h / 2))
            mStats.textureBytes += static_cast<uint64_t>(w) * h * 4;

        VkSamplerCreateInfo si{VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO};
        si.magFilter = toVk(tex.sampler.magFilter);
        si.minFilter = toVk(tex.sampler.minFilter);
        si.mipmapMode = tex.sampler.mipFilter == scene::MipFilter::Nearest ? VK_SAMPLER_MIPMAP_MODE_NEAREST : VK_SAMPLER_MIPMAP_MODE_LINEAR;
        si.addressModeU = toVk(tex.sampler.wrapU);
        si.addressModeV = toVk(tex.sampler.wrapV);
        si.addressModeW = VK_SAMPLER_ADDRESS_MODE_REPEAT;
        si.anisotropyEnable = maxAniso > 1.0f;
        si.maxAnisotropy = maxAniso;
        si.maxLod = VK_LOD_CLAMP_NONE;
        VkSampler sampler;
        VK_CHECK(vkCreateSampler(mCtx.device(), &si, nullptr, &sampler));
        mSamplers.push_back(sampler);
    }
    if (scene.textures.empty()) {
        ImageDesc d;
        d.format = VK_FORMAT_R8G8B8A8_UNORM;
        d.usage = VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT;
        mFallback = GpuImage(mCtx, d, scene.name + ".tex.fallback");
        VkSamplerCreateInfo si{VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO};
        VkSampler sampler;
        VK_CHECK(vkCreateSampler(mCtx.device(), &si, nullptr, &sampler));
        mSamplers.push_back(sampler);
    }

    // Level 0 of every texture by copy; the other levels by blits (colour and data: box filter, sRGB
    // decoded by the blit) or, for normal maps, by the Toksvig compute pass. A normal map's alpha is the Toksvig
    // chain's (shaders/scene/toksvig_mip.comp): sqrt(1 - length of the mean unit normal), 0 on level 0, whose
    // normals are unit whatever their bytes decode to (glTF gives a normal texture's alpha no meaning).
    for (uint32_t t = 0; t < scene.textures.size(); ++t) {
        const scene::TextureImage& img = scene.images[scene.textures[t].image];
        staging.emplace_back(mCtx, img.pixels.size(), VK_BUFFER_USAGE_TRANSFER_SRC_BIT, true, "texture.staging");
        auto* dst = static_cast<uint8_t*>(staging.back().mapped());
        std::memcpy(dst, img.pixels.data(), img.pixels.size());
        if (scene.textures[t].usage == scene::TextureUsage::Normal)
            for (size_t i = 3; i < img.pixels.size(); i += 4) dst[i] = 0;
    }
    mCtx.immediate([&](VkCommandBuffer cmd) {
        if (mFallback) {
            imageBarrier(cmd, mFallback.image(), 0, 1, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                         VK_PIPELINE_STAGE_2_NONE, 0, VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT);
            VkClearColorValue white{{1.0f, 1.0f, 1.0f, 1.0f}};
            VkImageSubresourceRange range{VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
            vkCmdClearColorImage(cmd, mFallback.image(), VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, &white, 1, &range);
            imageBarrier(cmd, mFallback.image(), 0, 1, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
                         VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT,
                         VK_ACCESS_2_SHADER_SAMPLED_READ_BIT);
        }
        for (uint32_t t = 0; t < mTextures.size(); ++t) {
            const GpuImage& image = mTextures[t];
            const ImageDesc& d = image.desc();
            imageBarrier(cmd, image.image(), 0, d.mipLevels, VK_IMAGE_LAYOUT_UNDEFINED, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                         VK_PIPELINE_STAGE_2_NONE, 0, VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT);
            VkBufferImageCopy copy{};
            copy.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
            copy.imageExtent = {d.width, d.height, 1};
            vkCmdCopyBufferToImage(cmd, staging[t].buffer(), image.image(), VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &copy);
            if (std::find(normalMaps.begin(), normalMaps.end(), t) != normalMaps.end()) continue;
            for (uint32_t m = 1; m < d.mipLevels; ++m) {
                imageBarrier(cmd, image.image(), m - 1, 1, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                             VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT,
                             VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_READ_BIT);
                VkImageBlit blit{};
                blit.srcSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, m - 1, 0, 1};
                blit.srcOffsets[1] = {static_cast<int32_t>(std::max(1u, d.width >> (m - 1))),
                                      static_cast<int32_t>(std::max(1u, d.height >> (m - 1))), 1};
                blit.dstSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, m, 0, 1};
                blit.dstOffsets[1] = {static_cast<int32_t>(std::max(1u, d.width >> m)),
                                      static_cast<int32_t>(std::max(1u, d.height >> m)), 1};
                vkCmdBlitImage(cmd, image.image(), VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, image.image(),
                               VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1, &blit, VK_FILTER_LINEAR);
            }
            if (d.mipLevels > 1)
                imageBarrier(cmd, image.image(), 0, d.mipLevels - 1, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL,
                             VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT,
                             VK_ACCESS_2_TRANSFER_READ_BIT, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT,
                             VK_ACCESS_2_SHADER_SAMPLED_READ_BIT);
            imageBarrier(cmd, image.image(), d.mipLevels - 1, 1, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL,
                         VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT,
                         VK_ACCESS_2_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT,
                         VK_ACCESS_2_SHADER_SAMPLED_READ_BIT);
        }
        buildToksvigMips(shaders, cmd, normalMaps);
    });
}

// Normal-map mips for Toksvig (MUSEUM_SPEC §2): each texel of level m+1 is the plain average of the 2x2
// decoded normals below it, re-encoded WITHOUT renormalising, and in alpha how much the unit normals of level 0
// under it disagree (sqrt(1 - length of their mean)), which the G-buffer pass reads as extra roughness
// (shaders/scene/toksvig_mip.comp).
void GpuScene::buildToksvigMips(ShaderCompiler& shaders, VkCommandBuffer cmd, const std::vector<uint32_t>& normalMaps) {
    if (normalMaps.empty()) return;
    CompiledShader shader = shaders.compile("scene/toksvig_mip.comp");
    VkDevice device = mCtx.device();
    VkDescriptorSetLayoutBinding bindings[2] = {
        {0, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, 1, VK_SHADER_STAGE_COMPUTE_BIT, nullptr},
        {1, VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, 1, VK_SHADER_STAGE_COMPUTE_BIT, nullptr},
    };
    VkDescriptorSetLayoutCreateInfo li{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
    li.bindingCount = 2;
    li.pBindings = bindings;
    VkDescriptorSetLayout setLayout;
    VK_CHECK(vkCreateDescriptorSetLayout(device, &li, nullptr, &setLayout));
    VkPipelineLayoutCreateInfo pl{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
    pl.setLayoutCount = 1;
    pl.pSetLayouts = &setLayout;
    VkPipelineLayout layout;
    VK_CHECK(vkCreatePipelineLayout(device, &pl, nullptr, &layout));
    VkPipeline pipeline = createComputePipeline(mCtx, shader, layout);

    uint32_t sets = 0;
    for (uint32_t t : normalMaps) sets += mTextures[t].desc().mipLevels;
    VkDescriptorPoolSize size{VK_DESCRIPTOR_TYPE_STORAGE_IMAGE, 2 * sets};
    VkDescriptorPoolCreateInfo pi{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
    pi.maxSets = sets;
    pi.poolSizeCount = 1;
    pi.pPoolSizes = &size;
    VkDescriptorPool pool;
    VK_CHECK(vkCreateDescriptorPool(device, &pi, nullptr, &pool));

    vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline);
    for (uint32_t t : normalMaps) {
        const GpuImage& image = mTextures[t];
        const ImageDesc& d = image.desc();
        imageBarrier(cmd, image.image(), 0, d.mipLevels, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, VK_IMAGE_LAYOUT_GENERAL,
                     VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT, VK_ACCESS_2_TRANSFER_WRITE_BIT, VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT,
                     VK_ACCESS_2_SHADER_STORAGE_READ_BIT | VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT);
        for (uint32_t m = 1; m < d.mipLevels; ++m) {
            VkDescriptorSetAllocateInfo ai{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
            ai.descriptorPool = pool;
            ai.descriptorSetCount = 1;
            ai.pSetLayouts = &setLayout;
            VkDescriptorSet set;
            VK_CHECK(vkAllocateDescriptorSets(device, &ai, &set));
            VkDescriptorImageInfo src{VK_NULL_HANDLE, image.mipView(m - 1), VK_IMAGE_LAYOUT_GENERAL};
            VkDescriptorImageInfo dst{VK_NULL_HANDLE, image.mipView(m), VK_IMAGE_LAYOUT_GENERAL};
            VkWriteDescriptorSet w[2] = {{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET}, {VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET}};
            for (int i = 0; i < 2; ++i) {
                w[i].dstSet = set;
                w[i].dstBinding = static_cast<uint32_t>(i);
                w[i].descriptorCount = 1;
                w[i].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_IMAGE;
                w[i].pImageInfo = i == 0 ? &src : &dst;
            }
            vkUpdateDescriptorSets(device, 2, w, 0, nullptr);
            vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_COMPUTE, layout, 0, 1, &set, 0, nullptr);
            uint32_t w2 = std::max(1u, d.width >> m), h2 = std::max(1u, d.height >> m);
            vkCmdDispatch(cmd, (w2 + 7) / 8, (h2 + 7) / 8, 1);
            imageBarrier(cmd, image.image(), m, 1, VK_IMAGE_LAYOUT_GENERAL, VK_IMAGE_LAYOUT_GENERAL,
                         VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
                         VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_READ_BIT);
        }
        imageBarrier(cmd, image.image(), 0, d.mipLevels, VK_IMAGE_LAYOUT_GENERAL, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL,
                     VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT, VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT,
                     VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT, VK_ACCESS_2_SHADER_SAMPLED_READ_BIT);
    }
    mCtx.destroyLater([device, pipeline, layout, setLayout, pool] {
        vkDestroyPipeline(device, pipeline, nullptr);
        vkDestroyPipelineLayout(device, layout, nullptr);
        vkDestroyDescriptorSetLayout(device, setLayout, nullptr);
        vkDestroyDescriptorPool(device, pool, nullptr);
    });
}

void GpuScene::createDescriptors() {
    VkDevice device = mCtx.device();
    const uint32_t textures = std::max<uint32_t>(1, textureCount());
    const VkShaderStageFlags stages = VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT | VK_SHADER_STAGE_COMPUTE_BIT;
    VkDescriptorSetLayoutBinding b[6] = {
        {0, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, 1, stages, nullptr},
        {1, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, stages, nullptr},
        {2, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, stages, nullptr},
        {3, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, stages, nullptr},
        {4, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, textures, stages, nullptr},
        {5, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, stages, nullptr},
    };
    VkDescriptorSetLayoutCreateInfo li{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
    li.bindingCount = 6;
    li.pBindings = b;
    VK_CHECK(vkCreateDescriptorSetLayout(device, &li, nullptr, &mSetLayout));
    VkDescriptorPoolSize sizes[3] = {{VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, 1},
                                     {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 4},
                                     {VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, textures}};
    VkDescriptorPoolCreateInfo pi{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
    pi.maxSets = 1;
    pi.poolSizeCount = 3;
    pi.pPoolSizes = sizes;
    VK_CHECK(vkCreateDescriptorPool(device, &pi, nullptr, &mPool));
    VkDescriptorSetAllocateInfo ai{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
    ai.descriptorPool = mPool;
    ai.descriptorSetCount = 1;
    ai.pSetLayouts = &mSetLayout;
    VK_CHECK(vkAllocateDescriptorSets(device, &ai, &mSet));

    VkDescriptorBufferInfo buffers[6] = {{mCamera.buffer(), 0, VK_WHOLE_SIZE},
                                         {mInstances.buffer(), 0, VK_WHOLE_SIZE},
                                         {mMaterials.buffer(), 0, VK_WHOLE_SIZE},
                                         {mLayers.buffer(), 0, VK_WHOLE_SIZE},
                                         {},
                                         {mPrevPositions.buffer(), 0, VK_WHOLE_SIZE}};
    std::vector<VkDescriptorImageInfo> images;
    for (uint32_t t = 0; t < mTextures.size(); ++t)
        images.push_back({mSamplers[t], mTextures[t].view(), VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL});
    if (images.empty()) images.push_back({mSamplers[0], mFallback.view(), VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL});
    std::vector<VkWriteDescriptorSet> writes;
    for (uint32_t i = 0; i < 6; ++i) {
        VkWriteDescriptorSet w{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
        w.dstSet = mSet;
        w.dstBinding = i;
        w.descriptorType = b[i].descriptorType;
        w.descriptorCount = i != 4 ? 1 : static_cast<uint32_t>(images.size());
        if (i != 4)
            w.pBufferInfo = &buffers[i];
        else w.pImageInfo = images.data();
        writes.push_back(w);
    }
    vkUpdateDescriptorSets(device, static_cast<uint32_t>(writes.size()), writes.data(), 0, nullptr);
}

void GpuScene::update(const scene::ScenePose& pose, const scene::ScenePose& previous, const CameraFrame& camera) {
    auto* out = static_cast<GpuInstance*>(mInstances.mapped());
    for (size_t i = 0; i < mScene.instances.size(); ++i) {
        const glm::mat4& world = i < pose.instanceWorld.size() ? pose.instanceWorld[i] : mScene.instances[i].world;
        const glm::mat4& prev = i < previous.instanceWorld.size() ? previous.instanceWorld[i] : world;
        out[i].world = world;
        out[i].prevWorld = prev;
        out[i].normalMatrix = glm::mat4(glm::transpose(glm::inverse(glm::mat3(world))));
        const uint32_t mesh = mScene.instances[i].mesh;
        out[i].flags = glm::vec4(mDeformation.meshDeforms(mesh) ? 1.0f : 0.0f, 0.0f, 0.0f, 0.0f);
    }
    GpuCamera c = camera.gpu();
    std::memcpy(mCamera.mapped(), &c, sizeof(c));
    if (!mDeformation.any() || !mVertices.mapped()) return;
    // Last frame's positions of what deforms: the same deformation with the previous pose (stateless, as prevWorld:
    // the first frame rendered, or one after a jump in time, gets its true motion).
    const scene::ScenePose& before = previous.nodeWorld.size() == mScene.nodes.size() ? previous : pose;
    mDeformation.pose(before, mPosed);
    auto* prev = static_cast<glm::vec4*>(mPrevPositions.mapped());
    for (const scene::Deformation::Range& r : mDeformation.ranges()) {
        for (uint32_t v = r.first; v < r.first + r.count; ++v)
            prev[v] = glm::vec4(mPosed[v].position, 1.0f);
    }
    // This frame's vertices, posed on the CPU and copied to the host-visible vertex buffer.
    mDeformation.pose(pose, mPosed);
    auto* vertices = static_cast<scene::Vertex*>(mVertices.mapped());
    for (const scene::Deformation::Range& r : mDeformation.ranges())
        std::memcpy(vertices + r.first, mPosed.data() + r.first, r.count * sizeof(scene::Vertex));
}

std::vector<VkVertexInputBindingDescription> GpuScene::vertexBindings() {
    return {{0, sizeof(scene::Vertex), VK_VERTEX_INPUT_RATE_VERTEX}};
}

std::vector<VkVertexInputAttributeDescription> GpuScene::vertexAttributes() {
    return {
        {0, 0, VK_FORMAT_R32G32B32_SFLOAT, offsetof(scene::Vertex, position)},
        {1, 0, VK_FORMAT_R32G32B32_SFLOAT, offsetof(scene::Vertex, normal)},
        {2, 0, VK_FORMAT_R32G32B32A32_SFLOAT, offsetof(scene::Vertex, tangent)},
        {3, 0, VK_FORMAT_R32G32_SFLOAT, offsetof(scene::Vertex, uv0)},
        {4, 0, VK_FORMAT_R32G32_SFLOAT, offsetof(scene::Vertex, uv1)},
        {5, 0, VK_FORMAT_R32G32B32A32_SFLOAT, offsetof(scene::Vertex, color)},
    };
}

void GpuScene::bindGeometry(VkCommandBuffer cmd) const {
    VkDeviceSize offset = 0;
    VkBuffer vb = mVertices.buffer();
    vkCmdBindVertexBuffers(cmd, 0, 1, &vb, &offset);
    vkCmdBindIndexBuffer(cmd, mIndices.buffer(), 0, VK_INDEX_TYPE_UINT32);
}

void GpuScene::drawIndexed(VkCommandBuffer cmd, const GpuDraw& draw) const {
    const scene::Primitive& p = mScene.primitives[draw.primitive];
    vkCmdDrawIndexed(cmd, p.indexCount, 1, p.firstIndex, static_cast<int32_t>(p.vertexOffset), 0);
}

} // namespace vitrine
