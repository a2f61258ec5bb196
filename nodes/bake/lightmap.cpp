// bake.lightmap: GPU-baked lightmaps and an irradiance volume (MUSEUM_SPEC §3), cached on disk. The CPU half
// (jobs, SH projection, cache format) is core/bake/lightmap_bake.hpp; the integrator shaders/bake/lightmap.comp.
#include "nodes/bake/baked_lighting.hpp"

#include "core/accel/gpu_bvh.hpp"
#include "core/bake/cache.hpp"
#include "core/bake/lightmap_bake.hpp"
#include "core/bake/lightmap_raster.hpp"
#include "core/base/error.hpp"
#include "core/base/log.hpp"
#include "core/gpu/buffer_set.hpp"
#include "core/gpu/context.hpp"
#include "core/gpu/transfer.hpp"
#include "core/graph/registry.hpp"
#include "core/scene/gpu_scene.hpp"
#include "core/scene/hash.hpp"
#include "core/shader/compiler.hpp"
#include "nodes/render/converge.hpp"
#include "nodes/render/pathtrace_cpu.hpp"
#include "shaders/bake/lightmap.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <numbers>
#include <optional>
#include <string>

namespace vitrine {
namespace {

using Clock = std::chrono::steady_clock;
using gpu_types::LightmapBakePush;

constexpr uint32_t kJobsPerRow = 4096;
constexpr uint32_t kCpuBakeVersion = 2; // of traceOnCpu's integrator, in the cache key

NodeSchema schema() {
    NodeSchema s;
    s.type = "bake.lightmap";
    s.doc = "Baked global illumination (MUSEUM_SPEC §3) by the path tracer of render.pathtrace: per-texel irradiance "
            "(lux) of every static instance with lightmap UVs (TEXCOORD_1) in one E5B9G9R9 atlas, and an irradiance "
            "volume (SH9 probes on a grid) for everything else. Sky, emitters and every bounce of sun, sky and "
            "emitters, surfaces reflecting diffusely with their albedo; the sun's direct light is left to the frame's "
            "shadowed sun. Noise removed by an edge-aware filter, charts dilated into their gutters. Baked on the "
            "first frame, with a progress bar, and cached on disk by scene, lighting and parameters.";
    // Read back once, to hash the lighting into the bake cache's key.
    auto tex = [](const char* name, const char* doc) {
        return InputPort{name, PortKind::Texture, {}, false, Usage::Sampled, doc, true};
    };
    s.inputs = {
        {"scene", PortKind::Scene, {}, false, Usage::Sampled, "The scene to bake (static instances get lightmaps)"},
        tex("sky", "A sky node's cube map (the environment's radiance, without the sun disk: sun_in_cubemap false)"),
        tex("sky_sh", "A sky node's `sh`: sun illuminance (texel 9, lux) and direction (texel 10)"),
    };
    OutputPort lightmap;
    lightmap.name = "lightmap";
    lightmap.format = VK_FORMAT_E5B9G9R9_UFLOAT_PACK32;
    lightmap.usage = Usage::TransferDst;
    lightmap.persistent = true;
    lightmap.doc = "Irradiance atlas (lux, rgb) of every lightmapped instance; `layout` says where each one is";
    OutputPort volume = lightmap;
    volume.name = "volume";
    volume.format = VK_FORMAT_R32G32B32A32_SFLOAT;
    volume.doc = "Irradiance volume: probe (x, y, z)'s SH9 radiance coefficient k at texel (9x + k, y + ny z); "
                 "a: 1 for a valid probe, 0 for one inside geometry";
    OutputPort layout;
    layout.name = "layout";
    layout.kind = PortKind::Buffer;
    layout.doc = "Where each instance's lightmap lies in the atlas and the volume's grid (for gbuffer.layered and "
                 "lighting.deferred)";
    s.outputs = {lightmap, volume, layout};
    s.params = {
        {"texels_per_meter",
         ParamType::Float,
         4.0,
         0.25,
         64.0,
         {},
         "Lightmap texel density (the demo's look: 8 to 16)"},
        {"samples", ParamType::Int, 32, 2.0, 65536.0, {}, "Paths per texel and per probe ray"},
        {"max_bounces",
         ParamType::Int,
         8,
         1.0,
         16.0,
         {},
         "Surfaces that reflect light along a path (8, as museum_reference traces)"},
        {"probe_spacing", ParamType::Float, 3.0, 0.1, 100.0, {}, "Metres between irradiance-volume probes"},
        {"probe_rays", ParamType::Int, 32, 16.0, 4096.0, {}, "Directions per probe"},
        {"filter_iterations", ParamType::Int, 4, 0.0, 8.0, {}, "Edge-aware à-trous filter steps (0: unfiltered)"},
        {"sun_scale", ParamType::Float, 1.0, 0.0, 100.0, {}, "Multiplier of the sky model's sun illuminance"},
        {"sky_scale", ParamType::Float, 1.0, 0.0, 100.0, {}, "Multiplier of the sky cube map's radiance"},
        {"emissive_scale", ParamType::Float, 1.0, 0.0, 1e6, {}, "Multiplier of emissive surfaces"},
        {"seed",
         ParamType::Int,
         0,
         0.0,
         65535.0,
         {},
         "Random sequence of the paths: another seed bakes independently at the same quality (the spread between seeds "
         "is the bake's noise)"},
        {"caustic_footprint",
         ParamType::Float,
         2.0,
         0.0,
         64.0,
         {},
         "Texels over which a glossy surface's reflection of the sun is spread (path-space regularisation: the "
         "sun's caustic off the polished floor, found by one path in tens of thousands with 40x a texel's light, "
         "keeps its energy but is blurred to this size; 0: exact and spiky, see the README)"},
        {"multiscatter",
         ParamType::Bool,
         false,
         {},
         {},
         {},
         "The paths reflect off the GGX lobe with its multiple-scattering compensation (as render.pathtrace's "
         "multiscatter; common/brdf.glsl ggxMultiscatter), on both integrators"},
        {"backend",
         ParamType::Enum,
         "auto",
         {},
         {},
         {"gpu", "cpu", "auto"},
         "Where the paths are traced: gpu (shaders/bake/lightmap.comp), cpu (render.pathtrace's CPU tracer through "
         "Embree on every core: the same materials and BRDF, about 10x the paths per second of lavapipe), auto: cpu "
         "when the Vulkan device is a CPU (lavapipe), else gpu"},
        {"cache", ParamType::Bool, true, {}, {}, {}, "Load and store the bake in the bake cache (off: bake every run)"},
    };
    return s;
}

void hashImage(const Image& image, scene::Hasher& h) { h.array(image.pixels); }

class LightmapBake final : public Node {
public:
    void setup(SetupContext& ctx) override {
        mScene = ctx.objectAs<SceneObject>("scene");
        const Params& p = ctx.params();
        mSettings.atlas.texelsPerMeter = p.getFloat("texels_per_meter");
        mSettings.samples = static_cast<uint32_t>(p.getInt("samples"));
        mSettings.maxBounces = static_cast<uint32_t>(p.getInt("max_bounces"));
        mSettings.probeSpacing = p.getFloat("probe_spacing");
        mSettings.probeRays = static_cast<uint32_t>(p.getInt("probe_rays"));
        mSettings.filter.iterations = p.getInt("filter_iterations");
        mSettings.filter.texelSize = 1.0f / mSettings.atlas.texelsPerMeter;
        mSettings.sunScale = p.getFloat("sun_scale");
        mSettings.skyScale = p.getFloat("sky_scale");
        mSettings.emissiveScale = p.getFloat("emissive_scale");
        mSettings.seed = static_cast<uint32_t>(p.getInt("seed"));
        mSettings.causticFootprint = p.getFloat("caustic_footprint");
        mSettings.multiscatter = p.getBool("multiscatter");
        mUseCache = p.getBool("cache");
        mBackend = p.getString("backend");

        const scene::Scene& scene = mScene->scene();
        try {
            mAtlas = bake::planLightmapAtlas(scene, mSettings.atlas);
        } catch (const UserError& e) {
            ctx.failParam("texels_per_meter", e.what());
        }
        mVolume = bake::planIrradianceVolume(scene, mSettings.probeSpacing, mSettings.maxProbes);

        auto layout = std::make_shared<BakedLightingObject>();
        layout->lightmapScaleOffset.assign(scene.instances.size(), glm::vec4(0.0f));
        for (const bake::LightmapRegion& r : mAtlas.regions) layout->lightmapScaleOffset[r.instance] = r.scaleOffset;
        layout->volumeOrigin = mVolume.origin;
        layout->volumeSpacing = mVolume.spacing;
        layout->volumeCounts = mVolume.counts;
        ctx.setObject("layout", layout);

        ImageDesc& lm = ctx.output("lightmap");
        lm.width = std::max(1u, mAtlas.width);
        lm.height = std::max(1u, mAtlas.height);
        ImageDesc& vol = ctx.output("volume");
        vol.width = std::max(1u, 9 * mVolume.counts.x);
        vol.height = std::max(1u, mVolume.counts.y * mVolume.counts.z);

        const size_t textures = std::max<size_t>(1, scene.textures.size());
        ShaderDefines defines = {{"VITRINE_SCENE_TEXTURES", std::to_string(textures)}};
        if (mSettings.multiscatter) defines.push_back({"VITRINE_MULTISCATTER", "1"});
        mPipeline = ctx.computePipeline("bake/lightmap.comp", defines, 4);
    }

    void execute(ExecuteContext& ctx) override {
        if (mUploaded) return; // persistent outputs: the bake serves every frame
        GpuScene& gpu = mScene->gpu(ctx.gpu(), ctx.shaders());
        const scene::Scene& scene = mScene->scene();

        // Run what was recorded so far (the sky), so the lighting the bake depends on can be hashed.
        ctx.splitSubmission();
        scene::Hasher lighting;
        const GpuImage& sky = ctx.input("sky");
        std::vector<Image> faces;
        for (uint32_t face = 0; face < sky.desc().layers; ++face) {
            faces.push_back(readImage(ctx.gpu(), sky, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, 0, face));
            hashImage(faces.back(), lighting);
        }
        const Image sh = readImage(ctx.gpu(), ctx.input("sky_sh"), VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
        hashImage(sh, lighting);
        const CpuSky cpuSky = cpuSkyFrom(std::move(faces), sh);
        const bool cpu =
            mBackend == "cpu" || (mBackend == "auto" && ctx.gpu().deviceInfo().type == VK_PHYSICAL_DEVICE_TYPE_CPU);
        // The tracer changes the bits (another estimator of the same light): a CPU bake is stored apart from a GPU
        // one. kCpuBakeVersion: bump when the CPU integrator below changes.
        if (cpu) {
            lighting.string("cpu tracer");
            lighting.value(kCpuBakeVersion);
        }
        // The bake's own code and the device that runs it change the result too: the SPIR-V of its shaders (an edit
        // of an included BRDF file re-bakes instead of loading a stale lightmap) and the device's name (another GPU, or
        // lavapipe, bakes other bits).
        hashBakeCode(ctx, lighting);
        const BakeKey key = bake::lightmapCacheKey(scene, mSettings, lighting.result());
        const BakeCache cache(defaultCacheDir());

        std::optional<bake::BakedLighting> baked;
        const auto loadStart = Clock::now();
        if (mUseCache)
            if (auto bytes = cache.get(key)) {
                baked = bake::deserializeBakedLighting(*bytes);
                if (baked && (baked->width != mAtlas.width || baked->height != mAtlas.height ||
                              baked->volume.counts != mVolume.counts))
                    baked.reset();
            }
        if (baked) {
            logInfo("scene '" + scene.name + "': lightmap loaded from the bake cache in " +
                    std::to_string(static_cast<int>(msSince(loadStart))) + " ms");
        } else {
            baked = bakeNow(ctx, gpu, cpu ? &cpuSky : nullptr);
            if (mUseCache && !cache.put(key, bake::serializeBakedLighting(*baked)))
                logWarning("scene '" + scene.name + "': could not write the lightmap to the bake cache under " +
                           cache.dir().string());
        }
        upload(ctx, *baked);
        mUploaded = true;
    }

    void releaseGpu() override { mUploaded = false; } // a new executor's outputs start empty

private:
    void hashBakeCode(ExecuteContext& ctx, scene::Hasher& h) const {
        const size_t textures = std::max<size_t>(1, mScene->scene().textures.size());
        const ShaderDefines defines = {{"VITRINE_SCENE_TEXTURES", std::to_string(textures)}};
        for (const char* path : {"bake/lightmap.comp", "bake/lightmap_texels.vert", "bake/lightmap_texels.frag"}) {
            const CompiledShader shader = ctx.shaders().compile(path, defines);
            h.bytes(shader.spirv.data(), shader.spirv.size() * sizeof(uint32_t));
        }
        h.string(ctx.gpu().deviceInfo().name);
    }

    static double msSince(Clock::time_point t) {
        return std::chrono::duration<double, std::milli>(Clock::now() - t).count();
    }

    // With `cpuSky`, the paths are traced on the CPU (traceOnCpu), else by shaders/bake/lightmap.comp.
    bake::BakedLighting bakeNow(ExecuteContext& ctx, GpuScene& gpu, const CpuSky* cpuSky) {
        const auto start = Clock::now();
        const scene::Scene& scene = mScene->scene();
        Context& context = ctx.gpu();
        bake::LightmapTexels texels;
        if (!mAtlas.regions.empty())
            texels = bake::rasterizeLightmapTexels(context, ctx.shaders(), gpu, scene, mAtlas);
        size_t texelJobs = 0;
        const std::vector<glm::vec4> jobs = bake::bakeJobs(texels, mVolume, mSettings.probeRays, &texelJobs);
        const size_t jobCount = jobs.size() / 2;
        if (!mAtlas.skipped.empty())
            logInfo("scene '" + scene.name + "': " + std::to_string(mAtlas.skipped.size()) +
                    " instances have no lightmap (dynamic, or no TEXCOORD_1) and take their diffuse light from the "
                    "irradiance volume");
        for (const auto& [instance, gap] : mAtlas.narrowChartGaps) {
            char line[96];
            std::snprintf(line, sizeof line, "%.1f texels apart (fewer than %.0f)", gap, mSettings.atlas.minChartGap);
            logWarning("scene '" + scene.name + "': the lightmap charts of mesh '" +
                       scene.meshes[scene.instances[instance].mesh].name + "' are " + line +
                       " at its region's largest size: their borders may take some of their neighbours' light; "
                       "its lightmap UVs need wider gaps between charts");
        }

        bake::BakedLighting out;
        out.width = mAtlas.width;
        out.height = mAtlas.height;
        out.volume = mVolume;
        if (jobCount > 0 && cpuSky) {
            const std::vector<glm::vec4> sums = traceOnCpu(jobs, jobCount, texelJobs, *cpuSky);
            resolve(sums.data(), texels, texelJobs, out);
        } else if (jobCount > 0) {
            GpuBuffer jobBuffer = uploadBuffer(context, jobs.data(), jobs.size() * sizeof(glm::vec4),
                                               VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, "bake.lightmap.jobs");
            GpuBuffer sums(context, 2 * jobCount * sizeof(glm::vec4), VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, true,
                           "bake.lightmap.sums");
            const std::array<VkBuffer, 2> buffers = {jobBuffer.buffer(), sums.buffer()};
            StorageBufferSet jobSet(context, buffers, VK_SHADER_STAGE_COMPUTE_BIT, "bake.lightmap.jobs");
            GpuBvh& bvh = mScene->bvh(context);
            const StorageBufferSet& geometry = gpu.geometrySet();
            const std::array<VkDescriptorSetLayout, 4> layouts = {bvh.setLayout(), gpu.setLayout(), geometry.layout(),
                                                                  jobSet.layout()};
            const std::array<VkDescriptorSet, 4> sets = {bvh.set(), gpu.set(), geometry.set(), jobSet.set()};

            const uint32_t perDispatch = LIGHTMAP_BAKE_PATHS_PER_DISPATCH;
            const uint32_t dispatches = (mSettings.samples + perDispatch - 1) / perDispatch;
            const uint32_t rows = static_cast<uint32_t>((jobCount + kJobsPerRow - 1) / kJobsPerRow);
            Progress progress("baking lightmap (" + std::to_string(texelJobs) + " texels, " +
                                  std::to_string(mVolume.probeCount()) + " probes, " + std::to_string(mSettings.samples) +
                                  " paths each)",
                              dispatches);
            uint32_t done = 0;
            for (uint32_t d = 0; d < dispatches; ++d) {
                LightmapBakePush push{};
                push.scales = {mSettings.sunScale, mSettings.skyScale, mSettings.emissiveScale,
                               mSettings.causticFootprintMeters()};
                const uint32_t count = std::min(perDispatch, mSettings.samples - done);
                const uint32_t sequence = d + (mSettings.seed << 16u); // distinct for every dispatch (fewer than 65536) and seed
                push.counts = {static_cast<uint32_t>(jobCount), count, sequence * 0x9E3779B9u + 0x7F4A7C15u, mSettings.maxBounces};
                push.grid = {kJobsPerRow, d == 0 ? LIGHTMAP_BAKE_FIRST : 0u, 0u, 0u};
                if (d > 0) ctx.computeBarrier();
                ctx.dispatchWithSets(mPipeline, &push, sizeof(push), std::min<uint32_t>(kJobsPerRow, jobCount), rows,
                                     layouts, sets);
                if (d + 1 == dispatches) hostReadBarrier(ctx.cmd());
                ctx.splitSubmission();
                done += count;
                progress.advance();
            }
            progress.finish();
            resolve(static_cast<const glm::vec4*>(sums.mapped()), texels, texelJobs, out);
        }
        out.bakeMs = msSince(start);
        logInfo("scene '" + scene.name + "': lightmap " + std::to_string(out.width) + "x" + std::to_string(out.height) +
                " and " + std::to_string(mVolume.probeCount()) + " probes baked in " +
                std::to_string(static_cast<int>(out.bakeMs / 1000.0 + 0.5)) + " s");
        return out;
    }

    // The integrator of shaders/bake/lightmap.comp on render.pathtrace's CPU tracer (nodes/render/pathtrace_cpu.hpp):
    // per job, `samples` paths of CpuRays::radiance (sky, emitters, the sun and the sky by next-event estimation at
    // every surface, the full material) from the texel along a cosine-distributed direction (irradiance: pi L) or
    // from the probe along its ray (radiance L). A path whose first triangle is the back of a single-sided surface
    // started inside geometry: it brings nothing and is counted, as on the GPU. Past the first surface such backs are
    // passed through, by both integrators and render.pathtrace (test BouncesPassThroughTheBackOfASingleSidedSurface). Returns the GPU's sums: per job (sum of estimates rgb, paths inside), (sum of squared luminance, 0, 0, 0).
    std::vector<glm::vec4> traceOnCpu(const std::vector<glm::vec4>& jobs, size_t jobCount, size_t texelJobs,
                                      const CpuSky& sky) const {
        const scene::Scene& scene = mScene->scene();
        CpuPathTracer tracer(scene, mScene->pose);
        CpuTraceSettings s;
        s.width = static_cast<int>(std::min<size_t>(kJobsPerRow, jobCount));
        s.height = static_cast<int>((jobCount + kJobsPerRow - 1) / kJobsPerRow);
        s.spp = mSettings.samples;
        s.maxBounces = mSettings.maxBounces;
        s.seed = mSettings.seed;
        s.sunScale = mSettings.sunScale;
        s.skyScale = mSettings.skyScale;
        s.emissiveScale = mSettings.emissiveScale;
        s.causticFootprint = mSettings.causticFootprintMeters();
        s.multiscatter = mSettings.multiscatter;
        s.envSampling = false; // the bake has the sky's cube map, not its sampling table
        std::vector<std::atomic<uint32_t>> inside(jobCount);
        const size_t width = static_cast<size_t>(s.width);
        auto sample = [&](const CpuRays& rays, int x, int y, uint32_t& rng) -> glm::vec3 {
            const size_t job = static_cast<size_t>(y) * width + static_cast<size_t>(x);
            if (job >= jobCount) return glm::vec3(0.0f);
            const glm::vec4 a = jobs[2 * job], b = jobs[2 * job + 1];
            const bool texel = a.w == bake::kJobTexel;
            const glm::vec3 n = glm::normalize(glm::vec3(b));
            const glm::vec3 dir =
                texel ? cpu_sampling::basisAround(n) * cpu_sampling::sampleCosine(CpuRays::next2(rng)) : n;
            const glm::vec3 origin = CpuRays::offset(glm::vec3(a), n, dir);
            CpuSurface first;
            bool startsInside = false;
            glm::vec3 L(0.0f);
            if (rays.firstHit(origin, dir, first, startsInside))
                L = rays.radianceFrom(first, dir, rng);
            else if (startsInside)
                inside[job].fetch_add(1, std::memory_order_relaxed);
            else
                L = rays.sky(dir);
            if (!std::isfinite(L.x) || !std::isfinite(L.y) || !std::isfinite(L.z)) L = glm::vec3(0.0f);
            return texel ? std::numbers::pi_v<float> * L : L;
        };
        Progress progress("baking lightmap on the CPU (" + std::to_string(texelJobs) + " texels, " +
                              std::to_string(mVolume.probeCount()) + " probes, " + std::to_string(mSettings.samples) +
                              " paths each)",
                          100);
        CpuAccumulation acc;
        acc.reset(s.width, s.height);
        tracer.estimate(s, sky, acc, sample, [&](double done) { progress.advanceTo(done); });
        progress.finish();
        std::vector<glm::vec4> sums(2 * jobCount);
        for (size_t job = 0; job < jobCount; ++job) {
            // stats: (count, mean luminance, sum of squared deviations, standard error).
            const glm::vec4 c = acc.color[job], st = acc.stats[job];
            sums[2 * job] = glm::vec4(glm::vec3(c) * st.x, float(inside[job].load()));
            sums[2 * job + 1] = glm::vec4(st.z + st.x * st.y * st.y, 0.0f, 0.0f, 0.0f);
        }
        return sums;
    }

    // The GPU's sums become irradiance per texel (filtered, dilated, packed) and SH per probe.
    void resolve(const glm::vec4* sums, bake::LightmapTexels& texels, size_t texelJobs, bake::BakedLighting& out) const {
        const float inv = 1.0f / static_cast<float>(mSettings.samples);
        size_t job = 0;
        texels.variance.assign(texels.region.size(), 0.0f);
        size_t inside = 0;
        for (size_t i = 0; i < texels.region.size(); ++i)
            if (texels.region[i] >= 0) {
                // A texel most of whose rays start inside geometry (under a wall, where a column stands on the
                // floor) is hidden: it is given its visible neighbours' light (dilation) rather than its own
                // darkness, which bilinear filtering would smear into the visible texels beside it.
                if (sums[2 * job].w > 0.5f * float(mSettings.samples)) {
                    texels.region[i] = -1;
                    ++inside;
                    ++job;
                    continue;
                }
                // The texel's light is the mean of the paths that started outside geometry: a path that starts
                // under a wall brings no light (0), and counting it would darken every texel at a wall's foot by
                // the share of its footprint the wall covers.
                const float outside = float(mSettings.samples) - sums[2 * job].w;
                const float invOutside = 1.0f / std::max(outside, 1.0f);
                const glm::vec3 mean = glm::vec3(sums[2 * job]) * invOutside;
                const float meanY = 0.2126f * mean.r + 0.7152f * mean.g + 0.0722f * mean.b;
                texels.irradiance[i] = mean;
                // Variance of the mean of the texel's samples' luminance.
                texels.variance[i] = std::max(sums[2 * job + 1].x * invOutside - meanY * meanY, 0.0f) * invOutside;
                ++job;
            }
        if (job != texelJobs) throw InternalError("bake.lightmap: texel jobs out of step");
        if (!texels.region.empty()) {
            bake::filterLightmap(texels, mSettings.filter);
            bake::dilateLightmap(texels, static_cast<int>(std::max(mSettings.atlas.gutter, 4u)));
        }
        if (inside > 0)
            logInfo("bake.lightmap: " + std::to_string(inside) + " of " + std::to_string(texelJobs) +
                    " texels lie inside geometry and take their neighbours' light");
        out.lightmap.assign(size_t(out.width) * out.height, 0u);
        for (size_t i = 0; i < texels.irradiance.size(); ++i) out.lightmap[i] = bake::packRgb9e5(texels.irradiance[i]);

        const uint32_t rays = mSettings.probeRays;
        std::vector<glm::vec3> radiance(rays);
        for (size_t probe = 0; probe < mVolume.probeCount(); ++probe) {
            float inside = 0.0f;
            for (uint32_t r = 0; r < rays; ++r) {
                const glm::vec4 s = sums[2 * (texelJobs + probe * rays + r)];
                radiance[r] = glm::vec3(s) * inv;
                inside += s.w;
            }
            bake::projectProbe(out.volume, probe, radiance, inside * inv / float(rays));
        }
    }

    static void hostReadBarrier(VkCommandBuffer cmd) {
        VkMemoryBarrier2 b{VK_STRUCTURE_TYPE_MEMORY_BARRIER_2};
        b.srcStageMask = VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT;
        b.srcAccessMask = VK_ACCESS_2_SHADER_STORAGE_WRITE_BIT;
        b.dstStageMask = VK_PIPELINE_STAGE_2_HOST_BIT;
        b.dstAccessMask = VK_ACCESS_2_HOST_READ_BIT;
        VkDependencyInfo dep{VK_STRUCTURE_TYPE_DEPENDENCY_INFO};
        dep.memoryBarrierCount = 1;
        dep.pMemoryBarriers = &b;
        vkCmdPipelineBarrier2(cmd, &dep);
    }

    void upload(ExecuteContext& ctx, const bake::BakedLighting& baked) const {
        const ImageDesc& lm = ctx.output("lightmap").desc();
        Image atlas(static_cast<int>(lm.width), static_cast<int>(lm.height));
        if (!baked.lightmap.empty())
            for (size_t i = 0; i < baked.lightmap.size(); ++i) {
                const glm::vec3 e = bake::unpackRgb9e5(baked.lightmap[i]);
                float* px = &atlas.pixels[i * 4];
                px[0] = e.r;
                px[1] = e.g;
                px[2] = e.b;
                px[3] = 1.0f;
            }
        ctx.upload("lightmap", atlas);

        const ImageDesc& vd = ctx.output("volume").desc();
        Image volume(static_cast<int>(vd.width), static_cast<int>(vd.height));
        const glm::uvec3 c = baked.volume.counts;
        for (uint32_t z = 0; z < c.z; ++z)
            for (uint32_t y = 0; y < c.y; ++y)
                for (uint32_t x = 0; x < c.x; ++x) {
                    const size_t probe = x + size_t(c.x) * (y + size_t(c.y) * z);
                    for (int k = 0; k < 9; ++k) {
                        float* px = volume.at(static_cast<int>(9 * x + k), static_cast<int>(y + c.y * z));
                        const glm::vec3 v = baked.volume.sh[probe][k];
                        px[0] = v.r;
                        px[1] = v.g;
                        px[2] = v.b;
                        px[3] = baked.volume.validity[probe];
                    }
                }
        ctx.upload("volume", volume);
    }

    std::shared_ptr<SceneObject> mScene;
    bake::LightmapBakeSettings mSettings;
    bake::LightmapAtlas mAtlas;
    bake::IrradianceVolume mVolume;
    bool mUseCache = true;
    std::string mBackend; // the `backend` param (gpu, cpu or auto), read in setup
    bool mUploaded = false;
    PipelineId mPipeline = 0;
};

const NodeRegistration kRegistration(schema(), [] { return std::make_unique<LightmapBake>(); });

} // namespace
} // namespace vitrine
