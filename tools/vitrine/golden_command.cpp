// `vitrine golden check|accept [NAME]...`: the image-regression harness of the project's own tests. The manifest
// (tests/golden/manifest.json) lists graphs to render and the FLIP tolerances per device class; golden images live
// beside it in <device class>/<name>.exr. `accept` renders and (re)writes goldens, `check` renders and compares, and
// on failure writes the images, a FLIP heat map and a report.html per failing image into --out.
#include "core/base/atomic_file.hpp"
#include "core/base/error.hpp"
#include "core/base/log.hpp"
#include "core/compare/report.hpp"
#include "core/graph/loader.hpp"
#include "core/image/io.hpp"
#include "tools/vitrine/cli.hpp"
#include "tools/vitrine/output_dir.hpp"
#include "tools/vitrine/render_output.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>

namespace vitrine::cli {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

struct Tolerance {
    double flipMean = 0.0;       // the mean FLIP error may not exceed this
    double percentile = 99.0;    // which per-pixel percentile is bounded ...
    double flipPercentile = 0.0; // ... and by how much
    double meanAbsDiff = 1.0;    // mean |rendered - golden| over RGB: catches small systematic shifts FLIP forgives
    // Block luminance: the image is cut into blockSize x blockSize blocks (0: off) and no block's mean luminance may
    // differ from the golden's by more than blockLuminance, relative (|a - g| / max(g, blockFloor)). Another CPU's
    // code generation moves Monte Carlo paths of the bake and so single pixels (zero-mean noise FLIP sees), while a
    // shading bug moves whole regions: this bound stays tight where the per-pixel ones must leave room for noise.
    int blockSize = 0;
    double blockLuminance = 1.0;
    double blockFloor = 0.01;
};

struct GoldenCase {
    std::string name;
    fs::path graph;
    std::vector<std::string> sets;
    std::string output; // empty: the graph's first output
    Tolerance tolerance;
};

struct Manifest {
    fs::path file;
    fs::path directory;
    std::vector<GoldenCase> cases;
    // The device class may have no goldens yet (nobody could accept them on such a device): `check --skip-missing`
    // then skips loudly instead of failing. Never set for lavapipe, whose goldens are in the tree.
    bool skipIfMissing = false;
    // A tolerance class meant for one device class only (e.g. "lavapipe-codegen": two code generations of llvmpipe);
    // empty: any.
    std::string appliesTo;
};

double number(const json& object, const std::string& key, const std::string& where, double min, double max) {
    auto it = object.find(key);
    if (it == object.end() || !it->is_number() || it->get<double>() < min || it->get<double>() > max)
        throw UserError(where + "/" + key + ": expected a number in [" + std::to_string(min) + ", " +
                        std::to_string(max) + "]");
    return it->get<double>();
}

Tolerance readTolerance(const json& t, const std::string& where, Tolerance base) {
    if (!t.is_object()) throw UserError(where + ": expected an object {flipMean, percentile, flipPercentile}");
    for (const auto& [key, value] : t.items())
        if (key != "flipMean" && key != "percentile" && key != "flipPercentile" && key != "meanAbsDiff" &&
            key != "blockSize" && key != "blockLuminance" && key != "blockFloor" && key != "skipIfMissing" &&
            key != "measured" && key != "appliesTo")
            throw UserError(where + "/" + key +
                            ": unknown key; expected flipMean, percentile, flipPercentile, meanAbsDiff, blockSize, "
                            "blockLuminance, blockFloor, measured, appliesTo or skipIfMissing");
    if (t.contains("flipMean")) base.flipMean = number(t, "flipMean", where, 0.0, 1.0);
    if (t.contains("percentile")) base.percentile = number(t, "percentile", where, 0.0, 100.0);
    if (t.contains("flipPercentile")) base.flipPercentile = number(t, "flipPercentile", where, 0.0, 1.0);
    if (t.contains("meanAbsDiff")) base.meanAbsDiff = number(t, "meanAbsDiff", where, 0.0, 1e30);
    if (t.contains("blockSize")) base.blockSize = static_cast<int>(number(t, "blockSize", where, 0.0, 4096.0));
    if (t.contains("blockLuminance")) base.blockLuminance = number(t, "blockLuminance", where, 0.0, 1e30);
    if (t.contains("blockFloor")) base.blockFloor = number(t, "blockFloor", where, 1e-9, 1e30);
    // "measured": free text (or an object) recording the spread the bounds were derived from; not read.
    return base;
}

Manifest readManifest(const fs::path& file, const std::string& deviceClass) {
    std::ifstream in(file);
    if (!in) throw UserError(file.string() + ": cannot read the golden manifest");
    json doc;
    try {
        doc = json::parse(in);
    } catch (const json::parse_error& e) {
        throw UserError(file.string() + ": JSON syntax error: " + e.what());
    }
    const std::string f = file.string() + ": ";
    if (doc.value("format", "") != "vitrine-golden/1") throw UserError(f + "/format: expected \"vitrine-golden/1\"");
    if (!doc.contains("tolerances") || !doc["tolerances"].contains(deviceClass))
        throw UserError(f + "/tolerances/" + deviceClass + ": expected the tolerances of this device class");
    const Tolerance base = readTolerance(doc["tolerances"][deviceClass], f + "/tolerances/" + deviceClass, {});
    if (!doc.contains("images") || !doc["images"].is_object() || doc["images"].empty())
        throw UserError(f + "/images: expected an object of golden images by name");

    Manifest m{file, file.parent_path(), {}, false};
    if (const json& t = doc["tolerances"][deviceClass]; t.contains("skipIfMissing")) {
        if (!t["skipIfMissing"].is_boolean())
            throw UserError(f + "/tolerances/" + deviceClass + "/skipIfMissing: expected true or false");
        m.skipIfMissing = t["skipIfMissing"].get<bool>();
    }
    if (const json& t = doc["tolerances"][deviceClass]; t.contains("appliesTo")) {
        if (!t["appliesTo"].is_string())
            throw UserError(f + "/tolerances/" + deviceClass + "/appliesTo: expected a device class name");
        m.appliesTo = t["appliesTo"].get<std::string>();
    }
    for (const auto& [name, entry] : doc["images"].items()) {
        const std::string where = f + "/images/" + name;
        if (!entry.is_object() || !entry.contains("graph") || !entry["graph"].is_string())
            throw UserError(where + ": expected {\"graph\": path relative to the manifest, \"set\": [...], "
                                    "\"output\": name, \"tolerance\": {...}}");
        GoldenCase c{name, m.directory / entry["graph"].get<std::string>(), {}, entry.value("output", ""), base};
        if (entry.contains("set")) {
            if (!entry["set"].is_array()) throw UserError(where + "/set: expected an array of \"key=value\" strings");
            for (const json& s : entry["set"]) {
                if (!s.is_string()) throw UserError(where + "/set: expected an array of \"key=value\" strings");
                c.sets.push_back(s.get<std::string>());
            }
        }
        if (entry.contains("tolerance") && entry["tolerance"].contains(deviceClass))
            c.tolerance = readTolerance(entry["tolerance"][deviceClass], where + "/tolerance/" + deviceClass, base);
        m.cases.push_back(std::move(c));
    }
    return m;
}

double meanAbsDifference(const Image& a, const Image& b) {
    double sum = 0.0;
    for (size_t i = 0; i < a.pixels.size(); ++i)
        if (i % 4 != 3) sum += std::fabs(static_cast<double>(a.pixels[i]) - b.pixels[i]);
    return sum / (3.0 * static_cast<double>(a.pixels.size() / 4));
}

// The largest relative difference of mean Rec. 709 luminance over blockSize x blockSize blocks (the last row and column
// of blocks may be smaller): |a - g| / max(g, floor).
double worstBlockLuminance(const Image& a, const Image& g, int blockSize, double floor) {
    if (blockSize <= 0) return 0.0;
    double worst = 0.0;
    for (int by = 0; by < a.height; by += blockSize)
        for (int bx = 0; bx < a.width; bx += blockSize) {
            double la = 0.0, lg = 0.0;
            int n = 0;
            for (int y = by; y < std::min(by + blockSize, a.height); ++y)
                for (int x = bx; x < std::min(bx + blockSize, a.width); ++x, ++n) {
                    const float* p = a.at(x, y);
                    const float* q = g.at(x, y);
                    la += 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
                    lg += 0.2126 * q[0] + 0.7152 * q[1] + 0.0722 * q[2];
                }
            la /= n;
            lg /= n;
            worst = std::max(worst, std::fabs(la - lg) / std::max(lg, floor));
        }
    return worst;
}

// The plain (unweighted) p-th percentile of the per-pixel errors: the smallest error that at least p % of the pixels
// do not exceed.
double percentileOf(const Image& errorMap, double p) {
    std::vector<float> values;
    for (size_t i = 0; i < errorMap.pixels.size(); i += 4)
        values.push_back(errorMap.pixels[i]);
    std::sort(values.begin(), values.end());
    const size_t rank = static_cast<size_t>(std::ceil(p / 100.0 * values.size()));
    return values[std::clamp<size_t>(rank, 1, values.size()) - 1];
}

// Writes what a developer needs to see why `name` failed: both images, the FLIP heat map and a report.html.
fs::path writeFailureReport(OutputDir& out, const GoldenCase& c, const Image& actual, const Image& golden,
                            const compare::PairComparison& pair) {
    auto image = [&](const std::string& file, const std::string& label, const Image& img) {
        compare::ReportImage r{label, encodePng(img), img.width, img.height};
        writeFileAtomically(out.claim(c.name + "/" + file),
                            std::string_view(reinterpret_cast<const char*>(r.png.data()), r.png.size()));
        return r;
    };
    compare::ReportInput report;
    report.title = "golden check failed: " + c.name;
    report.a = image("actual.png", "rendered now", actual);
    report.b = image("golden.png", "golden", golden);
    report.flipMaps.push_back(
        image("flip.png", "LDR-FLIP rendered vs golden", compare::flipColorMap(pair.flipErrorMap)));
    report.differenceMaps.push_back(image("diff.png", "|rendered − golden|",
                                          compare::falseColor(compare::absoluteDifference(actual, golden), 1.0)));
    report.metrics.push_back(pair.metrics);
    writeFileAtomically(out.claim(c.name + "/metrics.json"), compare::metricsJson(report).dump(2) + "\n");
    const fs::path html = out.claim(c.name + "/report.html");
    compare::writeReport(html, report);
    return html;
}

} // namespace

int goldenCommand(const Args& args) {
    const std::string usage = "golden: expected `golden check [NAME]...` or `golden accept [NAME]...`";
    if (args.positional.empty()) throw UserError(usage);
    const std::string action = args.positional[0];
    if (action != "check" && action != "accept") throw UserError(usage + ", got '" + action + "'");

    Context ctx(contextOptions(args));
    // --class NAME reads the tolerances of another class of the manifest (e.g. "lavapipe-codegen", the bounds between
    // two code generations of one CPU); the goldens stay the device class's unless --goldens names another folder.
    const std::string actualClass = deviceClass(ctx);
    const std::string deviceClassName = args.get("class", actualClass);
    const fs::path manifestFile = args.get("manifest", VITRINE_SOURCE_DIR "/tests/golden/manifest.json");
    Manifest manifest = readManifest(manifestFile, deviceClassName);
    std::vector<const GoldenCase*> selected;
    for (size_t i = 1; i < args.positional.size(); ++i) {
        auto it = std::find_if(manifest.cases.begin(), manifest.cases.end(),
                               [&](const GoldenCase& c) { return c.name == args.positional[i]; });
        if (it == manifest.cases.end())
            throw UserError(manifestFile.string() + ": /images: no golden image named '" + args.positional[i] + "'");
        selected.push_back(&*it);
    }
    if (selected.empty())
        for (const GoldenCase& c : manifest.cases)
            selected.push_back(&c);

    logInfo("device: " + ctx.deviceInfo().name + " (class " + actualClass + ", tolerances " + deviceClassName + ")");
    ShaderCompiler shaders;
    const fs::path goldenDir = args.has("goldens") ? fs::path(args.get("goldens", "")) : manifest.directory / actualClass;
    // --keep DIR: every image rendered by `check` is also written to DIR/<name>.exr, for a later `check --goldens DIR`
    // (the code-generation test compares another code generation's renders with these).
    const fs::path keepDir = args.get("keep", "");
    if (!keepDir.empty()) {
        std::error_code ec;
        fs::create_directories(keepDir, ec);
        if (ec) throw UserError(keepDir.string() + ": --keep: cannot create the folder: " + ec.message());
    }
    if (action == "check" && args.has("skip-missing") && !manifest.appliesTo.empty() &&
        manifest.appliesTo != actualClass) {
        const std::string message = "SKIPPED, NOT CHECKED: the tolerances " + deviceClassName + " apply to device class " +
                                    manifest.appliesTo + ", this device is " + actualClass;
        std::printf("%s\n", message.c_str());
        logWarning(message);
        return 77;
    }
    if (action == "check" && args.has("skip-missing") && manifest.skipIfMissing && !fs::is_directory(goldenDir)) {
        // For test harnesses: a device class that never had goldens is skipped, not failed, and says so loudly.
        const std::string message = "SKIPPED, NOT CHECKED: no goldens for device class " + deviceClassName + " in " +
                                    goldenDir.string() + "; run `vitrine golden accept` on this device";
        std::printf("%s\n", message.c_str());
        logWarning(message);
        return 77;
    }
    std::unique_ptr<OutputDir> reports;
    int failures = 0;
    for (const GoldenCase* c : selected) {
        std::vector<std::string> sets = c->sets;
        for (const std::string& s : args.all("set"))
            sets.push_back(s);
        const fs::path goldenFile = goldenDir / (c->name + ".exr");
        Image actual;
        if (args.has("from")) {
            // `check --from DIR`: DIR/<name>.exr (e.g. the goldens another machine or code generation accepted with
            // --manifest) stands for the render, so the spread between two sets of renders is measured without
            // rendering again.
            const fs::path file = fs::path(args.get("from", "")) / (c->name + ".exr");
            std::error_code ec;
            if (!fs::exists(file, ec))
                throw UserError(file.string() + ": --from: no image for '" + c->name + "'");
            actual = loadExrLayer(file, "");
        } else {
            GraphDesc desc = loadGraph(c->graph, sets);
            const std::string output = pickOutput(desc, c->output);
            const uint32_t frames = desc.frame.frames;
            actual = renderOutput(ctx, shaders, std::move(desc), output, frames, {frames - 1}, false).at(frames - 1);
        }

        if (!keepDir.empty() && !args.has("from")) writeExr(keepDir / (c->name + ".exr"), actual, ExrPixelType::Float);

        if (action == "accept") {
            std::error_code ec;
            fs::create_directories(goldenDir, ec);
            writeExr(goldenFile, actual, ExrPixelType::Float);
            std::printf("accepted %s -> %s (%dx%d)\n", c->name.c_str(), goldenFile.string().c_str(), actual.width,
                        actual.height);
            continue;
        }

        std::error_code ec;
        if (!fs::exists(goldenFile, ec))
            throw UserError(goldenFile.string() + ": no golden image for '" + c->name + "' on device class " +
                            deviceClassName + "; run `vitrine golden accept " + c->name + "` to create it");
        const Image golden = loadExrLayer(goldenFile, "");
        if (golden.width != actual.width || golden.height != actual.height) {
            std::printf("FAIL %s: rendered %dx%d, golden %s is %dx%d\n", c->name.c_str(), actual.width, actual.height,
                        goldenFile.string().c_str(), golden.width, golden.height);
            ++failures;
            continue;
        }
        const compare::PairComparison pair = compare::comparePair("rendered", actual, "golden", golden);
        const double mean = pair.metrics.flip.mean;
        const double pct = percentileOf(pair.flipErrorMap, c->tolerance.percentile);
        const double absDiff = meanAbsDifference(actual, golden);
        const Tolerance& t = c->tolerance;
        const double block = worstBlockLuminance(actual, golden, t.blockSize, t.blockFloor);
        const bool pass = mean <= t.flipMean && pct <= t.flipPercentile && absDiff <= t.meanAbsDiff &&
                          block <= t.blockLuminance;
        std::printf("%s %s: FLIP mean %.6f (max %.6f), p%g %.6f (max %.6f), mean |diff| %.3g (max %.3g)",
                    pass ? "ok  " : "FAIL", c->name.c_str(), mean, t.flipMean, t.percentile, pct, t.flipPercentile,
                    absDiff, t.meanAbsDiff);
        if (t.blockSize > 0)
            std::printf(", %dpx blocks' luminance %.4f (max %.4f)", t.blockSize, block, t.blockLuminance);
        std::printf("\n");
        if (pass) continue;
        ++failures;
        if (!reports)
            reports = std::make_unique<OutputDir>(args.get("out", "golden-report"),
                                                  args.has("force") || args.has("overwrite"));
        std::printf("     report: %s\n", writeFailureReport(*reports, *c, actual, golden, pair).string().c_str());
    }
    if (ctx.validationMessageCount() > 0) {
        logWarning(std::to_string(ctx.validationMessageCount()) + " Vulkan validation message(s)");
        return 2;
    }
    if (failures > 0) {
        std::printf("%d of %zu golden image(s) differ beyond the %s tolerances\n", failures, selected.size(),
                    deviceClassName.c_str());
        return 3;
    }
    return 0;
}

} // namespace vitrine::cli
