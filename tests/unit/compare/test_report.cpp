#include "core/compare/report.hpp"

#include "core/base/error.hpp"
#include "test_images.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

namespace vitrine::compare {
namespace {

std::vector<unsigned char> bytes(const std::string& s) {
    return {s.begin(), s.end()};
}

TEST(Base64, Rfc4648TestVectors) {
    EXPECT_EQ(base64Encode(bytes("")), "");
    EXPECT_EQ(base64Encode(bytes("f")), "Zg==");
    EXPECT_EQ(base64Encode(bytes("fo")), "Zm8=");
    EXPECT_EQ(base64Encode(bytes("foo")), "Zm9v");
    EXPECT_EQ(base64Encode(bytes("foob")), "Zm9vYg==");
    EXPECT_EQ(base64Encode(bytes("fooba")), "Zm9vYmE=");
    EXPECT_EQ(base64Encode(bytes("foobar")), "Zm9vYmFy");
    const std::vector<unsigned char> high = {0xff, 0xfe, 0x80};
    EXPECT_EQ(base64Encode(high), "//6A");
}

TEST(EscapeHtml, EscapesMarkupAndQuotes) {
    EXPECT_EQ(escapeHtml("<script>alert(\"x\") & 'y'</script>"),
              "&lt;script&gt;alert(&quot;x&quot;) &amp; &#39;y&#39;&lt;/script&gt;");
}

nlohmann::json baseGraph() {
    return nlohmann::json::parse(R"({
        "format": "vitrine-graph/1",
        "frame": {"width": 160, "height": 90, "frames": 32, "write": [31]},
        "nodes": {
            "aa": {"type": "aa.taa", "in": {"color": "lighting.color", "history": "aa.color@prev"},
                   "params": {"alpha": 0.1}, "ui": {"x": 10, "y": 20}},
            "a/b": {"type": "debug.view"}
        },
        "ui": {"zoom": 1.0}
    })");
}

nlohmann::json variantGraph() {
    nlohmann::json g = baseGraph();
    g["nodes"]["aa"]["type"] = "aa.fxaa";
    g["nodes"]["aa"]["in"].erase("history");
    g["nodes"]["aa"]["params"]["sharpness"] = 0.5;
    g["nodes"]["aa"]["ui"] = {{"x", 400}, {"y", 20}}; // moved in the editor only
    g["nodes"]["a/b"]["type"] = "debug.other";
    g["frame"]["write"].push_back(15);
    g["ui"]["zoom"] = 2.0;
    return g;
}

TEST(DiffGraphs, ListsChangesByPointerIgnoringUiBlocks) {
    const std::vector<GraphChange> changes = diffGraphs(baseGraph(), variantGraph());
    ASSERT_EQ(changes.size(), 5u);
    // Document order: keys sorted, so "frame" < "nodes", and "a/b" < "aa".
    EXPECT_EQ(changes[0].pointer, "/frame/write/1");
    EXPECT_EQ(changes[0].kind, GraphChange::Kind::Added);
    EXPECT_EQ(changes[0].after, 15);
    EXPECT_EQ(changes[1].pointer, "/nodes/a~1b/type"); // RFC 6901 escapes '/' as ~1
    EXPECT_EQ(changes[1].kind, GraphChange::Kind::Changed);
    EXPECT_EQ(changes[2].pointer, "/nodes/aa/in/history");
    EXPECT_EQ(changes[2].kind, GraphChange::Kind::Removed);
    EXPECT_EQ(changes[2].before, "aa.color@prev");
    EXPECT_EQ(changes[3].pointer, "/nodes/aa/params/sharpness");
    EXPECT_EQ(changes[3].kind, GraphChange::Kind::Added);
    EXPECT_EQ(changes[4].pointer, "/nodes/aa/type");
    EXPECT_EQ(changes[4].before, "aa.taa");
    EXPECT_EQ(changes[4].after, "aa.fxaa");
    EXPECT_TRUE(diffGraphs(baseGraph(), baseGraph()).empty());
}

ReportInput sampleInput() {
    ReportInput input;
    input.title = "TAA vs FXAA";
    input.a = {"Variant A (TAA)", bytes("foobar"), 64, 64};
    input.b = {"<script>alert(1)</script>", bytes("Man"), 64, 64};
    input.reference = ReportImage{"Path-traced reference", bytes("foob"), 64, 64};
    input.differenceMaps.push_back({"|A - B|", bytes("fo"), 64, 64});
    input.flipMaps.push_back({"FLIP A vs B", bytes("f"), 64, 64});
    PairMetrics ab;
    ab.test = "Variant A (TAA)";
    ab.reference = "B";
    ab.psnr = 34.2109;
    ab.ssim = 0.98765;
    ab.flip = {0.125, 0.25, 0.0625, 0.375, 0.0, 0.875};
    PairMetrics identical = ab;
    identical.reference = "A copy";
    identical.psnr = std::numeric_limits<double>::infinity();
    input.metrics = {ab, identical};
    TemporalMetrics t;
    t.label = "A";
    t.frameCount = 3;
    t.flicker = 0.0123;
    t.errorPerFrame = {30.0, 31.5, std::numeric_limits<double>::infinity()};
    input.temporal.push_back(t);
    input.graphA = baseGraph();
    input.graphB = variantGraph();
    return input;
}

std::string readFile(const std::filesystem::path& path) {
    std::ifstream file(path, std::ios::binary);
    std::stringstream ss;
    ss << file.rdbuf();
    return ss.str();
}

TEST(WriteReport, SelfContainedPageWithImagesMetricsAndChanges) {
    const std::filesystem::path dir = std::filesystem::temp_directory_path() / "vitrine_test_compare_report";
    std::filesystem::create_directories(dir);
    const std::filesystem::path path = dir / "report.html";
    writeReport(path, sampleInput());
    const std::string html = readFile(path);
    ASSERT_FALSE(html.empty());

    EXPECT_NE(html.find("Variant A (TAA)"), std::string::npos);
    EXPECT_NE(html.find("Path-traced reference"), std::string::npos);
    EXPECT_NE(html.find("data:image/png;base64,Zm9vYmFy\""), std::string::npos); // A = "foobar"
    EXPECT_NE(html.find("data:image/png;base64,TWFu\""), std::string::npos);     // B = "Man"
    EXPECT_NE(html.find("data:image/png;base64,Zm9vYg==\""), std::string::npos); // reference = "foob"
    EXPECT_NE(html.find("&lt;script&gt;alert(1)&lt;/script&gt;"), std::string::npos);
    EXPECT_EQ(html.find("<script>alert"), std::string::npos);
    EXPECT_NE(html.find("|A - B|"), std::string::npos);

    // Nothing is fetched: no remote URLs, no external stylesheets or scripts.
    EXPECT_EQ(html.find("http://"), std::string::npos);
    EXPECT_EQ(html.find("https://"), std::string::npos);
    EXPECT_EQ(html.find("<link"), std::string::npos);
    EXPECT_EQ(html.find("<script src"), std::string::npos);

    EXPECT_NE(html.find("id=\"split-view\""), std::string::npos);
    EXPECT_NE(html.find("type=\"range\""), std::string::npos);
    // FLIP colour bar: magma's published end colours.
    EXPECT_NE(html.find("#000004"), std::string::npos);
    EXPECT_NE(html.find("#fcfdbf"), std::string::npos);

    EXPECT_NE(html.find("34.21"), std::string::npos);
    EXPECT_NE(html.find("0.98765"), std::string::npos);
    EXPECT_NE(html.find("&infin;"), std::string::npos);
    EXPECT_NE(html.find("0.01230"), std::string::npos);

    EXPECT_NE(html.find("/nodes/aa/type"), std::string::npos);
    EXPECT_NE(html.find("&quot;aa.taa&quot;"), std::string::npos);
    EXPECT_NE(html.find("&quot;aa.fxaa&quot;"), std::string::npos);
    EXPECT_EQ(html.find("/nodes/aa/ui"), std::string::npos);
    std::filesystem::remove_all(dir);
}

TEST(WriteReport, RejectsMissingPngAndUnwritablePath) {
    ReportInput input = sampleInput();
    input.a.png.clear();
    EXPECT_THROW(renderReportHtml(input), UserError);
    EXPECT_THROW(writeReport("/nonexistent-vitrine-dir/sub/report.html", sampleInput()), UserError);
}

TEST(WriteReport, SaysWhenGraphsAreMissing) {
    ReportInput input = sampleInput();
    input.graphB = nullptr;
    EXPECT_NE(renderReportHtml(input).find("were not given"), std::string::npos);
}

TEST(MetricsJson, ParsesAndFollowsTheSchema) {
    const nlohmann::json doc = nlohmann::json::parse(metricsJson(sampleInput()).dump(2));
    EXPECT_EQ(doc.at("format"), "vitrine-compare/1");
    EXPECT_EQ(doc.at("images").at("b").at("label"), "<script>alert(1)</script>");
    EXPECT_EQ(doc.at("images").at("reference").at("width"), 64);
    ASSERT_EQ(doc.at("pairs").size(), 2u);
    EXPECT_DOUBLE_EQ(doc["pairs"][0].at("psnr").get<double>(), 34.2109);
    EXPECT_TRUE(doc["pairs"][1].at("psnr").is_null()); // +inf
    EXPECT_EQ(doc["pairs"][0]["flip"].at("mode"), "ldr");
    EXPECT_DOUBLE_EQ(doc["pairs"][0]["flip"].at("weightedMedian").get<double>(), 0.25);
    EXPECT_DOUBLE_EQ(doc["pairs"][0]["flip"].at("q3").get<double>(), 0.375);
    EXPECT_DOUBLE_EQ(doc["pairs"][0]["flip"].at("max").get<double>(), 0.875);
    const nlohmann::json& t = doc.at("temporal").at(0);
    EXPECT_TRUE(t.at("flickerMotionCompensated").is_null());
    EXPECT_EQ(t.at("errorPerFrame").at("metric"), "psnr");
    EXPECT_TRUE(t["errorPerFrame"]["values"][2].is_null());
    ASSERT_EQ(doc.at("graphChanges").size(), 5u);
    EXPECT_EQ(doc["graphChanges"][4].at("op"), "changed");
    EXPECT_EQ(doc["graphChanges"][4].at("before"), "aa.taa");
    EXPECT_FALSE(doc["graphChanges"][0].contains("before")); // an addition has no old value
}

// The noise floor and the block measure reach metrics.json and the page: a pair within the floor is marked, one beyond
// it too, and the floor's own numbers are there.
TEST(MetricsJson, NoiseFloorAndBlocks) {
    ReportInput input = sampleInput();
    NoiseFloor floor;
    floor.status = NoiseFloor::Status::Measured;
    floor.reason = "seed 0 -> 1";
    PairMetrics half;
    half.test = "reference half";
    half.reference = "reference";
    half.flip.mean = 0.2;
    half.blocks.withinShare = 0.97;
    half.blocks.meanAbsLog2 = 0.02;
    floor.pair = half;
    EXPECT_TRUE(floor.contains(0.3)); // 1.5 × 0.2
    EXPECT_FALSE(floor.contains(0.31));
    input.noiseFloor = floor;
    input.metrics[0].withinReferenceNoise = true;
    input.metrics[1].withinReferenceNoise = false;
    input.metrics[0].blocks.withinShare = 0.875;
    input.blockMaps.push_back({"log2 block luminance A / B", bytes("Ma"), 64, 64});
    input.referenceHalf = ReportImage{"reference half", bytes("fooba"), 64, 64};
    const nlohmann::json doc = nlohmann::json::parse(metricsJson(input).dump());
    EXPECT_EQ(doc["pairs"][0]["withinReferenceNoise"], true);
    EXPECT_EQ(doc["pairs"][1]["withinReferenceNoise"], false);
    EXPECT_DOUBLE_EQ(doc["pairs"][0]["blocks"]["withinShare"].get<double>(), 0.875);
    EXPECT_EQ(doc["pairs"][0]["blocks"]["size"], 16);
    EXPECT_EQ(doc["noiseFloor"]["status"], "measured");
    EXPECT_DOUBLE_EQ(doc["noiseFloor"]["flip"]["mean"].get<double>(), 0.2);
    EXPECT_DOUBLE_EQ(doc["noiseFloor"]["factor"].get<double>(), 1.5);
    EXPECT_EQ(doc["noiseFloor"]["half"], "reference half");
    EXPECT_EQ(doc["images"]["referenceHalf"]["width"], 64);
    EXPECT_TRUE(metricsJson(sampleInput())["noiseFloor"].is_null());
    EXPECT_TRUE(metricsJson(sampleInput())["pairs"][0]["withinReferenceNoise"].is_null());

    const std::string html = renderReportHtml(input);
    EXPECT_NE(html.find(">within reference noise<"), std::string::npos);
    EXPECT_NE(html.find(">beyond reference noise<"), std::string::npos);
    EXPECT_NE(html.find("id=\"noise-floor\""), std::string::npos);
    EXPECT_NE(html.find("0.20000"), std::string::npos);
    EXPECT_NE(html.find("87.5 %"), std::string::npos);
    EXPECT_NE(html.find("data:image/png;base64,TWE=\""), std::string::npos);     // the block map "Ma"
    EXPECT_NE(html.find("data:image/png;base64,Zm9vYmE=\""), std::string::npos); // the half "fooba"
    EXPECT_NE(html.find("Block luminance ratio"), std::string::npos);

    NoiseFloor unknown;
    unknown.reason = "the reference is an image file";
    input.noiseFloor = unknown;
    EXPECT_EQ(metricsJson(input)["noiseFloor"]["status"], "unknown");
    EXPECT_FALSE(metricsJson(input)["noiseFloor"].contains("flip"));
    EXPECT_NE(renderReportHtml(input).find("unknown (the reference is an image file)"), std::string::npos);
}

TEST(ComparePair, IdenticalImages) {
    const Image a = testing::colourfulImage(32, 32);
    const PairComparison c = comparePair("A", a, "R", a);
    EXPECT_EQ(c.metrics.psnr, std::numeric_limits<double>::infinity());
    EXPECT_EQ(c.metrics.ssim, 1.0);
    EXPECT_EQ(c.metrics.flip.mean, 0.0);
    EXPECT_EQ(c.flipErrorMap.width, 32);
    PairOptions hdr;
    hdr.hdr = true;
    EXPECT_TRUE(comparePair("A", a, "R", a, hdr).metrics.hdrFlip);
}

} // namespace
} // namespace vitrine::compare
