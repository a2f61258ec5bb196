// Comparisons that know their noise (issue #25, item 3): two independently seeded renders of one small path-traced
// scene differ a lot pixel by pixel (FLIP) and hardly at all per 16 px block; `vitrine compare --reference` renders the
// reference's second half itself, reports the noise floor and marks a pair that is only noise as within it. The scene
// is built here (a sphere on a floor in a box open to the sky, under the procedural sky's sun), written as .glb and
// traced by render.pathtrace through the real graph.
#include "core/compare/blocks.hpp"
#include "core/compare/metrics.hpp"
#include "core/image/io.hpp"
#include "tests/gpu/cli.hpp"
#include "tests/gpu/lighting_scene.hpp"

#include <cstdio>
#include <fstream>

namespace vitrine::test {
namespace {

using nlohmann::json;
using namespace lighting;

class CompareNoise : public GpuTest {};

constexpr int kW = 96, kH = 64;

std::filesystem::path noiseScene() {
    SceneBuilder b("compare_noise");
    std::vector<Tri> floor, wall;
    addQuad(floor, {0.0f, -1.0f, 0.0f}, {3.0f, 0.0f, 0.0f}, {0.0f, 0.0f, 3.0f}, {0.0f, 1.0f, 0.0f});
    addQuad(wall, {0.0f, 0.5f, -2.0f}, {3.0f, 0.0f, 0.0f}, {0.0f, 1.5f, 0.0f}, {0.0f, 0.0f, 1.0f});
    b.node("floor", static_cast<int32_t>(b.mesh("floor", floor, b.material("floor", {0.7f, 0.6f, 0.5f}, 0.0f, 0.2f))));
    b.node("wall", static_cast<int32_t>(b.mesh("wall", wall, b.material("wall", {0.3f, 0.5f, 0.7f}, 0.0f, 0.3f))));
    b.node("sphere",
           static_cast<int32_t>(
               b.mesh("sphere", sphereTris(0.8f, 48, 24), b.material("sphere", {0.9f, 0.3f, 0.2f}, 0.0f, 0.6f))),
           {0.0f, -0.2f, 0.0f});
    b.camera({0.0f, 0.6f, 3.5f}, {0.0f, -0.2f, 0.0f}, 0.9f);
    b.sun({0.4f, 0.8f, 0.45f});
    return b.write();
}

// The scene path traced: `seed` picks the random sequence, `sunScale` the sun's strength.
json traceGraph(const std::filesystem::path& glb, int seed, double sunScale = 1.0) {
    json nodes = {
        {"scene", {{"type", "scene.gltf"}, {"params", {{"path", glb.string()}}}}},
        {"sky",
         {{"type", "sky.procedural"},
          {"in", {{"scene", "scene.scene"}}},
          {"params", {{"size", 16}, {"sun_in_cubemap", false}}}}},
        {"env_cdf", {{"type", "sky.env_cdf"}, {"in", {{"sky", "sky.cubemap"}}}}},
        {"pt",
         {{"type", "render.pathtrace"},
          {"in",
           {{"scene", "scene.scene"},
            {"camera", "scene.camera"},
            {"sky", "sky.cubemap"},
            {"sky_sh", "sky.sh"},
            {"env_cdf", "env_cdf.cdf"}}},
          {"params", {{"spp", 4}, {"max_bounces", 3}, {"seed", seed}, {"sun_scale", sunScale}, {"report", false}}}}}};
    return graph(nodes, {{"color", "pt.color"}}, kW, kH);
}

// Two seeds of the same reference: per-pixel HDR-FLIP is large (it sees the Monte Carlo noise), the blocks agree within
// 5 % on average (mean |ratio - 1|), at least 5x less than FLIP and than the per-pixel relative difference. The block figures are checked against a plain CPU computation of block means.
TEST_F(CompareNoise, TwoSeedsDifferPerPixelButNotPerBlock) {
    const auto glb = noiseScene();
    const Image first = runGraph(traceGraph(glb, 0)).at("color");
    const Image second = runGraph(traceGraph(glb, 1)).at("color");
    ASSERT_EQ(first.width, kW);
    const double flip = compare::hdrFlip(first, second).mean;
    const compare::BlockRatioResult blocks = compare::blockLuminanceRatio(second, first);

    // The same figure from block means summed here.
    double sumRelative = 0.0;
    int lit = 0;
    for (int by = 0; by < kH / 16; ++by)
        for (int bx = 0; bx < kW / 16; ++bx) {
            double la = 0.0, lb = 0.0;
            for (int y = by * 16; y < by * 16 + 16; ++y)
                for (int x = bx * 16; x < bx * 16 + 16; ++x) {
                    const float* p = first.at(x, y);
                    const float* q = second.at(x, y);
                    la += 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
                    lb += 0.2126 * q[0] + 0.7152 * q[1] + 0.0722 * q[2];
                }
            if (la <= blocks.floor * 256 && lb <= blocks.floor * 256) continue;
            sumRelative += std::fabs(std::max(lb, blocks.floor * 256) / std::max(la, blocks.floor * 256) - 1.0);
            ++lit;
        }
    const double meanRelative = sumRelative / lit;
    // Per pixel, for scale: the mean relative difference of luminance.
    double pixelRelative = 0.0;
    for (int y = 0; y < kH; ++y)
        for (int x = 0; x < kW; ++x) {
            const float* p = first.at(x, y);
            const float* q = second.at(x, y);
            const double la = 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
            const double lb = 0.2126 * q[0] + 0.7152 * q[1] + 0.0722 * q[2];
            pixelRelative += std::fabs(lb - la) / std::max(la, 1e-6);
        }
    pixelRelative /= kW * kH;
    std::printf("two seeds, %dx%d, 4 spp: HDR-FLIP mean %.4f; per pixel mean |ratio - 1| %.4f; 16 px blocks mean "
                "|ratio - 1| %.4f (CPU %.4f), within 15 %% %.3f, mean |log2| %.4f, %d lit\n",
                kW, kH, flip, pixelRelative, blocks.meanAbsRelative, meanRelative, blocks.withinShare,
                blocks.meanAbsLog2, lit);
    EXPECT_EQ(lit, blocks.litBlocks);
    EXPECT_NEAR(blocks.meanAbsRelative, meanRelative, 1e-6);
    // Measured on lavapipe: HDR-FLIP 0.065, per pixel 0.119, blocks 0.0072.
    EXPECT_LT(meanRelative, 0.05);
    EXPECT_GT(flip, 0.05);
    EXPECT_GT(flip, 5.0 * meanRelative);
    EXPECT_GT(pixelRelative, 5.0 * meanRelative);
    // Not the same image: the seeds are independent.
    EXPECT_GT(maxAbsDiff(first, second), 0.0);
}

// `vitrine compare A B --reference R` with a path-traced R: it renders R's other half (seed + 1) itself, reports the
// noise floor, marks A (R's graph at another seed: nothing but noise) within it and B (the sun 3x as strong) beyond
// it, writes the block heat maps and says so in the report; --no-noise-floor skips the second half.
TEST_F(CompareNoise, CompareReportsTheNoiseFloorAndMarksAPairWithinIt) {
    const auto glb = noiseScene();
    const std::filesystem::path dir = freshDir("compare_noise_floor");
    auto write = [&](const std::string& name, const json& g) {
        std::ofstream(dir / name) << g.dump(2);
        return quote((dir / name).string());
    };
    const std::string reference = write("reference.json", traceGraph(glb, 0));
    const std::string a = write("other_seed.json", traceGraph(glb, 7));
    const std::string b = write("brighter_sun.json", traceGraph(glb, 0, 3.0));
    const std::filesystem::path out = dir / "out";
    const CliResult r = vitrine("compare " + a + " " + b + " --reference " + reference +
                                " --hdr --validate --quiet --out " + quote(out.string()));
    ASSERT_EQ(r.status, 0) << r.output;
    std::printf("%s", r.output.c_str());
    const json metrics = json::parse(readFile(out / "metrics.json"));
    const json& floor = metrics.at("noiseFloor");
    ASSERT_EQ(floor.at("status"), "measured") << floor.dump(2);
    EXPECT_NE(floor.at("reason").get<std::string>().find("pt.params.seed 0 -> 1"), std::string::npos);
    const double floorFlip = floor.at("flip").at("mean").get<double>();
    EXPECT_GT(floorFlip, 0.05); // 4 spp: the reference is noisy
    json pa, pb;
    for (const json& p : metrics.at("pairs")) {
        if (p.at("test") == "A" && p.at("reference") == "reference") pa = p;
        if (p.at("test") == "B" && p.at("reference") == "reference") pb = p;
        if (p.at("reference") == "B") {
            EXPECT_TRUE(p.at("withinReferenceNoise").is_null());
        }
    }
    ASSERT_FALSE(pa.is_null() || pb.is_null()) << metrics.dump(2);
    // The verdicts follow from the numbers: within means FLIP <= 1.5 x the floor.
    EXPECT_EQ(pa.at("withinReferenceNoise"), true) << pa.dump(2);
    EXPECT_LE(pa["flip"]["mean"].get<double>(), 1.5 * floorFlip);
    EXPECT_EQ(pb.at("withinReferenceNoise"), false) << pb.dump(2);
    EXPECT_GT(pb["flip"]["mean"].get<double>(), 1.5 * floorFlip);
    // The blocks see what the sun changed and not the noise.
    EXPECT_LT(pa["blocks"]["meanAbsRelative"].get<double>(), 0.05);
    EXPECT_GT(pb["blocks"]["meanAbsLog2"].get<double>(), 0.3);
    EXPECT_NE(r.output.find("within reference noise"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("noise floor: FLIP mean"), std::string::npos) << r.output;
    for (const char* file : {"reference_half.exr", "flip_reference_half.png", "blocks_a_reference.png",
                             "blocks_b_reference.png", "blocks_a_b.png", "blocks_reference_half.png"})
        EXPECT_TRUE(std::filesystem::is_regular_file(out / file)) << file;
    // The reference half is the reference's graph at seed 1: the same image as rendering that graph directly.
    const Image half = loadExrLayer(out / "reference_half.exr", "");
    const Image seed1 = runGraph(traceGraph(glb, 1)).at("color");
    EXPECT_EQ(maxAbsDiff(half, seed1), 0.0);
    // B's heat map is red where the sun lights more (B brighter than the reference): some pixel is saturated red.
    const Image heat = loadImage(out / "blocks_b_reference.png");
    bool red = false;
    for (int y = 0; y < heat.height; ++y)
        for (int x = 0; x < heat.width; ++x)
            red |= heat.at(x, y)[0] > 0.99f && heat.at(x, y)[1] < 0.3f && heat.at(x, y)[2] < 0.3f;
    EXPECT_TRUE(red);
    const std::string html = readFile(out / "report.html");
    EXPECT_NE(html.find(">within reference noise<"), std::string::npos);
    EXPECT_NE(html.find(">beyond reference noise<"), std::string::npos);
    EXPECT_NE(html.find("Block luminance ratio"), std::string::npos);

    // --no-noise-floor: no second half, no verdicts.
    const std::filesystem::path skipped = dir / "skipped";
    const CliResult s = vitrine("compare " + a + " " + b + " --reference " + reference +
                                " --hdr --no-noise-floor --validate --quiet --out " + quote(skipped.string()));
    ASSERT_EQ(s.status, 0) << s.output;
    const json m2 = json::parse(readFile(skipped / "metrics.json"));
    EXPECT_EQ(m2["noiseFloor"]["status"], "skipped");
    EXPECT_FALSE(std::filesystem::exists(skipped / "reference_half.exr"));
    for (const json& p : m2["pairs"])
        EXPECT_TRUE(p["withinReferenceNoise"].is_null());
}

// An image reference has no seed to change: the floor is unknown unless --reference-half gives the other half.
TEST_F(CompareNoise, ImageReferenceNeedsItsHalfGiven) {
    const std::filesystem::path dir = freshDir("compare_noise_images");
    Image base(48, 32);
    for (int y = 0; y < 32; ++y)
        for (int x = 0; x < 48; ++x)
            for (int c = 0; c < 4; ++c)
                base.at(x, y)[c] = c == 3 ? 1.0f : 0.3f + 0.01f * ((x * 7 + y * 13 + c * 5) % 17);
    Image other = base;
    for (size_t i = 0; i < other.pixels.size(); i += 4)
        for (int c = 0; c < 3; ++c)
            other.pixels[i + c] *= 1.0f + 0.2f * (((i / 4) * 2654435761u >> 7) % 3 == 0 ? 1.0f : -0.5f);
    writeExr(dir / "r.exr", base, ExrPixelType::Float);
    writeExr(dir / "r2.exr", other, ExrPixelType::Float);
    const std::string r = quote((dir / "r.exr").string()), r2 = quote((dir / "r2.exr").string());
    const CliResult unknown =
        vitrine("compare " + r2 + " " + r + " --reference " + r + " --quiet --out " + quote((dir / "u").string()));
    ASSERT_EQ(unknown.status, 0) << unknown.output;
    const json mu = json::parse(readFile(dir / "u" / "metrics.json"));
    EXPECT_EQ(mu["noiseFloor"]["status"], "unknown");
    EXPECT_NE(mu["noiseFloor"]["reason"].get<std::string>().find("--reference-half"), std::string::npos);
    EXPECT_NE(unknown.output.find("noise floor: unknown"), std::string::npos) << unknown.output;

    const CliResult given = vitrine("compare " + r2 + " " + r + " --reference " + r + " --reference-half " + r2 +
                                    " --quiet --out " + quote((dir / "g").string()));
    ASSERT_EQ(given.status, 0) << given.output;
    const json mg = json::parse(readFile(dir / "g" / "metrics.json"));
    ASSERT_EQ(mg["noiseFloor"]["status"], "measured");
    // A is the half itself: its FLIP against the reference is the floor, so it is within; B is the reference.
    EXPECT_DOUBLE_EQ(mg["pairs"][1]["flip"]["mean"].get<double>(), mg["noiseFloor"]["flip"]["mean"].get<double>());
    EXPECT_EQ(mg["pairs"][1]["withinReferenceNoise"], true);
    EXPECT_EQ(mg["pairs"][2]["withinReferenceNoise"], true); // identical: FLIP 0

    // Without a reference the half means nothing: a clear error.
    const CliResult alone = vitrine("compare " + r2 + " " + r + " --reference-half " + r2 + " --quiet --out " +
                                    quote((dir / "x").string()));
    EXPECT_EQ(alone.status, 1) << alone.output;
    EXPECT_NE(alone.output.find("--reference R"), std::string::npos) << alone.output;
}


// --regions: the mean luminance ratio of each named region per pair, in the terminal, metrics.json and the report,
// with regions.png; --output NAME picks that layer of a multi-layer EXR (what `vitrine run` writes); a wrong regions
// file is refused with its JSON pointer before anything is compared.
TEST_F(CompareNoise, RegionsReportEachRegionsRatioOnTheChosenExrLayer) {
    const std::filesystem::path dir = freshDir("compare_regions");
    const int w = 40, h = 20;
    Image reference(w, h), test(w, h), display(w, h);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            for (int c = 0; c < 4; ++c) {
                const float base = c == 3 ? 1.0f : 1.0f + 0.1f * static_cast<float>((x * 7 + y * 3 + c) % 5);
                reference.at(x, y)[c] = base;
                test.at(x, y)[c] = c == 3 ? 1.0f : base * (x < w / 2 ? 0.8f : 1.5f);
                display.at(x, y)[c] = 0.5f; // the other layer: identical in both files
            }
    writeExr(dir / "test.exr", {ExrLayer{"final", &display}, ExrLayer{"radiance", &test}}, ExrPixelType::Float);
    writeExr(dir / "reference.exr", {ExrLayer{"final", &display}, ExrLayer{"radiance", &reference}},
             ExrPixelType::Float);
    std::ofstream(dir / "halves.regions.json") << R"({"format": "vitrine-regions/1", "regions": [
        {"name": "left half", "polygons": [[[0, 0], [0.5, 0], [0.5, 1], [0, 1]]]},
        {"name": "right half", "polygons": [[[0.5, 0], [1, 0], [1, 1], [0.5, 1]]]}]})";
    const std::string t = quote((dir / "test.exr").string()), r = quote((dir / "reference.exr").string());
    const CliResult res = vitrine("compare " + t + " " + r + " --output radiance --hdr --regions " +
                                  quote((dir / "halves.regions.json").string()) + " --quiet --out " +
                                  quote((dir / "out").string()));
    ASSERT_EQ(res.status, 0) << res.output;
    const json m = json::parse(readFile(dir / "out" / "metrics.json"));
    const json& regions = m.at("regions").at("pairs").at(0).at("regions");
    ASSERT_EQ(regions.size(), 2u) << m.dump(2);
    EXPECT_EQ(regions[0]["name"], "left half");
    EXPECT_EQ(regions[0]["pixels"], w * h / 2);
    EXPECT_NEAR(regions[0]["ratio"].get<double>(), 0.8, 1e-5);
    EXPECT_NEAR(regions[1]["ratio"].get<double>(), 1.5, 1e-5);
    // Each region's FLIP: the mean of flip_a_b.exr (the pair's error map, as written) over the region's pixels.
    const Image flip = loadExrLayer(dir / "out" / "flip_a_b.exr", "");
    double flipSum[2] = {0.0, 0.0};
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            flipSum[x < w / 2 ? 0 : 1] += flip.at(x, y)[0];
    for (int i = 0; i < 2; ++i) {
        const double expected = flipSum[i] / (w * h / 2);
        EXPECT_GT(expected, 0.01) << "the halves differ: FLIP must see it";
        EXPECT_NEAR(regions[i]["flip"].get<double>(), expected, 1e-6) << i;
    }
    EXPECT_GT(regions[1]["flip"].get<double>(), regions[0]["flip"].get<double>()) << "x1.5 is further off than x0.8";
    EXPECT_NE(res.output.find("left half"), std::string::npos) << res.output;
    EXPECT_NE(res.output.find("1.500"), std::string::npos) << res.output;
    EXPECT_TRUE(std::filesystem::is_regular_file(dir / "out" / "regions.png"));
    EXPECT_NE(readFile(dir / "out" / "report.html").find("<h3>Regions</h3>"), std::string::npos);
    // The "final" layers are identical: without --output that is not what was compared... with it, it is.
    const CliResult fin = vitrine("compare " + t + " " + r + " --output final --quiet --out " +
                                  quote((dir / "final").string()));
    ASSERT_EQ(fin.status, 0) << fin.output;
    EXPECT_TRUE(json::parse(readFile(dir / "final" / "metrics.json"))["pairs"][0]["psnr"].is_null()); // identical
    // A wrong file: its path and JSON pointer, exit 1.
    std::ofstream(dir / "bad.regions.json") << R"({"format": "vitrine-regions/1", "regions": [{"name": "x"}]})";
    const CliResult bad = vitrine("compare " + t + " " + r + " --regions " + quote((dir / "bad.regions.json").string()) +
                                  " --quiet --out " + quote((dir / "bad").string()));
    EXPECT_EQ(bad.status, 1) << bad.output;
    EXPECT_NE(bad.output.find("bad.regions.json: /regions/0/polygons: missing"), std::string::npos) << bad.output;
}

} // namespace
} // namespace vitrine::test
