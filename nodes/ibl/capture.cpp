// ibl.capture: every reflection probe's six faces rendered by the frame's own G-buffer and lighting nodes (an
// inner graph run per face, nodes/ibl/capture_graph.hpp), prefiltered with GGX per mip (shaders/ibl/prefilter.comp)
// into one cube-map array, plus the split-sum BRDF LUT (shaders/ibl/brdf_lut.comp). Cached in the bake cache.
#include "nodes/bake/baked_lighting.hpp"
#include "nodes/ibl/capture_graph.hpp"
#include "nodes/ibl/cube_mips.hpp"

#include "core/bake/cache.hpp"
#include "core/base/error.hpp"
#include "core/base/log.hpp"
#include "core/gpu/context.hpp"
#include "core/gpu/descriptors.hpp"
#include "core/gpu/transfer.hpp"
#include "core/graph/executor.hpp"
#include "core/scene/hash.hpp"
#include "core/shader/compiler.hpp"
#include "shaders/ibl/capture.h"

#include <glm/gtc/packing.hpp>

#include <algorithm>
#include <array>
#include <bit>
#include <chrono>
#include <cstring>

namespace vitrine {
namespace {

using Clock = std::chrono::steady_clock;
constexpr uint32_t kCacheVersion = 1;

NodeSchema schema() {
    NodeSchema s;
    s.type = "ibl.capture";
    s.doc = "Localized reflection probes (MUSEUM_SPEC §4): each of the scene's probes sees the lit scene through six "
            "90-degree faces rendered by gbuffer.layered, shadow.directional and lighting.deferred (an inner graph run "
            "per face: sun, shadows, sky, lightmaps and irradiance volume as in the frame), then every mip is the "
            "radiance convolved with the GGX lobe of roughness mip / (mips - 1) by filtered importance sampling "
            "[Karis13]. Also the split-sum BRDF LUT. Captured on the first frame (with a progress bar) and cached on "
            "disk by scene, probes, sky, baked lighting and params.";
    auto tex = [](const char* name, const char* doc, bool optional = false) {
        return InputPort{name, PortKind::Texture, {}, optional, Usage::Sampled, doc, true};
    };
    s.inputs = {
        {"scene", PortKind::Scene, {}, false, Usage::Sampled, "The scene; its `probes` are captured in order"},
        tex("sky", "A sky node's cube map (as lighting.deferred's `sky`)"),
        tex("sky_sh", "A sky node's `sh` (SH9 radiance, the sun)"),
        tex("lightmap", "bake.lightmap's lightmap (with volume and baked)", true),
        tex("volume", "bake.lightmap's irradiance volume (with lightmap and baked)", true),
        {"baked", PortKind::Buffer, {}, true, Usage::Sampled, "bake.lightmap's layout (with lightmap and volume)"},
    };
    OutputPort cubes;
    cubes.name = "cubes";
    cubes.format = VK_FORMAT_R16G16B16A16_SFLOAT;
    cubes.size = SizeRule::absolute(32, 32);
    cubes.persistent = true;
    cubes.readBack = true;
    cubes.doc = "Prefiltered radiance (cd/m²), a cube-map array: probe i is layers [6i, 6i + 6) (+X, -X, +Y, -Y, +Z, "
                "-Z); mip m is GGX roughness m / (mips - 1) (shaders/ibl/ibl_common.glsl)";
    OutputPort lut;
    lut.name = "brdf_lut";
    lut.format = VK_FORMAT_R32G32_SFLOAT;
    lut.size = SizeRule::absolute(64, 64);
    lut.persistent = true;
    lut.doc = "Split-sum BRDF LUT: texel (NoV, roughness) = (A, B), specular albedo f0 A + B (ibl_common.glsl)";
    s.outputs = {cubes, lut};
    s.params = {
        {"size", ParamType::Int, 32, 4.0, 2048.0, {}, "Face size in texels of mip 0 (the demo: 256)"},
        {"mips", ParamType::Int, 0, 0.0, 12.0, {}, "Mip levels (roughness steps); 0: down to 1x1"},
        {"samples", ParamType::Int, 512, 1.0, 4096.0, {}, "GGX samples per prefiltered texel"},
        {"lut_size", ParamType::Int, 64, 8.0, 1024.0, {}, "BRDF LUT size (lut_size x lut_size)"},
        {"lut_samples", ParamType::Int, 16384, 16.0, 16384.0, {}, "GGX samples per LUT texel"},
        {"znear", ParamType::Float, 0.05, 1e-4, 100.0, {}, "Near plane of the face cameras (m)"},
        {"sky_ambient", ParamType::Float, 0.15, 0.0, 1.0, {}, "lighting.deferred's sky_ambient in the capture"},
        {"sun_scale", ParamType::Float, 1.0, 0.0, 100.0, {}, "lighting.deferred's sun_scale in the capture"},
        {"emissive_scale", ParamType::Float, 1.0, 0.0, 1e6, {}, "lighting.deferred's emissive_scale in the capture"},
        {"shadows", ParamType::Bool, true, {}, {}, {}, "Sun shadows in the capture (shadow.directional per face)"},
        {"shadow_resolution", ParamType::Int, 512, 64.0, 8192.0, {}, "shadow.directional's resolution per face"},
        {"shadow_cascades", ParamType::Int, 2, 1.0, 4.0, {}, "shadow.directional's cascades per face"},
        {"shadow_distance", ParamType::Float, 30.0, 1.0, 10000.0, {}, "shadow.directional's distance per face (m)"},
        {"cache", ParamType::Bool, true, {}, {}, {}, "Load and store the capture in the bake cache"},
        {"recapture", ParamType::Bool, false, {}, {}, {}, "Capture even when the bake cache holds this capture (and replace it)"},
    };
    return s;
}

// Host copy of the whole cube-map array: mip m's layers in order, RGBA half floats (the output's format).
struct CubeArrayData {
    uint32_t size = 0, mips = 0, layers = 0;
    std::vector<uint16_t> texels;
    size_t mipOffset(uint32_t m) const {
        size_t o = 0;
        for (uint32_t i = 0; i < m; ++i) o += size_t(4) * layers * (size >> i) * (size >> i);
        return o;
    }
};

std::vector<uint8_t> serialize(const CubeArrayData& d) {
    std::vector<uint8_t> out(16 + d.texels.size() * 2);
    const uint32_t header[4] = {kCacheVersion, d.size, d.mips, d.layers};
    std::memcpy(out.data(), header, 16);
    std::memcpy(out.data() + 16, d.texels.data(), d.texels.size() * 2);
    return out;
}

std::optional<CubeArrayData> deserialize(const std::vector<uint8_t>& bytes, uint32_t size, uint32_t mips, uint32_t layers) {
    if (bytes.size() < 16) return std::nullopt;
    uint32_t header[4];
    std::memcpy(header, bytes.data(), 16);
    if (header[0] != kCacheVersion || header[1] != size || header[2] != mips || header[3] != layers) return std::nullopt;
    CubeArrayData d{size, mips, layers, {}};
    d.texels.resize(d.mipOffset(mips));
    if (bytes.size() != 16 + d.texels.size() * 2) return std::nullopt;
    std::memcpy(d.texels.data(), bytes.data() + 16, d.texels.size() * 2);
    return d;
}

class Capture final : public Node {
public:
    void setup(SetupContext& ctx) override {
        const Params& p = ctx.params();
        mScene = ctx.objectAs<SceneObject>("scene");
        const scene::Scene& scene = mScene->scene();
        // A scene without probes (a glTF file viewed through the museum pipeline with --scene) gets one black cube:
        // ibl.localized then shades nothing and every pixel takes its sky fallback.
        mEmpty = scene.probes.empty();
        if (mEmpty)
            logWarning("ibl.capture: scene '" + scene.name +
                       "' has no reflection probes (Scene::probes); its indirect specular falls back to the sky");
        const bool lm = ctx.hasInput("lightmap"), vol = ctx.hasInput("volume"), baked = ctx.hasInput("baked");
        if (lm != vol || vol != baked)
            ctx.failParam("shadows", "connect lightmap, volume and baked (bake.lightmap's three outputs) together, or none");
        if (baked) mBaked = ctx.objectAs<BakedLightingObject>("baked");
        mSize = static_cast<uint32_t>(p.getInt("size"));
        const uint32_t fullChain = std::bit_width(mSize);
        mMips = p.getInt("mips") ? static_cast<uint32_t>(p.getInt("mips")) : fullChain;
        if (mMips > fullChain)
            ctx.failParam("mips", "at most " + std::to_string(fullChain) + " mips for faces of " + std::to_string(mSize) +
                                      " texels, got " + std::to_string(mMips));
        mLayers = static_cast<uint32_t>(6 * std::max<size_t>(scene.probes.size(), 1));
        ImageDesc& cubes = ctx.output("cubes");
        cubes.width = cubes.height = mSize;
        cubes.mipLevels = mMips;
        cubes.layers = mLayers;
        cubes.cube = true;
        cubes.cubeArray = true;
        mLutSize = static_cast<uint32_t>(p.getInt("lut_size"));
        ImageDesc& lut = ctx.output("brdf_lut");
        lut.width = lut.height = mLutSize;

        mLighting.size = mSize;
        mLighting.znear = p.getFloat("znear");
        mLighting.skyAmbient = p.getFloat("sky_ambient");
        mLighting.sunScale = p.getFloat("sun_scale");
        mLighting.emissiveScale = p.getFloat("emissive_scale");
        mLighting.shadows = p.getBool("shadows");
        mLighting.shadowResolution = static_cast<uint32_t>(p.getInt("shadow_resolution"));
        mLighting.shadowCascades = static_cast<uint32_t>(p.getInt("shadow_cascades"));
        mLighting.shadowDistance = p.getFloat("shadow_distance");
        mSamples = static_cast<uint32_t>(p.getInt("samples"));
        mLutSamples = static_cast<uint32_t>(p.getInt("lut_samples"));
        mUseCache = p.getBool("cache");
        mRecapture = p.getBool("recapture");

        mLutPipeline = ctx.computePipeline("ibl/brdf_lut.comp");
        mPrefilterPipeline = ctx.computePipeline("ibl/prefilter.comp", {}, 1);
        mCopyPipeline = ctx.computePipeline("ibl/copy_mip.comp", {}, 1);
    }

    void execute(ExecuteContext& ctx) override {
        if (mDone) return; // persistent outputs: one capture serves every frame
        gpu_types::IblBrdfLutPush lut{mLutSize, mLutSamples, 0, 0};
        ctx.dispatch(mLutPipeline, &lut, sizeof(lut), mLutSize, mLutSize);

        if (mEmpty) {
            CubeArrayData black{mSize, mMips, mLayers, {}};
            black.texels.assign(black.mipOffset(mMips), 0);
            writeCached(ctx, black);
            mDone = true;
            return;
        }
        // Run what was recorded so far (sky, bake), so the inputs can be read back and hashed.
        ctx.splitSubmission();
        auto inputs = std::make_shared<CaptureInputs>();
        inputs->scene = mScene->shared();
        inputs->anisotropy = mScene->anisotropy;
        inputs->time = mScene->time;
        const GpuImage& sky = ctx.input("sky");
        if (sky.desc().layers != 6) throw UserError("ibl.capture: input 'sky' must be a cube map (6 layers)");
        for (uint32_t f = 0; f < 6; ++f) inputs->sky.push_back(readImage(ctx.gpu(), sky, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, 0, f));
        inputs->skySh = readImage(ctx.gpu(), ctx.input("sky_sh"), VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
        if (mBaked) {
            inputs->lightmap = readImage(ctx.gpu(), ctx.input("lightmap"), VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
            inputs->volume = readImage(ctx.gpu(), ctx.input("volume"), VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
            inputs->baked = mBaked;
        }
        const BakeKey key = cacheKey(ctx.params(), *inputs, ctx.shaders().treeHash());
        const BakeCache cache(defaultCacheDir());
        const scene::Scene& scene = mScene->scene();

        std::optional<CubeArrayData> data;
        if (mUseCache && !mRecapture)
            if (auto bytes = cache.get(key)) data = deserialize(*bytes, mSize, mMips, mLayers);
        if (data) {
            logInfo("scene '" + scene.name + "': " + std::to_string(scene.probes.size()) +
                    " reflection probes loaded from the bake cache");
            mFromCache = true;
            writeCached(ctx, *data);
        } else {
            const auto start = Clock::now();
            std::vector<Image> faces = captureFaces(ctx, inputs);
            prefilter(ctx, std::move(faces));
            mFromCache = false;
            if (mUseCache) {
                ctx.splitSubmission();
                CubeArrayData out = readCubes(ctx);
                if (!cache.put(key, serialize(out)))
                    logWarning("scene '" + scene.name + "': could not write the probes to the bake cache under " +
                               cache.dir().string());
            }
            mCaptureMs = std::chrono::duration<double, std::milli>(Clock::now() - start).count();
            logInfo("scene '" + scene.name + "': " + std::to_string(scene.probes.size()) + " reflection probes (" +
                    std::to_string(mSize) + "² faces, " + std::to_string(mMips) + " mips) captured and prefiltered in " +
                    std::to_string(static_cast<int>(mCaptureMs)) + " ms");
        }
        mDone = true;
    }

    void releaseGpu() override {
        mDone = false;
        mSets = DescriptorSets();
        mSource = GpuImage();
    }

private:
    // shaderTree: ShaderCompiler::treeHash(). The capture renders through gbuffer.layered, lighting.deferred and the
    // scene's shaders (the Toksvig mips among them), so an edit to any shader is another capture.
    BakeKey cacheKey(const Params& p, const CaptureInputs& in, uint64_t shaderTree) const {
        scene::Hasher h;
        h.string("probes");
        h.value(kCacheVersion);
        h.value(shaderTree);
        h.value(in.scene->contentHash());
        h.value(in.time);
        for (const Image& f : in.sky) h.array(f.pixels);
        h.array(in.skySh.pixels);
        if (in.lightmap) h.array(in.lightmap->pixels);
        if (in.volume) h.array(in.volume->pixels);
        if (in.baked) {
            h.array(in.baked->lightmapScaleOffset);
            h.value(in.baked->volumeOrigin);
            h.value(in.baked->volumeSpacing);
            h.value(in.baked->volumeCounts);
        }
        h.value(mSize);
        h.value(mMips);
        h.value(mSamples);
        h.value(mLighting.znear);
        h.value(mLighting.skyAmbient);
        h.value(mLighting.sunScale);
        h.value(mLighting.emissiveScale);
        h.value(mLighting.shadows);
        h.value(mLighting.shadowResolution);
        h.value(mLighting.shadowCascades);
        h.value(mLighting.shadowDistance);
        h.value(in.anisotropy);
        (void)p;
        return {"probes", h.result()};
    }

    // Runs the inner graph for 6 x probes frames; returns face f of probe i as image 6 i + f (texel order of the cube).
    std::vector<Image> captureFaces(ExecuteContext& ctx, std::shared_ptr<CaptureInputs> inputs) {
        std::unique_ptr<CaptureGraph> graph = buildCaptureGraph(inputs, mLighting);
        std::vector<Image> faces(mLayers);
        Progress progress("capturing " + std::to_string(mLayers / 6) + " reflection probes (" + std::to_string(mSize) +
                              "² faces)",
                          mLayers);
        {
            Executor inner(ctx.gpu(), graph->graph, ctx.shaders());
            RunOptions options;
            options.progress = false;
            options.onOutput = [&](uint32_t frame, const std::string&, const Image& image) {
                Image& face = faces.at(frame);
                face = Image(image.width, image.height);
                // The face camera is right-handed, so its image is the face mirrored left to right.
                for (int y = 0; y < image.height; ++y)
                    for (int x = 0; x < image.width; ++x)
                        std::memcpy(face.at(x, y), image.at(image.width - 1 - x, y), 4 * sizeof(float));
                progress.advance();
            };
            inner.run(options);
        }
        progress.finish();
        return faces;
    }

    void prefilter(ExecuteContext& ctx, std::vector<Image> faces) {
        const uint32_t sourceMips = std::bit_width(mSize);
        ImageDesc d;
        d.width = d.height = mSize;
        d.mipLevels = sourceMips;
        d.layers = mLayers;
        d.cube = true;
        d.cubeArray = true;
        d.format = VK_FORMAT_R32G32B32A32_SFLOAT;
        d.usage = VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT;
        mSource = GpuImage(ctx.gpu(), d, "ibl.capture.source");
        uploadCubeMips(ctx.gpu(), mSource, boxMips(std::move(faces), sourceMips));
        resetPrefilterSets(ctx.gpu(), mSets, "ibl.capture.prefilter");
        const std::array<VkDescriptorSetLayout, 1> layouts = {mSets.layout()};
        for (uint32_t m = 0; m < mMips; ++m) {
            // One set per output mip: the source's cube-array view (a cached capture: mip m's array view), mip m of
            // cubes.
            const VkDescriptorSet set =
                prefilterMipSet(ctx.gpu(), mSets, mSource.view(), ctx.output("cubes").mipView(m));
            gpu_types::IblPrefilterPush push{};
            push.size = mSize >> m;
            push.layers = mLayers;
            push.samples = mSamples;
            push.sourceSize = mSize;
            push.roughness = mMips > 1 ? float(m) / float(mMips - 1) : 0.0f;
            push.sourceMips = float(sourceMips);
            ctx.dispatchWithSets(mPrefilterPipeline, &push, sizeof(push), push.size, push.size * mLayers, layouts,
                                 std::array<VkDescriptorSet, 1>{set});
        }
    }

    void writeCached(ExecuteContext& ctx, const CubeArrayData& data) {
        std::vector<std::vector<Image>> mips(mMips);
        for (uint32_t m = 0; m < mMips; ++m) {
            const uint32_t s = mSize >> m;
            const uint16_t* src = data.texels.data() + data.mipOffset(m);
            for (uint32_t layer = 0; layer < mLayers; ++layer) {
                Image face(static_cast<int>(s), static_cast<int>(s));
                for (size_t i = 0; i < face.pixels.size(); ++i) face.pixels[i] = glm::unpackHalf1x16(*src++);
                mips[m].push_back(std::move(face));
            }
        }
        ImageDesc d;
        d.width = d.height = mSize;
        d.mipLevels = mMips;
        d.layers = mLayers;
        d.cube = true;
        d.cubeArray = true;
        d.format = VK_FORMAT_R32G32B32A32_SFLOAT;
        d.usage = VK_IMAGE_USAGE_SAMPLED_BIT | VK_IMAGE_USAGE_TRANSFER_DST_BIT;
        mSource = GpuImage(ctx.gpu(), d, "ibl.capture.cached");
        uploadCubeMips(ctx.gpu(), mSource, mips);
        resetPrefilterSets(ctx.gpu(), mSets, "ibl.capture.prefilter");
        const std::array<VkDescriptorSetLayout, 1> layouts = {mSets.layout()};
        for (uint32_t m = 0; m < mMips; ++m) {
            const VkDescriptorSet set =
                prefilterMipSet(ctx.gpu(), mSets, mSource.mipView(m), ctx.output("cubes").mipView(m));
            gpu_types::IblPrefilterPush push{};
            push.size = mSize >> m;
            push.layers = mLayers;
            ctx.dispatchWithSets(mCopyPipeline, &push, sizeof(push), push.size, push.size * mLayers, layouts,
                                 std::array<VkDescriptorSet, 1>{set});
        }
    }

    CubeArrayData readCubes(ExecuteContext& ctx) {
        CubeArrayData d{mSize, mMips, mLayers, {}};
        d.texels.reserve(d.mipOffset(mMips));
        const GpuImage& cubes = ctx.output("cubes");
        for (uint32_t m = 0; m < mMips; ++m)
            for (uint32_t layer = 0; layer < mLayers; ++layer) {
                const Image face = readImage(ctx.gpu(), cubes, VK_IMAGE_LAYOUT_GENERAL, m, layer);
                for (float v : face.pixels) d.texels.push_back(glm::packHalf1x16(v));
            }
        return d;
    }

    std::shared_ptr<SceneObject> mScene;
    std::shared_ptr<BakedLightingObject> mBaked;
    CaptureLighting mLighting;
    bool mEmpty = false; // no probes: one black cube
    uint32_t mSize = 32, mMips = 6, mLayers = 6, mLutSize = 64, mSamples = 64, mLutSamples = 1024;
    bool mUseCache = true, mRecapture = false, mDone = false, mFromCache = false;
    double mCaptureMs = 0.0;
    PipelineId mLutPipeline = 0, mPrefilterPipeline = 0, mCopyPipeline = 0;
    DescriptorSets mSets;
    GpuImage mSource;
};

const NodeRegistration kRegistration(schema(), [] { return std::make_unique<Capture>(); });

} // namespace
} // namespace vitrine
