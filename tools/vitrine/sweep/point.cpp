#include "tools/vitrine/sweep/point.hpp"

#include "core/base/atomic_file.hpp"
#include "core/base/error.hpp"
#include "core/base/log.hpp"
#include "core/compare/report.hpp"
#include "core/graph/loader.hpp"
#include "core/image/io.hpp"
#include "tools/vitrine/render_output.hpp"

#include <sys/resource.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <ctime>

namespace vitrine::sweep {

namespace fs = std::filesystem;

namespace {

using Clock = std::chrono::steady_clock;

double msSince(Clock::time_point t) {
    return std::chrono::duration<double, std::milli>(Clock::now() - t).count();
}

// `compare --frame N` / `--frames A:B`: the frame count is part of the document before validation.
std::vector<std::string> frameSets(const FrameSpec& f) {
    if (f.graphDefault) return {};
    return {"frame.frames=" + std::to_string(f.last + 1), "frame.write=[" + std::to_string(f.last) + "]"};
}

std::vector<std::string> concat(std::vector<std::string> a, const std::vector<std::string>& b) {
    a.insert(a.end(), b.begin(), b.end());
    return a;
}

// The frames a point and its reference render, as `vitrine compare` chooses them for the same pair: without a range,
// the still is the last frame of the longer graph.
struct Frames {
    uint32_t count = 1;
    uint32_t first = 0;
    uint32_t last = 0;
    std::vector<uint32_t> wanted() const {
        std::vector<uint32_t> w;
        for (uint32_t f = first; f <= last; ++f) w.push_back(f);
        return w;
    }
    std::string key(const std::string& output) const {
        std::string safe = output;
        for (char& c : safe) if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
        return safe + "_" + std::to_string(first) + "-" + std::to_string(last) + "_of_" + std::to_string(count);
    }
};

Frames chooseFrames(const FrameSpec& spec, const GraphDesc& point, const GraphDesc* reference) {
    uint32_t graphFrames = std::max<uint32_t>(1, point.frame.frames);
    if (reference) graphFrames = std::max(graphFrames, reference->frame.frames);
    Frames f;
    if (spec.graphDefault) {
        f.first = f.last = graphFrames - 1;
    } else {
        f.first = spec.temporal ? spec.first : spec.last;
        f.last = spec.last;
    }
    f.count = std::max(f.last + 1, graphFrames);
    return f;
}

struct Loaded {
    GraphDesc point;
    std::optional<GraphDesc> reference;
    std::string output;
    Frames frames;
};

Loaded load(const SweepFile& sweep, const Point& point) {
    Loaded l{loadGraph(point.graph, concat(frameSets(point.frames), point.sets)), std::nullopt, "", {}};
    l.output = cli::pickOutput(l.point, sweep.output);
    if (sweep.reference) {
        l.reference = loadGraph(*sweep.reference, concat(frameSets(point.frames), sweep.sizeSets()));
        cli::pickOutput(*l.reference, l.output);
    }
    l.frames = chooseFrames(point.frames, l.point, l.reference ? &*l.reference : nullptr);
    return l;
}

fs::path referenceDir(const fs::path& outDir, const Loaded& l) {
    return outDir / "reference" / l.frames.key(l.output);
}

// The reference frames, from DIR/reference/KEY/ (float EXR keeps every value) or rendered and stored there.
std::vector<Image> referenceFrames(Context& ctx, ShaderCompiler& shaders, const Loaded& l, const fs::path& outDir,
                                   bool* rendered) {
    const fs::path dir = referenceDir(outDir, l);
    std::vector<Image> frames;
    std::error_code ec;
    if (fs::exists(dir / "done", ec)) {
        for (uint32_t f : l.frames.wanted()) frames.push_back(loadImage(dir / ("frame_" + std::to_string(f) + ".exr")));
        if (rendered) *rendered = false;
        return frames;
    }
    logInfo("rendering the reference " + l.reference->file + " (" + std::to_string(l.frames.count) + " frame(s))");
    std::map<uint32_t, Image> images =
        cli::renderOutput(ctx, shaders, *l.reference, l.output, l.frames.count, l.frames.wanted(), false);
    fs::create_directories(dir, ec);
    for (uint32_t f : l.frames.wanted()) {
        writeExr(dir / ("frame_" + std::to_string(f) + ".exr"), images.at(f), ExrPixelType::Float);
        frames.push_back(std::move(images.at(f)));
    }
    writeFileAtomically(dir / "done", l.reference->file + "\n");
    if (rendered) *rendered = true;
    return frames;
}

uint64_t maxRssBytes() {
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    return static_cast<uint64_t>(usage.ru_maxrss) * 1024;
}

double median(std::vector<double> v) {
    if (v.empty()) return 0.0;
    std::sort(v.begin(), v.end());
    const size_t n = v.size();
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

nlohmann::json number(double v) {
    return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr);
}

int runPointOrThrow(const SweepFile& sweep, const Point& point, const fs::path& outDir, const cli::Args& args,
                    const fs::path& dir, nlohmann::json& phases) {
    const auto start = Clock::now();
    auto t = Clock::now();
    Loaded l = load(sweep, point);
    phases["load_ms"] = msSince(t);

    t = Clock::now();
    Context ctx(cli::contextOptions(args));
    ShaderCompiler shaders;
    phases["device_ms"] = msSince(t);

    cli::RenderStats stats;
    std::map<uint32_t, Image> images = cli::renderOutput(ctx, shaders, l.point, l.output, l.frames.count,
                                                         l.frames.wanted(), false, &stats);
    phases["compile_ms"] = stats.compileMs - stats.sceneBuildMs;
    phases["scene_build_ms"] = stats.sceneBuildMs;
    phases["pipelines_ms"] = stats.pipelineMs;
    phases["render_ms"] = stats.runMs;
    std::vector<Image> frames;
    for (uint32_t f : l.frames.wanted()) frames.push_back(std::move(images.at(f)));
    const Image& still = frames.back();

    nlohmann::json m = nlohmann::json::object();
    nlohmann::json j;
    j["format"] = "vitrine-sweep-point/1";
    j["id"] = point.id;
    j["label"] = point.label;
    j["values"] = point.values;
    j["graph"] = point.graph.string();
    j["sets"] = point.sets;
    j["output"] = l.output;
    j["device"] = ctx.deviceInfo().name;
    j["width"] = still.width;
    j["height"] = still.height;
    j["frames"] = {{"count", l.frames.count}, {"first", l.frames.first}, {"last", l.frames.last}};

    std::vector<Image> reference;
    if (l.reference) {
        t = Clock::now();
        bool rendered = false;
        reference = referenceFrames(ctx, shaders, l, outDir, &rendered);
        phases[rendered ? "reference_render_ms" : "reference_load_ms"] = msSince(t);
    }
    t = Clock::now();
    std::optional<compare::PairComparison> pair;
    if (l.reference && (sweep.wants("flip") || sweep.wants("ssim") || sweep.wants("psnr") || sweep.keep.count("flip") ||
                        sweep.keep.count("report"))) {
        // The same call `vitrine compare POINT REFERENCE` makes for its pair "A vs B" (LDR-FLIP, default viewing).
        pair = compare::comparePair("A", still, "B", reference.back(), compare::PairOptions{});
        if (sweep.wants("flip")) {
            m["flip"] = pair->metrics.flip.mean;
            m["flip_weighted_median"] = pair->metrics.flip.weightedMedian;
        }
        if (sweep.wants("ssim")) m["ssim"] = pair->metrics.ssim;
        if (sweep.wants("psnr")) m["psnr"] = number(pair->metrics.psnr);
    }
    if (sweep.wants("flicker")) m["flicker"] = frames.size() >= 2 ? nlohmann::json(compare::flicker(frames)) : nullptr;
    if (sweep.wants("gpu_ms")) {
        // Median over the rendered frames after the first (the first alone for a single frame), per pass as `bench`.
        const size_t warmup = stats.timings.size() > 1 ? 1 : 0;
        nlohmann::json perNode = nlohmann::json::object();
        for (size_t p = 0; p < stats.passIds.size(); ++p) {
            std::vector<double> ms;
            for (size_t f = warmup; f < stats.timings.size(); ++f) ms.push_back(stats.timings[f].passGpuMs[p]);
            perNode[stats.passIds[p]] = median(ms);
        }
        std::vector<double> totals;
        for (size_t f = warmup; f < stats.timings.size(); ++f) {
            double sum = 0;
            for (double v : stats.timings[f].passGpuMs) sum += v;
            totals.push_back(sum);
        }
        m["gpu_ms"] = median(totals);
        j["gpu_ms_per_node"] = perNode;
        j["gpu_ms_frames_timed"] = totals.size();
    }
    if (sweep.wants("memory")) {
        m["device_bytes"] = stats.memory.transientAliased + stats.memory.persistent;
        m["max_rss_bytes"] = maxRssBytes();
        j["memory_bytes"] = {{"transient_aliased", stats.memory.transientAliased},
                             {"transient_unaliased", stats.memory.transientUnaliased},
                             {"persistent", stats.memory.persistent}};
    }
    phases["metrics_ms"] = msSince(t);

    t = Clock::now();
    nlohmann::json kept = nlohmann::json::object();
    auto keepPng = [&](const std::string& name, const Image& image) {
        writePng(dir / (name + ".png"), image);
        kept[name] = name + ".png";
    };
    if (sweep.keep.count("image")) keepPng("image", still);
    if (l.reference && sweep.keep.count("reference")) keepPng("reference", reference.back());
    if (l.reference && sweep.keep.count("diff"))
        keepPng("diff", compare::falseColor(compare::absoluteDifference(still, reference.back()), 1.0));
    if (pair && sweep.keep.count("flip")) keepPng("flip", compare::flipColorMap(pair->flipErrorMap));
    if (pair && sweep.keep.count("report")) {
        compare::ReportInput report;
        report.title = point.id + " " + point.label + " vs " + l.reference->file;
        report.a = {"A: " + point.label, encodePng(still), still.width, still.height};
        report.b = {"B: reference " + l.reference->file, encodePng(reference.back()), still.width, still.height};
        report.differenceMaps.push_back(
            {"|A − B| × 1", encodePng(compare::falseColor(compare::absoluteDifference(still, reference.back()), 1.0)),
             still.width, still.height});
        report.flipMaps.push_back(
            {"LDR-FLIP A vs B", encodePng(compare::flipColorMap(pair->flipErrorMap)), still.width, still.height});
        report.metrics.push_back(pair->metrics);
        report.graphA = l.point.document;
        report.graphB = l.reference->document;
        compare::writeReport(dir / "compare.html", report);
        kept["report"] = "compare.html";
    }
    j["images"] = kept;
    writeFileAtomically(dir / "graph.json", l.point.document.dump(2) + "\n");
    phases["write_ms"] = msSince(t);
    phases["total_ms"] = msSince(start);
    j["metrics"] = m;
    j["phases_ms"] = phases;
    if (ctx.validationMessageCount() > 0)
        throw std::runtime_error(std::to_string(ctx.validationMessageCount()) + " Vulkan validation message(s)");
    j["status"] = "ok";
    writeFileAtomically(dir / "metrics.json", j.dump(2) + "\n");
    return 0;
}

} // namespace

void writePointError(const fs::path& pointDir, const Point& point, const std::string& message, int exitCode) {
    nlohmann::json e = {{"format", "vitrine-sweep-point/1"}, {"id", point.id},         {"label", point.label},
                        {"values", point.values},            {"status", "failed"},     {"error", message},
                        {"exit_code", exitCode}};
    std::error_code ec;
    fs::create_directories(pointDir, ec);
    writeFileAtomically(pointDir / "error.json", e.dump(2) + "\n");
}

int runPoint(const SweepFile& sweep, const Point& point, const fs::path& outDir, const cli::Args& args) {
    nlohmann::json phases = nlohmann::json::object();
    // The driver puts its clock (CLOCK_REALTIME, ns) in the environment as it starts the process: start_ms is then
    // exec, dynamic linking, static initialisers and reading the sweep file.
    if (const char* spawned = std::getenv("VITRINE_SWEEP_SPAWN_NS")) {
        timespec now{};
        clock_gettime(CLOCK_REALTIME, &now);
        const double nowNs = static_cast<double>(now.tv_sec) * 1e9 + static_cast<double>(now.tv_nsec);
        phases["start_ms"] = (nowNs - std::strtod(spawned, nullptr)) / 1e6;
    }
    const fs::path dir = outDir / "points" / point.id;
    std::error_code ec;
    fs::create_directories(dir, ec);
    fs::remove(dir / "error.json", ec);
    try {
        return runPointOrThrow(sweep, point, outDir, args, dir, phases);
    } catch (const UserError& e) {
        writePointError(dir, point, e.what(), 1);
        std::fprintf(stderr, "error: %s\n", e.what());
        return 1;
    } catch (const std::exception& e) {
        writePointError(dir, point, std::string("internal error: ") + e.what(), 2);
        std::fprintf(stderr, "internal error: %s\n", e.what());
        return 2;
    }
}

void renderReferences(const SweepFile& sweep, const std::vector<Point>& points, const fs::path& outDir,
                      const cli::Args& args) {
    if (!sweep.reference) return;
    std::unique_ptr<Context> ctx;
    std::unique_ptr<ShaderCompiler> shaders;
    std::set<fs::path> done;
    for (const Point& point : points) {
        std::optional<Loaded> l;
        try {
            l = load(sweep, point);
        } catch (const UserError&) {
            continue; // that point fails in its own process, with its own error.json
        }
        const fs::path dir = referenceDir(outDir, *l);
        std::error_code ec;
        if (!done.insert(dir).second || fs::exists(dir / "done", ec)) continue;
        if (!ctx) {
            ctx = std::make_unique<Context>(cli::contextOptions(args));
            shaders = std::make_unique<ShaderCompiler>();
        }
        referenceFrames(*ctx, *shaders, *l, outDir, nullptr);
    }
    if (ctx && ctx->validationMessageCount() > 0)
        throw std::runtime_error(std::to_string(ctx->validationMessageCount()) + " Vulkan validation message(s) rendering the reference");
}

} // namespace vitrine::sweep
