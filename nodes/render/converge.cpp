// "Converge, then cache" (see converge.hpp).
#include "nodes/render/converge.hpp"
#include "core/base/log.hpp"
#include "core/gpu/context.hpp"
#include "core/gpu/transfer.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>
#include <optional>

namespace vitrine {

void appendConvergeParams(std::vector<ParamSpec>& params) {
    params.push_back(
        {"target_noise",
         ParamType::Float,
         0.0,
         0.0,
         1.0,
         {},
         "Converge, then cache: > 0 traces batches of `spp` samples until the median over lit pixels of the standard "
         "error of the mean luminance, relative to that mean (stats.w / stats.y), is at most this and min_spp is "
         "reached (or max_seconds ran out); the converged result is stored in the bake cache under a key of "
         "everything it depends on and loaded, not traced, by later runs. 0: `spp` samples a frame, no cache"});
    params.push_back(
        {"min_spp",
         ParamType::Int,
         64,
         1.0,
         1e9,
         {},
         "With target_noise: at least this many samples per pixel (the noise estimate of a few samples is itself noisy)"});
    params.push_back({"max_seconds",
                      ParamType::Float,
                      0.0,
                      0.0,
                      1e7,
                      {},
                      "With target_noise: stop after this long even if the target is not reached (0: no limit); a "
                      "result stopped early (or by Ctrl-C) is kept in the bake cache as a partial result that the next "
                      "run with the same inputs resumes"});
}

uint32_t convergeBatchSeed(uint32_t seed, uint32_t b) { return (seed * 0x85EBCA6Bu + 0x27D4EB2Fu) ^ (b * 0x9E3779B9u); }

ConvergeProgress convergeAccumulation(const ConvergeRun& run, CpuAccumulation& acc, const TraceBatchFn& traceBatch) {
    const auto start = std::chrono::steady_clock::now();
    auto elapsed = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(); };
    if (run.firstBatch == 0) acc.reset(run.width, run.height);
    std::unique_ptr<Progress> bar;
    if (run.report) {
        char label[200];
        std::snprintf(label, sizeof label, "%s %dx%d to %.2f %% noise on the %s", run.what.c_str(), run.width,
                      run.height, run.target * 100.0, run.where.c_str());
        bar = std::make_unique<Progress>(label, 1000);
    }
    size_t shown = 0;
    // samples: in the accumulation (a resumed run's included); traced: by this run.
    double samples = double(run.firstBatch) * run.batch, traced = 0.0, noise = 1.0, p90 = 0.0;
    double firstBatchEnd = 0.0; // seconds: the first batch carries one-off costs (pipelines, first touches of memory)
    bool announced = false;
    ConvergeProgress progress;
    const char* stoppedBy = "max_seconds ran out";
    uint32_t b = run.firstBatch;
    for (;; ++b) {
        traceBatch(run.batch, convergeBatchSeed(run.seed, b), b);
        samples += run.batch;
        traced += run.batch;
        noise = acc.relativeNoise(&p90);
        const double t = elapsed();
        if (b == run.firstBatch) firstBatchEnd = t;
        // Noise falls as 1 / sqrt(samples): the samples the target needs, and the time that takes.
        const double needed = std::max(run.minSpp, samples * (noise / run.target) * (noise / run.target));
        {
            char line[200];
            std::snprintf(line, sizeof line, "%s: batch %u: %.0f spp in %.2f s, standard error %.4f %% (median), %.4f %% (p90)",
                          run.node.c_str(), b, samples, t, noise * 100.0, p90 * 100.0);
            logDebug(line);
        }
        // The estimate is announced once min_spp samples are in (and a batch after the first), not after the first
        // batch: with a few samples a pixel's standard error is estimated low (the rare bright paths are not yet
        // seen), and the first batch's time includes one-off costs. Measured on the museum's reference (80x45,
        // target 0.036, lavapipe's CPU tracer): after the first 16 spp it predicted 6,574 spp and 204 s for what took
        // 11,520 spp and 90 s; announced at 64 spp, 9,189 spp and 69 s for a run of 11,520 spp and 85 s. The progress
        // bar's time left follows the rate as it goes.
        if (run.report && !announced && b > run.firstBatch && (samples >= run.minSpp || noise <= run.target)) {
            const double perSample = (t - firstBatchEnd) / (traced - run.batch);
            char line[280];
            std::snprintf(line, sizeof line,
                          "%s: %.0f spp in %.1f s, standard error %.1f %% (median); the target %.2f %% needs about "
                          "%.0f spp: about %.0f s on this machine (estimates from few samples tend to be low)",
                          run.node.c_str(), samples, run.secondsBefore + t, noise * 100.0, run.target * 100.0, needed,
                          run.secondsBefore + t + std::max(0.0, needed - samples) * perSample);
            std::fprintf(stderr, "\n");
            logInfo(line);
            announced = true;
        }
        if (bar) {
            const size_t now = static_cast<size_t>(std::min(0.999, samples / needed) * 1000.0);
            if (now > shown) bar->advance(now - shown);
            shown = std::max(shown, now);
        }
        if (samples >= run.minSpp && noise <= run.target) {
            progress.converged = true;
            break;
        }
        if (run.maxSeconds > 0.0 && t >= run.maxSeconds) break;
        if (run.stop && run.stop()) {
            stoppedBy = "asked to stop";
            break;
        }
    }
    if (bar) {
        bar->advance(1000 - shown);
        bar.reset();
    }
    progress.batches = b + 1;
    progress.seconds = run.secondsBefore + elapsed();
    char line[320];
    if (progress.converged)
        std::snprintf(line, sizeof line,
                      "%s: converged after %.0f spp in %.1f s%s: standard error %.2f %% of the pixel's mean (median), "
                      "%.2f %% (p90)",
                      run.node.c_str(), samples, progress.seconds, run.firstBatch > 0 ? " (over several runs)" : "",
                      noise * 100.0, p90 * 100.0);
    else
        std::snprintf(line, sizeof line,
                      "%s: stopped (%s) after %.0f spp in %.1f s: standard error %.2f %% of the pixel's mean (median), "
                      "%.2f %% (p90), above the target %.2f %%",
                      run.node.c_str(), stoppedBy, samples, progress.seconds, noise * 100.0, p90 * 100.0,
                      run.target * 100.0);
    (progress.converged ? logInfo : logWarning)(line);
    return progress;
}

BakeKey partialKey(const BakeKey& key) {
    return BakeKey{key.kind + "_partial", key.hash};
}

namespace {

// The converged result under `key`, if the bake cache has one of this size (logs the load time and its noise).
bool loadConverged(const BakeCache& cache, const BakeKey& key, const std::string& node, int width, int height,
                   CpuAccumulation& acc) {
    const auto loadStart = std::chrono::steady_clock::now();
    std::optional<std::vector<uint8_t>> bytes = cache.get(key);
    if (!bytes || !acc.deserialize(*bytes, width, height)) return false;
    double p90 = 0.0;
    const double noise = acc.relativeNoise(&p90);
    char line[280];
    std::snprintf(line, sizeof line,
                  "%s: converged result loaded from the bake cache in %.0f ms (%.0f spp, standard error %.2f %% of the "
                  "pixel's mean (median), %.2f %% (p90))",
                  node.c_str(),
                  std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - loadStart).count(),
                  static_cast<double>(acc.stats.empty() ? 0.0f : acc.stats[0].x), noise * 100.0, p90 * 100.0);
    logInfo(line);
    return true;
}

// A partial result: the accumulation's bytes, then this trailer.
struct PartialTrailer {
    uint32_t magic = 0x54524150u; // "PART"
    uint32_t batches = 0;         // batches 0 .. batches - 1 are in the accumulation
    uint32_t batch = 0;           // samples per pixel per batch (also in the key: a check)
    uint32_t reserved = 0;
    double seconds = 0.0; // what they took, over every run so far
};

std::vector<uint8_t> serializePartial(const CpuAccumulation& acc, const ConvergeProgress& progress, uint32_t batch) {
    std::vector<uint8_t> bytes = acc.serialize();
    PartialTrailer trailer;
    trailer.batches = progress.batches;
    trailer.batch = batch;
    trailer.seconds = progress.seconds;
    const size_t at = bytes.size();
    bytes.resize(at + sizeof trailer);
    std::memcpy(bytes.data() + at, &trailer, sizeof trailer);
    return bytes;
}

// The partial result under partialKey(key) into acc and its trailer; nullopt (acc unchanged) when there is none, or
// it is of another size, batch or format.
std::optional<PartialTrailer> loadPartial(const BakeCache& cache, const BakeKey& key, const ConvergeRun& run,
                                          CpuAccumulation& acc) {
    std::optional<std::vector<uint8_t>> bytes = cache.get(partialKey(key));
    if (!bytes || bytes->size() < sizeof(PartialTrailer)) return std::nullopt;
    PartialTrailer trailer;
    std::memcpy(&trailer, bytes->data() + bytes->size() - sizeof trailer, sizeof trailer);
    if (trailer.magic != PartialTrailer{}.magic || trailer.batch != run.batch || trailer.batches == 0)
        return std::nullopt;
    bytes->resize(bytes->size() - sizeof trailer);
    if (!acc.deserialize(*bytes, run.width, run.height)) return std::nullopt;
    return trailer;
}

} // namespace

bool convergeCached(const BakeKey& key, const ConvergeRun& runIn, CpuAccumulation& acc, const TraceBatchFn& traceBatch,
                    const ConvergeHooks& hooks) {
    const BakeCache cache(defaultCacheDir());
    if (loadConverged(cache, key, runIn.node, runIn.width, runIn.height, acc)) return true;
    ConvergeRun run = runIn;
    run.firstBatch = 0;
    run.secondsBefore = 0.0;
    if (std::optional<PartialTrailer> partial = loadPartial(cache, key, run, acc)) {
        run.firstBatch = partial->batches;
        run.secondsBefore = partial->seconds;
        double p90 = 0.0;
        const double noise = acc.relativeNoise(&p90);
        char line[280];
        std::snprintf(line, sizeof line,
                      "%s: resuming the partial result an earlier run stopped with (%.0f spp in %.1f s, standard "
                      "error %.2f %% (median)): %s",
                      run.node.c_str(), double(run.firstBatch) * run.batch, run.secondsBefore, noise * 100.0,
                      cache.pathOf(partialKey(key)).string().c_str());
        logInfo(line);
        if (hooks.resumed) hooks.resumed(acc);
    }
    const ConvergeProgress progress = convergeAccumulation(run, acc, traceBatch);
    if (hooks.finished) hooks.finished(acc);
    if (progress.converged) {
        if (!cache.put(key, acc.serialize()))
            logWarning(run.node + ": could not write the converged result to the bake cache under " +
                       cache.dir().string());
        std::error_code ec;
        std::filesystem::remove(cache.pathOf(partialKey(key)), ec);
        return true;
    }
    if (cache.put(partialKey(key), serializePartial(acc, progress, run.batch)))
        logWarning(run.node +
                   ": kept the partial result in the bake cache; the next run with the same inputs resumes "
                   "from it (" +
                   cache.pathOf(partialKey(key)).string() + ")");
    else
        logWarning(run.node + ": could not write the partial result to the bake cache under " + cache.dir().string());
    return false;
}

void hashTraceInputs(scene::Hasher& h, const SceneObject& scene, const CameraFrame& cam, const CpuSky& sky, int width,
                     int height) {
    h.value(scene.scene().lightTransportHash());
    h.array(scene.pose.instanceWorld);
    if (scene.deformation().any()) { // the posed vertices follow the joints (nodes) and the morph weights
        h.string("deformed");
        h.array(scene.pose.nodeWorld);
        for (const std::vector<float>& w : scene.pose.meshWeights)
            h.array(w);
    }
    h.value(cam.viewProjNoJitter);
    h.value(cam.state.position);
    for (const Image& face : sky.faces) h.array(face.pixels);
    h.value(sky.sunIlluminance);
    h.value(sky.sunDirection);
    h.value(sky.envCdf.empty());
    h.value(width);
    h.value(height);
}

CpuSky cpuSkyFrom(std::vector<Image> faces, const Image& sh) {
    CpuSky sky;
    sky.size = faces.empty() ? 0 : faces.front().width;
    sky.faces = std::move(faces);
    sky.sunIlluminance = glm::vec3(sh.at(9, 0)[0], sh.at(9, 0)[1], sh.at(9, 0)[2]);
    sky.sunDirection = glm::vec3(sh.at(10, 0)[0], sh.at(10, 0)[1], sh.at(10, 0)[2]);
    return sky;
}

CpuSky readCpuSky(ExecuteContext& ctx) {
    const GpuImage& cube = ctx.input("sky");
    std::vector<Image> faces;
    for (uint32_t face = 0; face < 6; ++face)
        faces.push_back(readImage(ctx.gpu(), cube, VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL, 0, face));
    CpuSky sky = cpuSkyFrom(std::move(faces),
                            readImage(ctx.gpu(), ctx.input("sky_sh"), VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL));
    if (ctx.hasInput("env_cdf"))
        sky.envCdf = readImage(ctx.gpu(), ctx.input("env_cdf"), VK_IMAGE_LAYOUT_SHADER_READ_ONLY_OPTIMAL);
    return sky;
}

void CpuResultUpload::upload(ExecuteContext& ctx, PipelineId storePipeline, const CpuAccumulation& acc) {
    const size_t bytes = acc.color.size() * 2 * sizeof(glm::vec4);
    if (!mBuffer || mBuffer.size() < bytes) {
        mSet = StorageBufferSet();
        mBuffer = GpuBuffer(ctx.gpu(), bytes, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, true, "cpu_result");
        const VkBuffer buffers[1] = {mBuffer.buffer()};
        mSet = StorageBufferSet(ctx.gpu(), buffers, VK_SHADER_STAGE_COMPUTE_BIT, "cpu_result");
    }
    auto* dst = static_cast<glm::vec4*>(mBuffer.mapped());
    for (size_t i = 0; i < acc.color.size(); ++i) {
        dst[2 * i] = acc.color[i];
        dst[2 * i + 1] = acc.stats[i];
    }
    const glm::uvec4 push(static_cast<uint32_t>(acc.width), static_cast<uint32_t>(acc.height), 0u, 0u);
    std::array<VkDescriptorSetLayout, 1> layouts = {mSet.layout()};
    std::array<VkDescriptorSet, 1> sets = {mSet.set()};
    ctx.dispatchWithSets(storePipeline, &push, sizeof(push), push.x, push.y, layouts, sets);
}

} // namespace vitrine
