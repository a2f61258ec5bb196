// color.grade: a colour grade through OpenColorIO (exposure/contrast, ASC CDL, a LUT file) on the GPU, from the
// GLSL OCIO generates for it; the LUT's 3D textures are the node's own (set 1), uploaded on the first frame.
#include "core/base/error.hpp"
#include "core/base/paths.hpp"
#include "core/gpu/context.hpp"
#include "core/gpu/resources.hpp"
#include "core/gpu/vk_check.hpp"
#include "core/graph/node.hpp"
#include "core/graph/registry.hpp"
#include "core/image/color.hpp"
#include "core/image/grade.hpp"
#include "core/shader/compiler.hpp"

#include <array>
#include <cstring>
#include <fstream>
#include <regex>
#include <sstream>

namespace vitrine {
namespace {

NodeSchema schema() {
    NodeSchema s;
    s.type = "color.grade";
    s.doc = "Colour grade through OpenColorIO on the GPU: exposure/contrast (source space), ASC CDL and a LUT file "
            "(OCIO FileTransform, e.g. .cube) in the working space; OCIO's GLSL, equal to its CPU processor.";
    s.inputs = {{"color", PortKind::Texture, {}, false, Usage::Sampled, "Colour in the `source` colour space"}};
    OutputPort out;
    out.name = "color";
    out.formatFrom = "color";
    out.size = SizeRule::ofInput("color");
    out.doc = "Graded colour, in the `source` colour space";
    s.outputs = {out};
    s.params = {
        {"source", ParamType::String, "scene_linear", {}, {}, {},
         "OCIO colour space of the input and output (post.tonemap's output is linear Rec.709: scene_linear)"},
        {"working", ParamType::String, "sRGB - Texture", {}, {}, {},
         "OCIO colour space the CDL and the LUT apply in (display-encoded sRGB by default, as grading LUTs expect)"},
        {"exposure", ParamType::Float, 0.0, -10.0, 10.0, {}, "Exposure (stops) in the source space"},
        {"contrast", ParamType::Float, 1.0, 0.0, 4.0, {}, "Contrast around `pivot` in the source space (1: none)"},
        {"pivot", ParamType::Float, 0.18, 0.001, 10.0, {}, "Contrast pivot (source-space value that stays put)"},
        {"slope", ParamType::Vec3, {1.0, 1.0, 1.0}, 0.0, 10.0, {}, "ASC CDL slope per channel"},
        {"offset", ParamType::Vec3, {0.0, 0.0, 0.0}, -1.0, 1.0, {}, "ASC CDL offset per channel"},
        {"power", ParamType::Vec3, {1.0, 1.0, 1.0}, 0.01, 10.0, {}, "ASC CDL power per channel"},
        {"saturation", ParamType::Float, 1.0, 0.0, 4.0, {}, "ASC CDL saturation (Rec.709 luma weights)"},
        {"cdl_clamp", ParamType::Bool, true, {}, {}, {}, "Clamp the CDL to [0, 1] as ASC CDL v1.2 does"},
        {"lut", ParamType::Path, "", {}, {}, {},
         "LUT file OCIO can read (.cube, .3dl, .csp, ...): a bare file name is one of data/luts/ (warm_film.cube), a path "
         "is relative to the graph; empty: none"},
        {"lut_interpolation", ParamType::Enum, "tetrahedral", {}, {}, {"tetrahedral", "linear"}, "3D LUT interpolation"},
    };
    return s;
}

class GradeNode final : public Node {
public:
    void setup(SetupContext& ctx) override {
        const Params& p = ctx.params();
        GradeSettings g;
        g.source = p.getString("source");
        g.working = p.getString("working");
        g.exposure = p.getFloat("exposure");
        g.contrast = p.getFloat("contrast");
        g.pivot = p.getFloat("pivot");
        g.slope = p.getVec3("slope");
        g.offset = p.getVec3("offset");
        g.power = p.getVec3("power");
        g.saturation = p.getFloat("saturation");
        g.cdlClamp = p.getBool("cdl_clamp");
        // A bare file name is one of data/luts/ (so that variants in other folders can share it); a path is relative to
        // the graph file.
        const std::string lut = p.getString("lut");
        if (!lut.empty())
            g.lut = lut.find('/') == std::string::npos ? dataDir() / "luts" / lut
                                                       : ctx.resolvePath(lut);
        g.lutTetrahedral = p.getString("lut_interpolation") == "tetrahedral";
        GradeShader shader;
        try {
            shader = vitrine::Grade(ColorConfig::builtin(), g).shader("OCIOGrade");
        } catch (const UserError& e) {
            // core/image/grade.cpp starts its messages with the setting they are about.
            const std::string what = e.what();
            for (const char* param : {"source", "working", "lut"})
                if (what.rfind(std::string(param) + ": ", 0) == 0)
                    ctx.failParam(param, what.substr(std::string(param).size() + 2));
            ctx.failParam("lut", what);
        }
        // OCIO's GLSL 4.0 declares its LUT samplers without bindings; Vulkan wants them: set 1, binding i.
        for (size_t i = 0; i < shader.luts.size(); ++i) {
            const std::string decl = "uniform sampler3D " + shader.luts[i].samplerName + ";";
            const size_t at = shader.glsl.find(decl);
            if (at == std::string::npos)
                throw InternalError("color.grade: OCIO's shader does not declare " + decl);
            shader.glsl.replace(at, decl.size(), "layout(set = 1, binding = " + std::to_string(i) + ") " + decl);
        }
        mLuts = std::move(shader.luts);
        std::filesystem::path body = defaultShaderDir() / "color/grade.comp.in";
        std::ifstream in(body);
        if (!in) throw InternalError(body.string() + ": cannot read the color.grade shader body");
        std::stringstream ss;
        ss << in.rdbuf();
        mPipeline = ctx.computePipelineSource("color/grade.comp (OCIO grade)", "#version 460\n" + shader.glsl + "\n" + ss.str(),
                                              mLuts.empty() ? 0u : 1u);
    }

    void execute(ExecuteContext& ctx) override {
        const ImageDesc& out = ctx.output("color").desc();
        if (mLuts.empty()) {
            ctx.dispatch(mPipeline, nullptr, 0, out.width, out.height);
            return;
        }
        if (!mSet) upload(ctx.gpu());
        const std::array<VkDescriptorSetLayout, 1> layouts = {mLayout};
        const std::array<VkDescriptorSet, 1> sets = {mSet};
        ctx.dispatchWithSets(mPipeline, nullptr, 0, out.width, out.height, layouts, sets);
    }

    void releaseGpu() override {
        if (!mCtx) return;
        Context* c = mCtx;
        auto textures = std::move(mTextures);
        VkDescriptorPool pool = mPool;
        VkDescriptorSetLayout layout = mLayout;
        VkSampler sampler = mSampler;
        c->destroyLater([c, textures, pool, layout, sampler] {
            for (const Texture& t : textures) {
                vkDestroyImageView(c->device(), t.view, nullptr);
                vkDestroyImage(c->device(), t.image, nullptr);
                c->allocator().free(t.memory);
            }
            if (pool) vkDestroyDescriptorPool(c->device(), pool, nullptr);
            if (layout) vkDestroyDescriptorSetLayout(c->device(), layout, nullptr);
            if (sampler) vkDestroySampler(c->device(), sampler, nullptr);
        });
        mTextures.clear();
        mPool = VK_NULL_HANDLE;
        mLayout = VK_NULL_HANDLE;
        mSampler = VK_NULL_HANDLE;
        mSet = VK_NULL_HANDLE;
        mCtx = nullptr;
    }
    ~GradeNode() override { releaseGpu(); }

private:
    struct Texture {
        VkImage image = VK_NULL_HANDLE;
        VkImageView view = VK_NULL_HANDLE;
        Allocation memory;
    };

    // The LUTs as RGBA32F 3D textures (RGB32F is rarely sampleable), their sampler and descriptor set.
    void upload(Context& gpu) {
        mCtx = &gpu;
        VkDevice device = gpu.device();
        const VkFormat format = VK_FORMAT_R32G32B32A32_SFLOAT;
        VkFormatProperties props;
        vkGetPhysicalDeviceFormatProperties(gpu.physicalDevice(), format, &props);
        const bool filterable = (props.optimalTilingFeatures & VK_FORMAT_FEATURE_SAMPLED_IMAGE_FILTER_LINEAR_BIT) != 0;
        bool needLinear = false;
        for (const GradeLut3d& lut : mLuts) needLinear |= lut.linear;
        if (needLinear && !filterable)
            throw UserError("color.grade: this device cannot filter RGBA32F 3D textures; use lut_interpolation tetrahedral");

        VkSamplerCreateInfo si{VK_STRUCTURE_TYPE_SAMPLER_CREATE_INFO};
        si.magFilter = si.minFilter = needLinear ? VK_FILTER_LINEAR : VK_FILTER_NEAREST;
        si.mipmapMode = VK_SAMPLER_MIPMAP_MODE_NEAREST;
        si.addressModeU = si.addressModeV = si.addressModeW = VK_SAMPLER_ADDRESS_MODE_CLAMP_TO_EDGE;
        VK_CHECK(vkCreateSampler(device, &si, nullptr, &mSampler));

        size_t stagingBytes = 0;
        for (const GradeLut3d& lut : mLuts) stagingBytes += size_t(lut.edge) * lut.edge * lut.edge * 16;
        GpuBuffer staging(gpu, stagingBytes, VK_BUFFER_USAGE_TRANSFER_SRC_BIT, true, "color.grade.staging");
        auto* dst = static_cast<float*>(staging.mapped());
        for (const GradeLut3d& lut : mLuts) {
            const size_t n = size_t(lut.edge) * lut.edge * lut.edge;
            for (size_t i = 0; i < n; ++i) {
                dst[4 * i + 0] = lut.rgb[3 * i + 0];
                dst[4 * i + 1] = lut.rgb[3 * i + 1];
                dst[4 * i + 2] = lut.rgb[3 * i + 2];
                dst[4 * i + 3] = 1.0f;
            }
            dst += 4 * n;
        }
        for (size_t k = 0; k < mLuts.size(); ++k) {
            const unsigned e = mLuts[k].edge;
            VkImageCreateInfo ii{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
            ii.imageType = VK_IMAGE_TYPE_3D;
            ii.format = format;
            ii.extent = {e, e, e};
            ii.mipLevels = ii.arrayLayers = 1;
            ii.samples = VK_SAMPLE_COUNT_1_BIT;
            ii.tiling = VK_IMAGE_TILING_OPTIMAL;
            ii.usage = VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT;
            ii.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
            Texture t;
            VK_CHECK(vkCreateImage(device, &ii, nullptr, &t.image));
            VkMemoryRequirements req;
            vkGetImageMemoryRequirements(device, t.image, &req);
            t.memory = gpu.allocator().allocate(req, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT, false);
            VK_CHECK(vkBindImageMemory(device, t.image, t.memory.memory, t.memory.offset));
            gpu.setName(reinterpret_cast<uint64_t>(t.image), VK_OBJECT_TYPE_IMAGE, "color.grade.lut" + std::to_string(k));
            VkImageViewCreateInfo vi{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
            vi.image = t.image;
            vi.viewType = VK_IMAGE_VIEW_TYPE_3D;
            vi.format = format;
            vi.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
            VK_CHECK(vkCreateImageView(device, &vi, nullptr, &t.view));
            mTextures.push_back(t);
        }
        gpu.immediate([&](VkCommandBuffer cmd) {
            VkDeviceSize offset = 0;
            for (size_t k = 0; k < mLuts.size(); ++k) {
                const unsigned e = mLuts[k].edge;
                VkImageMemoryBarrier2 b{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER_2};
                b.srcStageMask = VK_PIPELINE_STAGE_2_NONE;
                b.dstStageMask = VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT;
                b.dstAccessMask = VK_ACCESS_2_TRANSFER_WRITE_BIT;
                b.oldLayout = VK_IMAGE_LAYOUT_UNDEFINED;
                b.newLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
                b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
                b.image = mTextures[k].image;
                b.subresourceRange = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 1, 0, 1};
                VkDependencyInfo dep{VK_STRUCTURE_TYPE_DEPENDENCY_INFO};
                dep.imageMemoryBarrierCount = 1;
                dep.pImageMemoryBarriers = &b;
                vkCmdPipelineBarrier2(cmd, &dep);
                VkBufferImageCopy copy{};
                copy.bufferOffset = offset;
                copy.imageSubresource = {VK_IMAGE_ASPECT_COLOR_BIT, 0, 0, 1};
                copy.imageExtent = {e, e, e};
                vkCmdCopyBufferToImage(cmd, staging.buffer(), mTextures[k].image, VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL, 1,
                                       &copy);
                offset += VkDeviceSize(e) * e * e * 16;
                b.srcStageMask = VK_PIPELINE_STAGE_2_ALL_TRANSFER_BIT;
                b.srcAccessMask = VK_ACCESS_2_TRANSFER_WRITE_BIT;
                b.dstStageMask = VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT;
                b.dstAccessMask = VK_ACCESS_2_SHADER_SAMPLED_READ_BIT;
                b.oldLayout = VK_IMAGE_LAYOUT_TRANSFER_DST_OPTIMAL;
                b.newLayout = VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL;
                vkCmdPipelineBarrier2(cmd, &dep);
            }
        });

        std::vector<VkDescriptorSetLayoutBinding> bindings;
        for (uint32_t k = 0; k < mLuts.size(); ++k)
            bindings.push_back({k, VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, 1, VK_SHADER_STAGE_COMPUTE_BIT, nullptr});
        VkDescriptorSetLayoutCreateInfo li{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
        li.bindingCount = static_cast<uint32_t>(bindings.size());
        li.pBindings = bindings.data();
        VK_CHECK(vkCreateDescriptorSetLayout(device, &li, nullptr, &mLayout));
        VkDescriptorPoolSize size{VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER, static_cast<uint32_t>(mLuts.size())};
        VkDescriptorPoolCreateInfo pi{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
        pi.maxSets = 1;
        pi.poolSizeCount = 1;
        pi.pPoolSizes = &size;
        VK_CHECK(vkCreateDescriptorPool(device, &pi, nullptr, &mPool));
        VkDescriptorSetAllocateInfo ai{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
        ai.descriptorPool = mPool;
        ai.descriptorSetCount = 1;
        ai.pSetLayouts = &mLayout;
        VK_CHECK(vkAllocateDescriptorSets(device, &ai, &mSet));
        std::vector<VkDescriptorImageInfo> images;
        for (const Texture& t : mTextures) images.push_back({mSampler, t.view, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL});
        std::vector<VkWriteDescriptorSet> writes;
        for (uint32_t k = 0; k < images.size(); ++k) {
            VkWriteDescriptorSet w{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
            w.dstSet = mSet;
            w.dstBinding = k;
            w.descriptorCount = 1;
            w.descriptorType = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER;
            w.pImageInfo = &images[k];
            writes.push_back(w);
        }
        vkUpdateDescriptorSets(device, static_cast<uint32_t>(writes.size()), writes.data(), 0, nullptr);
    }

    std::vector<GradeLut3d> mLuts;
    PipelineId mPipeline = 0;
    Context* mCtx = nullptr;
    std::vector<Texture> mTextures;
    VkSampler mSampler = VK_NULL_HANDLE;
    VkDescriptorSetLayout mLayout = VK_NULL_HANDLE;
    VkDescriptorPool mPool = VK_NULL_HANDLE;
    VkDescriptorSet mSet = VK_NULL_HANDLE;
};

const NodeRegistration kRegistration(schema(), [] { return std::make_unique<GradeNode>(); });

} // namespace
} // namespace vitrine
