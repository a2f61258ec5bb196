// `vitrine compare` and `vitrine golden` as a user runs them: the real binary, real graphs, on the Vulkan device the
// machine has (lavapipe in CI), at small sizes. Checks outcomes a user relies on (FXAA scores better against the
// supersampled ground truth, the report exists and parses, bad input exits 1 naming the file, a perturbed render
// fails the golden check), not numbers the code under test produced.
#include "core/image/io.hpp"
#include "tests/gpu/cli.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <sys/wait.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace vitrine::test {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

const std::string kSource = VITRINE_SOURCE_DIR;
const std::string kSmall = "--set frame.width=160 --set frame.height=90";

const json* findPair(const json& metrics, const std::string& test, const std::string& reference) {
    for (const json& p : metrics["pairs"])
        if (p["test"] == test && p["reference"] == reference) return &p;
    return nullptr;
}

Image flat(int w, int h, float v) {
    Image image(w, h);
    for (size_t i = 0; i < image.pixels.size(); ++i)
        image.pixels[i] = i % 4 == 3 ? 1.0f : v;
    return image;
}

TEST(CompareCli, FxaaBeatsNoAaAgainstTheSupersampledReference) {
    const fs::path out = freshDir("compare_fxaa");
    const CliResult r = vitrine("compare " + quote(kSource + "/graphs/fxaa_zoneplate.json") + " " +
                                quote(kSource + "/graphs/variants/no_fxaa.json") + " --reference " +
                                quote(kSource + "/graphs/variants/supersampled.json") + " " + kSmall +
                                " --validate --quiet --out " + quote(out.string()));
    ASSERT_EQ(r.status, 0) << r.output;
    const json metrics = json::parse(readFile(out / "metrics.json"));
    const json* fxaa = findPair(metrics, "A", "reference");
    const json* none = findPair(metrics, "B", "reference");
    ASSERT_TRUE(fxaa && none) << metrics.dump(2);
    std::printf("vs supersampled: FXAA PSNR %.3f FLIP %.4f; no AA PSNR %.3f FLIP %.4f\n", (*fxaa)["psnr"].get<double>(),
                (*fxaa)["flip"]["mean"].get<double>(), (*none)["psnr"].get<double>(),
                (*none)["flip"]["mean"].get<double>());
    EXPECT_LT((*fxaa)["flip"]["mean"].get<double>(), (*none)["flip"]["mean"].get<double>());
    EXPECT_GT((*fxaa)["psnr"].get<double>(), (*none)["psnr"].get<double>());
    EXPECT_EQ(metrics["images"]["a"]["width"], 160);
    EXPECT_EQ(metrics["images"]["reference"]["height"], 90);
    // The variant differs from its base where it removes the fxaa node and rewires the tone mapper.
    bool removedFxaa = false;
    for (const json& c : metrics["graphChanges"])
        removedFxaa |= c["op"] == "removed" && c["pointer"] == "/nodes/fxaa";
    EXPECT_TRUE(removedFxaa) << metrics["graphChanges"].dump(2);

    const std::string html = readFile(out / "report.html");
    EXPECT_NE(html.find("<html"), std::string::npos);
    EXPECT_NE(html.find("data:image/png;base64,"), std::string::npos);
    // Self-contained: nothing is fetched from the network.
    EXPECT_EQ(html.find("src=\"http"), std::string::npos);
    EXPECT_EQ(html.find("href=\"http"), std::string::npos);
    for (const char* file : {"a.png", "b.png", "reference.png", "diff_a_b.exr", "flip_a_b.png", "flip_a_reference.exr"})
        EXPECT_TRUE(fs::is_regular_file(out / file)) << file;
    // The written images are the renders: A's EXR is 160x90.
    EXPECT_EQ(loadExrLayer(out / "a.exr", "").width, 160);
}

TEST(CompareCli, FramesRangeAddsTemporalMetrics) {
    const fs::path out = freshDir("compare_frames");
    const CliResult r =
        vitrine("compare " + quote(kSource + "/graphs/fxaa_zoneplate.json") + " " +
                quote(kSource + "/graphs/variants/no_fxaa.json") + " --reference " +
                quote(kSource + "/graphs/variants/no_fxaa.json") +
                " --set frame.width=48 --set frame.height=32 --frames 1:3 --validate --quiet --out " + quote(out.string()));
    ASSERT_EQ(r.status, 0) << r.output;
    const json metrics = json::parse(readFile(out / "metrics.json"));
    ASSERT_EQ(metrics["temporal"].size(), 3u);
    for (const json& t : metrics["temporal"]) {
        EXPECT_EQ(t["frames"], 3);
        // The zone plate does not move: a still image has no flicker.
        EXPECT_EQ(t["flicker"], 0.0) << t["label"];
    }
    const json& b = metrics["temporal"][1];
    ASSERT_EQ(b["label"], "B");
    ASSERT_EQ(b["errorPerFrame"]["values"].size(), 3u);
    // B and the reference are the same graph: zero FLIP error in every frame.
    for (const json& v : b["errorPerFrame"]["values"])
        EXPECT_EQ(v, 0.0);
    EXPECT_GT(metrics["temporal"][0]["errorPerFrame"]["values"][0].get<double>(), 0.0);
}

// --output-a / --output-b pick each side's output (one term of a frame against its twin's): a graph with two flat
// outputs (checkers whose two colours are equal) compared with itself, A from `dark` and B from `bright`. a.exr and
// b.exr hold those values, the mean luminance line gives their ratio, and a name the graph lacks exits 1 naming it.
TEST(CompareCli, OutputPerSidePicksEachSidesOutput) {
    const fs::path out = freshDir("compare_output_per_side");
    auto flatChecker = [](double v) {
        return json{{"type", "pattern.checker"},
                    {"params", {{"color_a", {v, v, v, 1.0}}, {"color_b", {v, v, v, 1.0}}}}};
    };
    const json graph = {{"format", "vitrine-graph/1"},
                        {"frame", {{"width", 32}, {"height", 16}}},
                        {"nodes", {{"dark", flatChecker(0.25)}, {"bright", flatChecker(0.5)}}},
                        {"outputs", {{"final", "bright.color"}, {"terms/dark", "dark.color"}, {"terms/bright", "bright.color"}}}};
    const fs::path file = out / "two_outputs.json";
    std::ofstream(file) << graph.dump(2);
    const CliResult r = vitrine("compare " + quote(file.string()) + " " + quote(file.string()) +
                                " --output-a terms/dark --output-b terms/bright --hdr --quiet --out " +
                                quote((out / "report").string()));
    ASSERT_EQ(r.status, 0) << r.output;
    const Image a = loadImage(out / "report" / "a.exr"), b = loadImage(out / "report" / "b.exr");
    ASSERT_EQ(a.width, 32);
    EXPECT_NEAR(a.at(5, 5)[1], 0.25f, 1e-3f);
    EXPECT_NEAR(b.at(5, 5)[1], 0.5f, 1e-3f);
    EXPECT_NE(r.output.find("A / B 0.5000"), std::string::npos) << r.output;
    // Without --output-b, B falls back to --output (here: none, so "final", the bright checker).
    const CliResult fallback = vitrine("compare " + quote(file.string()) + " " + quote(file.string()) +
                                       " --output-a terms/dark --hdr --quiet --out " +
                                       quote((out / "fallback").string()));
    ASSERT_EQ(fallback.status, 0) << fallback.output;
    EXPECT_NEAR(loadImage(out / "fallback" / "b.exr").at(5, 5)[1], 0.5f, 1e-3f);
    const CliResult missing = vitrine("compare " + quote(file.string()) + " " + quote(file.string()) +
                                      " --output-b terms/nothing --quiet --out " + quote((out / "missing").string()));
    EXPECT_EQ(missing.status, 1) << missing.output;
    EXPECT_NE(missing.output.find("terms/nothing"), std::string::npos) << missing.output;
}

TEST(CompareCli, ImagesOfDifferentSizesAreAUserError) {
    const fs::path dir = freshDir("compare_sizes");
    writeExr(dir / "small.exr", flat(16, 9, 0.5f), ExrPixelType::Float);
    writeExr(dir / "large.exr", flat(32, 18, 0.5f), ExrPixelType::Float);
    const CliResult r = vitrine("compare " + quote((dir / "small.exr").string()) + " " +
                                quote((dir / "large.exr").string()) + " --validate --out " + quote((dir / "out").string()));
    EXPECT_EQ(r.status, 1) << r.output;
    EXPECT_NE(r.output.find("small.exr"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("large.exr"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("16x9"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("same size"), std::string::npos) << r.output;

    // A graph rendered at 160x90 against a 16x9 image.
    const CliResult g =
        vitrine("compare " + quote(kSource + "/graphs/variants/no_fxaa.json") + " " +
                quote((dir / "small.exr").string()) + " " + kSmall + " --validate --quiet --out " + quote((dir / "out").string()));
    EXPECT_EQ(g.status, 1) << g.output;
    EXPECT_NE(g.output.find("160x90"), std::string::npos) << g.output;
    EXPECT_NE(g.output.find("small.exr"), std::string::npos) << g.output;
}

TEST(CompareCli, MissingAndNonImageFilesAreUserErrorsNamingTheFile) {
    const fs::path dir = freshDir("compare_bad_files");
    writeExr(dir / "ok.exr", flat(8, 8, 0.25f), ExrPixelType::Float);
    std::ofstream(dir / "notes.txt") << "not an image\n";
    std::ofstream(dir / "fake.png") << "not a PNG either\n";
    const std::string ok = quote((dir / "ok.exr").string()), outDir = " --out " + quote((dir / "out").string());
    struct Case {
        std::string args;
        std::string file;
    };
    for (const Case& c : {Case{ok + " " + quote((dir / "missing.exr").string()), "missing.exr"},
                          Case{quote((dir / "notes.txt").string()) + " " + ok, "notes.txt"},
                          Case{ok + " " + ok + " --reference " + quote((dir / "fake.png").string()), "fake.png"},
                          Case{ok + " " + quote((dir / "nope.json").string()), "nope.json"}}) {
        const CliResult r = vitrine("compare " + c.args + outDir);
        EXPECT_EQ(r.status, 1) << c.file << ": " << r.output;
        EXPECT_NE(r.output.find(c.file), std::string::npos) << r.output;
        EXPECT_EQ(r.output.find("internal error"), std::string::npos) << r.output;
    }
}

TEST(CompareCli, DoesNotOverwriteFilesItDidNotWriteUnlessForced) {
    const fs::path dir = freshDir("compare_overwrite");
    writeExr(dir / "x.exr", flat(8, 8, 0.25f), ExrPixelType::Float);
    writeExr(dir / "y.exr", flat(8, 8, 0.75f), ExrPixelType::Float);
    fs::create_directories(dir / "out");
    std::ofstream(dir / "out" / "report.html") << "mine";
    const std::string args = "compare " + quote((dir / "x.exr").string()) + " " + quote((dir / "y.exr").string()) +
                             " --out " + quote((dir / "out").string());
    const CliResult refused = vitrine(args);
    EXPECT_EQ(refused.status, 1) << refused.output;
    EXPECT_NE(refused.output.find("--force"), std::string::npos) << refused.output;
    EXPECT_EQ(readFile(dir / "out" / "report.html"), "mine");
    EXPECT_FALSE(fs::exists(dir / "out" / "a.png"));

    const CliResult forced = vitrine(args + " --force");
    ASSERT_EQ(forced.status, 0) << forced.output;
    EXPECT_NE(readFile(dir / "out" / "report.html"), "mine");
    // What vitrine wrote itself it may replace on the next run without being told.
    EXPECT_EQ(vitrine(args).status, 0);
}

TEST(GoldenCli, PerturbedRenderFailsTheCheckAndWritesAReport) {
    const fs::path out = freshDir("golden_perturbed");
    // A slightly higher zone-plate frequency moves every ring.
    const CliResult r = vitrine("golden check fxaa_zoneplate --set pattern.params.max_frequency=0.32 --validate --quiet "
                                "--skip-missing --out " + quote(out.string()));
    // Only a device class that never had goldens (the manifest marks it skipIfMissing) may skip; lavapipe never does.
    if (r.status == 77 && r.output.find("class lavapipe") == std::string::npos) GTEST_SKIP() << r.output;
    EXPECT_EQ(r.status, 3) << r.output;
    EXPECT_NE(r.output.find("FAIL fxaa_zoneplate"), std::string::npos) << r.output;
    EXPECT_TRUE(fs::is_regular_file(out / "fxaa_zoneplate" / "report.html"));
    EXPECT_TRUE(fs::is_regular_file(out / "fxaa_zoneplate" / "flip.png"));
    const json metrics = json::parse(readFile(out / "fxaa_zoneplate" / "metrics.json"));
    EXPECT_GT(metrics["pairs"][0]["flip"]["mean"].get<double>(), 0.002);
}

// The block-luminance bound catches a small shift of brightness that loose per-pixel bounds let through; --keep writes
// the render that --from reads back; a tolerance class meant for another device class skips (77).
TEST(GoldenCli, BlockLuminanceKeepFromAndClass) {
    const fs::path dir = freshDir("golden_blocks");
    const json loose = {{"flipMean", 1.0}, {"percentile", 99}, {"flipPercentile", 1.0}, {"meanAbsDiff", 1.0},
                        {"blockSize", 16}, {"blockLuminance", 0.01}};
    json manifest = {{"format", "vitrine-golden/1"},
                     {"tolerances", {{"lavapipe", loose}, {"gpu", loose}, {"elsewhere", loose}}},
                     {"images", {{"zp", {{"graph", kSource + "/graphs/fxaa_zoneplate.json"},
                                         {"set", {"frame.width=64", "frame.height=36"}}}}}}};
    manifest["tolerances"]["elsewhere"]["appliesTo"] = "no-such-class";
    std::ofstream(dir / "manifest.json") << manifest.dump(2);
    const std::string m = " --manifest " + quote((dir / "manifest.json").string()) + " --quiet --force";
    ASSERT_EQ(vitrine("golden accept" + m).status, 0);

    const CliResult same = vitrine("golden check" + m + " --keep " + quote((dir / "kept").string()) + " --out " +
                                   quote((dir / "r0").string()));
    EXPECT_EQ(same.status, 0) << same.output;
    EXPECT_NE(same.output.find("16px blocks' luminance 0.0000"), std::string::npos) << same.output;
    EXPECT_TRUE(fs::is_regular_file(dir / "kept" / "zp.exr"));

    // 0.05 EV brighter: +3.5 % everywhere. Every per-pixel bound is 1; only the blocks see it.
    const CliResult brighter = vitrine("golden check" + m + " --set tonemap.params.exposure=0.05 --keep " +
                                       quote((dir / "bright").string()) + " --out " + quote((dir / "r1").string()));
    EXPECT_EQ(brighter.status, 3) << brighter.output;
    EXPECT_NE(brighter.output.find("FAIL zp"), std::string::npos) << brighter.output;

    // --from compares the kept render without rendering: the same verdict.
    const CliResult from = vitrine("golden check" + m + " --from " + quote((dir / "bright").string()) + " --out " +
                                   quote((dir / "r2").string()));
    EXPECT_EQ(from.status, 3) << from.output;
    const CliResult fromSame = vitrine("golden check" + m + " --from " + quote((dir / "kept").string()) + " --out " +
                                       quote((dir / "r3").string()));
    EXPECT_EQ(fromSame.status, 0) << fromSame.output;

    // --goldens DIR: the kept brighter render as the golden makes the brighter render pass.
    const CliResult goldens = vitrine("golden check" + m + " --set tonemap.params.exposure=0.05 --goldens " +
                                      quote((dir / "bright").string()) + " --out " + quote((dir / "r4").string()));
    EXPECT_EQ(goldens.status, 0) << goldens.output;

    // A class whose tolerances apply to another device class is skipped, loudly.
    const CliResult other = vitrine("golden check" + m + " --skip-missing --class elsewhere --out " +
                                     quote((dir / "r5").string()));
    EXPECT_EQ(other.status, 77) << other.output;
    EXPECT_NE(other.output.find("SKIPPED, NOT CHECKED"), std::string::npos) << other.output;
}

} // namespace
} // namespace vitrine::test
