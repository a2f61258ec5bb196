// `vitrine compare A B [--reference R]`: renders graphs or loads images, computes PSNR, SSIM, FLIP and the block
// luminance ratio (and, over --frames a:b, flicker and error per frame), with a reference also its noise floor (FLIP
// between the reference and a second, independently seeded half), writes the images, heat maps, metrics.json and one
// self-contained report.html. The metrics and the report come from core/compare; this file only gathers the inputs.
#include "core/base/atomic_file.hpp"
#include "core/base/error.hpp"
#include "core/base/log.hpp"
#include "core/compare/report.hpp"
#include "core/graph/loader.hpp"
#include "core/image/io.hpp"
#include "tools/vitrine/cli.hpp"
#include "tools/vitrine/interrupt.hpp"
#include "tools/vitrine/output_dir.hpp"
#include "tools/vitrine/render_output.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <fstream>
#include <memory>
#include <optional>

namespace vitrine::cli {

namespace fs = std::filesystem;

namespace {

struct Input {
    std::string role; // "A", "B" or "reference": labels in the report and in messages
    std::string key;  // "a", "b" or "reference": file names
    fs::path path;
    std::optional<GraphDesc> graph; // empty: an image file
    std::string output;             // the graph output compared
    std::vector<Image> frames;      // frames first..last (an image repeats itself)
    Image still;                    // the frame compared as a still
};

std::string lower(std::string s) {
    std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return std::tolower(c); });
    return s;
}

bool isImageFile(const fs::path& path) {
    const std::string ext = lower(path.extension().string());
    return ext == ".exr" || ext == ".png" || ext == ".jpg" || ext == ".jpeg" || ext == ".hdr";
}

// `frames`: the frame count --frame/--frames ask for (0: the graph's own), part of the graph before validation.
Input openInput(const std::string& role, const std::string& key, const fs::path& path, const Args& args,
                uint32_t frames) {
    const std::string expected = "expected a graph (.json) or an image (.exr, .png, .jpg, .hdr)";
    std::error_code ec;
    if (!fs::exists(path, ec)) throw UserError(path.string() + ": not found (compare " + role + ": " + expected + ")");
    if (!fs::is_regular_file(path, ec))
        throw UserError(path.string() + ": not a regular file (compare " + role + ": " + expected + ")");
    Input in{role, key, path, {}, {}, {}, {}};
    const std::string ext = lower(path.extension().string());
    if (ext == ".json") {
        in.graph = loadGraph(path, setsWithFrames(args, frames, false, path.string()));
        // --output-a/-b/-reference pick one side's output (one term of the frame against its twin's), else --output.
        const std::string side = key == "reference_half" ? "reference" : key;
        in.output = pickOutput(*in.graph, args.get("output-" + side, args.get("output")));
    } else if (!isImageFile(path)) {
        throw UserError(path.string() + ": compare " + role + ": " + expected + ", got a '" + ext + "' file");
    }
    return in;
}

struct FrameRange {
    uint32_t first = 0;
    uint32_t last = 0;
    uint32_t still = 0; // the frame compared as a still image
    bool temporal = false;
};

uint32_t parseIndex(const std::string& text, const std::string& option, const std::string& expected) {
    if (text.empty() || text.size() > 6 || !std::all_of(text.begin(), text.end(), ::isdigit))
        throw UserError(option + ": expected " + expected + ", got '" + text + "'");
    return static_cast<uint32_t>(std::stoul(text));
}

// --frame N picks the still; --frames a:b renders a..b for temporal metrics (the still defaults to b). Without either
// the still is the last frame of the longest graph (graphFrames).
FrameRange frameRange(const Args& args, uint32_t graphFrames) {
    FrameRange r;
    if (args.has("frames")) {
        const std::string text = args.get("frames");
        const auto colon = text.find(':');
        const std::string expected = "FIRST:LAST frame indices with FIRST < LAST (e.g. 0:15)";
        if (colon == std::string::npos) throw UserError("--frames: expected " + expected + ", got '" + text + "'");
        r.first = parseIndex(text.substr(0, colon), "--frames", expected);
        r.last = parseIndex(text.substr(colon + 1), "--frames", expected);
        if (r.first >= r.last) throw UserError("--frames: expected " + expected + ", got '" + text + "'");
        r.temporal = true;
        r.still = r.last;
    } else {
        r.still = graphFrames - 1;
    }
    if (args.has("frame")) {
        r.still = parseIndex(args.get("frame"), "--frame", "a frame index");
        if (r.temporal && (r.still < r.first || r.still > r.last))
            throw UserError("--frame " + std::to_string(r.still) + ": expected a frame inside --frames " +
                            args.get("frames"));
    }
    if (!r.temporal) r.first = r.last = r.still;
    return r;
}

void requireSameSize(const Input& a, const Input& b) {
    if (a.still.width == b.still.width && a.still.height == b.still.height) return;
    auto describe = [](const Input& in) {
        return in.role + " " + in.path.string() + (in.graph ? " (output " + in.output + ")" : "") + " is " +
               std::to_string(in.still.width) + "x" + std::to_string(in.still.height);
    };
    throw UserError("compare: " + describe(a) + " but " + describe(b) +
                    "; expected the same size (for graphs, e.g. --set frame.width=W --set frame.height=H)");
}

void writeBytes(const fs::path& path, const std::vector<unsigned char>& bytes) {
    writeFileAtomically(path, std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()));
}

// Writes NAME.png (and NAME.exr with the float values when `exr`) and returns the PNG for the report.
compare::ReportImage writeImage(OutputDir& out, const std::string& name, const std::string& label, const Image& image,
                                bool exr) {
    compare::ReportImage r{label, encodePng(image), image.width, image.height};
    writeBytes(out.claim(name + ".png"), r.png);
    if (exr) writeExr(out.claim(name + ".exr"), image, ExrPixelType::Float);
    return r;
}

// The noise floor's second reference half: --reference-half FILE, or the reference graph with the seed of every
// render.pathtrace node moved on by one. Empty (with `reason` set) when there is none.
std::optional<Input> referenceHalf(const Input& reference, const Args& args, uint32_t frames,
                                   compare::NoiseFloor& floor) {
    if (args.has("no-noise-floor")) {
        floor.status = compare::NoiseFloor::Status::Skipped;
        floor.reason = "--no-noise-floor";
        return std::nullopt;
    }
    if (args.has("reference-half")) {
        Input half = openInput("reference half", "reference_half", args.get("reference-half"), args, frames);
        floor.reason = "--reference-half " + half.path.string();
        return half;
    }
    if (!reference.graph) {
        floor.reason = "the reference is an image file; pass --reference-half FILE, an independent render of it";
        return std::nullopt;
    }
    Input half = reference;
    half.role = "reference half";
    half.key = "reference_half";
    std::string changed;
    for (NodeDecl& node : half.graph->nodes) {
        // render.pathtrace and the ray-traced twins (reference.*, but for reference.substitute, which has no seed).
        if (!node.schema || !(node.schema->type == "render.pathtrace" ||
                              (node.schema->type.starts_with("reference.") && node.params.contains("seed"))))
            continue;
        const int64_t seed = node.params.value("seed", int64_t(0));
        const int64_t next = seed >= 2147483647 ? 0 : seed + 1; // the param's range is [0, 2^31 - 1]
        node.params["seed"] = next;
        half.graph->document["nodes"][node.id]["params"]["seed"] = next;
        changed += (changed.empty() ? "" : ", ") + node.id + ".params.seed " + std::to_string(seed) + " -> " +
                   std::to_string(next);
    }
    if (changed.empty()) {
        floor.reason = "the reference graph has no render.pathtrace or reference.* node to re-seed; pass "
                       "--reference-half FILE, an independent render of it";
        return std::nullopt;
    }
    floor.reason = "the reference graph with " + changed;
    return half;
}

// Mean Rec. 709 luminance of an image's linear values (what a.exr holds).
double meanLuminance(const Image& image) {
    double sum = 0.0;
    const size_t pixels = static_cast<size_t>(image.width) * image.height;
    for (size_t i = 0; i < pixels; ++i) {
        const float* p = image.pixels.data() + i * 4;
        sum += 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
    }
    return pixels > 0 ? sum / static_cast<double>(pixels) : 0.0;
}

std::string formatPsnr(double psnr) {
    char buffer[32];
    if (std::isfinite(psnr))
        std::snprintf(buffer, sizeof buffer, "%7.2f dB", psnr);
    else
        std::snprintf(buffer, sizeof buffer, "%10s", "identical");
    return buffer;
}

} // namespace

int compareCommand(const Args& args) {
    if (args.positional.size() != 2) throw UserError("compare: expected two inputs, A and B (graphs or images)");
    // --frame/--frames fix the frame count before the graphs are validated; without them each graph keeps its own.
    const uint32_t askedFrames = args.has("frame") || args.has("frames") ? frameRange(args, 1).last + 1 : 0;
    Input a = openInput("A", "a", args.positional[0], args, askedFrames);
    Input b = openInput("B", "b", args.positional[1], args, askedFrames);
    std::optional<Input> reference;
    if (args.has("reference"))
        reference = openInput("reference", "reference", args.get("reference"), args, askedFrames);
    std::vector<Input*> inputs = {&a, &b};
    if (reference) inputs.push_back(&*reference);
    if (!reference && (args.has("reference-half") || args.has("no-noise-floor")))
        throw UserError(std::string(args.has("reference-half") ? "--reference-half" : "--no-noise-floor") +
                        ": expected --reference R too (the noise floor is the reference's own noise)");
    std::optional<compare::NoiseFloor> noiseFloor;
    std::optional<Input> half;
    if (reference) {
        noiseFloor.emplace();
        half = referenceHalf(*reference, args, askedFrames, *noiseFloor);
    }
    // Rendered and compared as a still, never part of the temporal metrics.
    std::vector<Input*> rendered = inputs;
    if (half) rendered.push_back(&*half);

    uint32_t graphFrames = 1;
    for (const Input* in : rendered)
        if (in->graph) graphFrames = std::max(graphFrames, in->graph->frame.frames);
    const FrameRange range = frameRange(args, graphFrames);
    // --regions: read (and so refused, when wrong) before anything renders.
    std::optional<compare::RegionSet> regions;
    if (args.has("regions")) regions = compare::loadRegions(args.get("regions"));
    const bool hdr = args.has("hdr");
    double ppd = compare::kDefaultPixelsPerDegree;
    if (args.has("ppd")) {
        const std::string text = args.get("ppd");
        char* end = nullptr;
        ppd = std::strtod(text.c_str(), &end);
        if (text.empty() || *end != '\0' || !(ppd > 0.0) || !std::isfinite(ppd))
            throw UserError("--ppd: expected pixels per degree > 0, got '" + text + "'");
    }
    double diffScale = 1.0;
    if (args.has("diff-scale")) {
        const std::string text = args.get("diff-scale");
        char* end = nullptr;
        diffScale = std::strtod(text.c_str(), &end);
        if (text.empty() || *end != '\0' || !(diffScale > 0.0) || !std::isfinite(diffScale))
            throw UserError("--diff-scale: expected a number > 0, got '" + text + "'");
    }

    // Every file this run writes is checked before any rendering, so a refusal comes at once.
    std::vector<std::string> names = {"a.png",        "a.exr",        "b.png",        "b.exr",        "diff_a_b.png",
                                      "diff_a_b.exr", "flip_a_b.png", "flip_a_b.exr", "metrics.json", "report.html"};
    if (reference)
        names.insert(names.end(), {"reference.png", "reference.exr", "diff_a_reference.png", "diff_b_reference.png",
                                   "flip_a_reference.png", "flip_a_reference.exr", "flip_b_reference.png",
                                   "flip_b_reference.exr", "blocks_a_reference.png", "blocks_b_reference.png"});
    names.push_back("blocks_a_b.png");
    if (regions) names.push_back("regions.png");
    if (half)
        names.insert(names.end(), {"reference_half.png", "reference_half.exr", "flip_reference_half.png",
                                   "flip_reference_half.exr", "blocks_reference_half.png"});
    const std::string defaultOut =
        (fs::path("out") / "compare" / (a.path.stem().string() + "_vs_" + b.path.stem().string())).string();
    OutputDir out(args.get("out", defaultOut), args.has("force") || args.has("overwrite"));
    for (const std::string& name : names) {
        std::error_code ec;
        if (fs::exists(out.dir() / name, ec)) out.claim(name);
    }

    std::unique_ptr<Context> ctx;
    std::unique_ptr<ShaderCompiler> shaders;
    uint32_t frameCount = range.last + 1;
    for (const Input* in : rendered)
        if (in->graph) frameCount = std::max(frameCount, in->graph->frame.frames);
    std::vector<uint32_t> wanted;
    for (uint32_t f = range.first; f <= range.last; ++f)
        wanted.push_back(f);
    // Ctrl-C (handlers installed by the command line's main) stops the render in progress after its frame (a
    // converging path tracer keeps its partial result in the bake cache, so the next compare resumes it) and then the
    // comparison.
    for (Input* in : rendered) {
        if (in->graph) {
            if (!ctx) {
                ctx = std::make_unique<Context>(contextOptions(args));
                shaders = std::make_unique<ShaderCompiler>();
                logInfo("device: " + ctx->deviceInfo().name);
            }
            logInfo("rendering " + in->role + ": " + in->path.string() + " (output " + in->output + ", " +
                    std::to_string(frameCount) + " frame(s))");
            std::map<uint32_t, Image> frames =
                renderOutput(*ctx, *shaders, *in->graph, in->output, frameCount, wanted, !args.has("quiet"), nullptr,
                             [] { return InterruptHandlers::received() != 0; });
            if (int signal = InterruptHandlers::received()) {
                logWarning(std::string(signal == SIGINT ? "interrupted (SIGINT)" : "terminated (SIGTERM)") +
                           " while rendering " + in->role +
                           ": nothing compared (a converging path tracer kept what "
                           "it traced in the bake cache; the next compare resumes it)");
                return kExitInterrupted;
            }
            for (uint32_t f : wanted)
                in->frames.push_back(std::move(frames.at(f)));
        } else {
            // --output(-a/-b/-reference) NAME picks that layer of a multi-layer EXR (what `vitrine run` writes: one
            // layer per output).
            const std::string side = in->key == "reference_half" ? "reference" : in->key;
            const std::string layer = args.get("output-" + side, args.get("output"));
            Image image = !layer.empty() && lower(in->path.extension().string()) == ".exr"
                              ? loadExrLayer(in->path, layer)
                              : loadImage(in->path);
            in->frames.assign(wanted.size(), image);
        }
        in->still = in->frames[range.still - range.first];
    }
    requireSameSize(a, b);
    if (reference) requireSameSize(a, *reference);
    if (half) requireSameSize(*reference, *half);

    logInfo("computing metrics");
    compare::PairOptions pairOptions;
    pairOptions.hdr = hdr;
    pairOptions.pixelsPerDegree = ppd;
    compare::ReportInput report;
    report.title = a.path.stem().string() + " vs " + b.path.stem().string() +
                   (reference ? " (reference: " + reference->path.stem().string() + ")" : "");
    const std::string frameText = " [frame " + std::to_string(range.still) + "]";
    auto label = [&](const Input& in) {
        return in.role + ": " + in.path.string() + (in.graph ? " → " + in.output + frameText : "");
    };
    report.a = writeImage(out, "a", label(a), a.still, true);
    report.b = writeImage(out, "b", label(b), b.still, true);
    if (reference) report.reference = writeImage(out, "reference", label(*reference), reference->still, true);
    if (half) report.referenceHalf = writeImage(out, "reference_half", label(*half), half->still, true);

    const Image diff = compare::absoluteDifference(a.still, b.still);
    writeExr(out.claim("diff_a_b.exr"), diff, ExrPixelType::Float);
    char scaleText[32];
    std::snprintf(scaleText, sizeof scaleText, "%g", diffScale);
    report.differenceMaps.push_back(writeImage(out, "diff_a_b", std::string("|A − B| × ") + scaleText,
                                               compare::falseColor(diff, diffScale), false));

    struct PairJob {
        const Input* test;
        const Input* ref;
        std::string name;
    };
    // The noise floor first, so the pairs against the reference can be marked as they are computed.
    std::vector<PairJob> jobs;
    // --regions: each pair's rows, computed with its FLIP error map while that is at hand.
    std::vector<compare::RegionTable::Pair> regionPairs;
    std::optional<compare::RegionTable::Pair> halfRegions;
    if (half) jobs.push_back({&*half, &*reference, "reference_half"});
    jobs.push_back({&a, &b, "a_b"});
    if (reference) {
        jobs.push_back({&a, &*reference, "a_reference"});
        jobs.push_back({&b, &*reference, "b_reference"});
        for (const Input* in : {&a, &b})
            report.differenceMaps.push_back(writeImage(
                out, "diff_" + in->key + "_reference", "|" + in->role + " − reference| × " + scaleText,
                compare::falseColor(compare::absoluteDifference(in->still, reference->still), diffScale), false));
    }
    for (const PairJob& job : jobs) {
        compare::PairComparison pair =
            compare::comparePair(job.test->role, job.test->still, job.ref->role, job.ref->still, pairOptions);
        writeExr(out.claim("flip_" + job.name + ".exr"), pair.flipErrorMap, ExrPixelType::Float);
        if (regions) {
            compare::RegionTable::Pair rows{
                job.test->role, job.ref->role,
                compare::regionLuminanceRatios(*regions, job.test->still, job.ref->still, &pair.flipErrorMap)};
            if (half && job.test == &*half)
                halfRegions = std::move(rows);
            else
                regionPairs.push_back(std::move(rows));
        }
        report.flipMaps.push_back(
            writeImage(out, "flip_" + job.name,
                       std::string(hdr ? "HDR" : "LDR") + "-FLIP " + job.test->role + " vs " + job.ref->role,
                       compare::flipColorMap(pair.flipErrorMap), false));
        report.blockMaps.push_back(writeImage(
            out, "blocks_" + job.name,
            "log2 block luminance " + job.test->role + " / " + job.ref->role + " (" +
                std::to_string(compare::kBlockSize) + " px)",
            compare::blockRatioHeatMap(pair.blockRatio, job.test->still.width, job.test->still.height), false));
        if (half && job.test == &*half) {
            noiseFloor->status = compare::NoiseFloor::Status::Measured;
            noiseFloor->pair = pair.metrics;
            continue;
        }
        if (reference && job.ref == &*reference && noiseFloor->status == compare::NoiseFloor::Status::Measured)
            pair.metrics.withinReferenceNoise = noiseFloor->contains(pair.metrics.flip.mean);
        report.metrics.push_back(pair.metrics);
    }
    report.noiseFloor = noiseFloor;

    if (regions) {
        compare::RegionTable table;
        table.source = regions->source;
        table.description = regions->description;
        const Input& base = reference ? *reference : b;
        table.overlay = writeImage(out, "regions", "regions of " + regions->source + " over " + base.role,
                                   compare::regionOverlay(*regions, base.still), false);
        // The noise floor's pair last: each region's FLIP between the reference's halves, beside the others'.
        table.pairs = std::move(regionPairs);
        if (halfRegions) table.pairs.push_back(std::move(*halfRegions));
        report.regions = std::move(table);
    }

    if (range.temporal) {
        for (const Input* in : inputs) {
            compare::TemporalMetrics t;
            t.label = in->role;
            t.frameCount = static_cast<int>(in->frames.size());
            t.flicker = compare::flicker(in->frames);
            t.errorMetric = compare::FrameMetric::FlipMean;
            if (reference && in != &*reference)
                t.errorPerFrame = compare::errorPerFrame(in->frames, reference->frames, t.errorMetric);
            report.temporal.push_back(std::move(t));
        }
    }
    if (a.graph) report.graphA = a.graph->document;
    if (b.graph) report.graphB = b.graph->document;

    writeFileAtomically(out.claim("metrics.json"), compare::metricsJson(report).dump(2) + "\n");
    compare::writeReport(out.claim("report.html"), report);

    // --no-summary: nothing on stdout (the Python module's vitrine.compare returns metrics.json instead).
    if (!args.has("no-summary")) {
        for (const compare::PairMetrics& m : report.metrics)
            std::printf("%-3s vs %-10s PSNR %s   SSIM %.4f   FLIP mean %.4f (weighted median %.4f)   blocks within "
                        "15%% %5.1f%%, mean |log2| %.3f%s\n",
                        m.test.c_str(), m.reference.c_str(), formatPsnr(m.psnr).c_str(), m.ssim, m.flip.mean,
                        m.flip.weightedMedian, 100.0 * m.blocks.withinShare, m.blocks.meanAbsLog2,
                        !m.withinReferenceNoise   ? ""
                        : *m.withinReferenceNoise ? "   within reference noise"
                                                  : "   beyond reference noise");
        if (report.regions) {
            std::printf("%-22s %8s", "region", "pixels");
            for (const auto& p : report.regions->pairs)
                std::printf("  %18s", (p.test + "/" + (p.reference == "reference" ? "R" : p.reference)).c_str());
            std::printf("   (mean luminance ratio, FLIP mean)\n");
            for (size_t r = 0; r < regions->regions.size(); ++r) {
                std::printf("%-22s %8d", regions->regions[r].name.c_str(), report.regions->pairs.front().regions[r].pixels);
                for (const auto& p : report.regions->pairs)
                    std::printf("  %10.3f, %6.4f", p.regions[r].ratio, p.regions[r].flip);
                std::printf("\n");
            }
        }
        // Whole-frame brightness: which side is darker, and by how much (one term against its twin, a frame against R).
        std::printf("mean luminance: A %.6g, B %.6g", meanLuminance(a.still), meanLuminance(b.still));
        if (reference) std::printf(", reference %.6g", meanLuminance(reference->still));
        const double lumB = meanLuminance(b.still);
        std::printf("; A / B %.4f", lumB > 0.0 ? meanLuminance(a.still) / lumB : 0.0);
        if (reference) {
            const double lumR = meanLuminance(reference->still);
            std::printf(", A / reference %.4f, B / reference %.4f", lumR > 0.0 ? meanLuminance(a.still) / lumR : 0.0,
                        lumR > 0.0 ? lumB / lumR : 0.0);
        }
        std::printf("\n");
        if (noiseFloor) {
            if (noiseFloor->status == compare::NoiseFloor::Status::Measured)
                std::printf("noise floor: FLIP mean %.4f between the reference and its other half (%s); blocks "
                            "within 15%% %5.1f%%, mean |log2| %.3f; pairs with FLIP mean <= %.4f are within reference "
                            "noise\n",
                            noiseFloor->pair->flip.mean, noiseFloor->reason.c_str(),
                            100.0 * noiseFloor->pair->blocks.withinShare, noiseFloor->pair->blocks.meanAbsLog2,
                            noiseFloor->factor * noiseFloor->pair->flip.mean);
            else
                std::printf("noise floor: %s (%s)\n",
                            noiseFloor->status == compare::NoiseFloor::Status::Skipped ? "skipped" : "unknown",
                            noiseFloor->reason.c_str());
        }
        for (const compare::TemporalMetrics& t : report.temporal)
            std::printf("%-9s flicker %.5f over %d frames\n", t.label.c_str(), t.flicker, t.frameCount);
        std::printf("wrote %s\n", (out.dir() / "report.html").string().c_str());
    }
    if (ctx && ctx->validationMessageCount() > 0) {
        logWarning(std::to_string(ctx->validationMessageCount()) + " Vulkan validation message(s)");
        return 2;
    }
    return 0;
}

} // namespace vitrine::cli
