#include "tools/vitrine/sweep/collect.hpp"
#include "tools/vitrine/sweep/sweep_file.hpp"

#include "core/base/error.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <regex>

namespace vitrine::sweep {
namespace {

namespace fs = std::filesystem;
const fs::path kSource = VITRINE_SOURCE_DIR;

// A sweep file written into a temporary folder next to nothing: graphs are named by absolute paths.
class SweepFileTest : public ::testing::Test {
protected:
    fs::path write(nlohmann::json doc) {
        fs::path dir = fs::temp_directory_path() / ("vitrine_sweep_test_" + std::to_string(::getpid()));
        fs::create_directories(dir);
        fs::path file = dir / (std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()) + ".json");
        std::ofstream(file) << doc.dump(2);
        return file;
    }
    static nlohmann::json base() {
        return {{"format", "vitrine-sweep/1"},
                {"graph", (kSource / "graphs/fxaa_zoneplate.json").string()},
                {"reference", (kSource / "graphs/variants/supersampled.json").string()},
                {"axes", nlohmann::json::array({{{"set", "fxaa.params.subpix"}, {"values", {0.25, 0.5, 0.75}}}})}};
    }
    // parseSweepFile's message, which must start with the file name and the pointer.
    std::string errorOf(const nlohmann::json& doc) {
        const fs::path file = write(doc);
        try {
            parseSweepFile(file);
        } catch (const UserError& e) {
            const std::string message = e.what();
            EXPECT_EQ(message.rfind(file.string() + ": ", 0), 0u) << message;
            return message.substr(file.string().size() + 2);
        }
        ADD_FAILURE() << "no error for " << doc.dump();
        return "";
    }
};

TEST_F(SweepFileTest, ErrorsNameThePointer) {
    auto doc = base();
    doc["format"] = "vitrine-sweep/2";
    EXPECT_EQ(errorOf(doc).rfind("/format: expected \"vitrine-sweep/1\"", 0), 0u);

    doc = base();
    doc["axes"][0] = {{"name", "x"}, {"param", "fxaa.params.subpix"}, {"values", {1}}};
    EXPECT_EQ(errorOf(doc).rfind("/axes/0/param: unknown key", 0), 0u) << errorOf(doc);

    doc = base();
    doc["axes"][0] = {{"name", "x"}};
    EXPECT_EQ(errorOf(doc).rfind("/axes/0: expected exactly one axis kind", 0), 0u) << errorOf(doc);

    doc = base();
    doc["axes"][0]["set"] = "fxaa.params.subpixel";
    std::string e = errorOf(doc);
    EXPECT_EQ(e.rfind("/axes/0/set: --set fxaa.params.subpixel: node 'fxaa' (aa.fxaa) has no param 'subpixel'", 0), 0u) << e;
    EXPECT_NE(e.find("subpix"), std::string::npos) << "lists the params it has: " << e;

    doc = base();
    doc["axes"][0]["set"] = "taa.params.feedback";
    e = errorOf(doc);
    EXPECT_EQ(e.rfind("/axes/0/set: --set taa.params.feedback: the base graph", 0), 0u) << e;
    EXPECT_NE(e.find("has no node 'taa'"), std::string::npos) << e;

    doc = base();
    doc["axes"][0]["set"] = "fxaa.subpix";
    EXPECT_EQ(errorOf(doc).rfind("/axes/0/set: expected NODE.params.PARAM", 0), 0u);

    doc = base();
    doc["axes"].push_back({{"variants", {"no_such_variant.json"}}});
    e = errorOf(doc);
    EXPECT_EQ(e.rfind("/axes/1/variants/0: variant file ", 0), 0u) << e;
    EXPECT_NE(e.find("not found"), std::string::npos) << e;

    doc = base();
    doc["combine"] = "zip";
    doc["axes"].push_back({{"set", "fxaa.params.edge_threshold"}, {"values", {0.1, 0.2}}});
    e = errorOf(doc);
    EXPECT_EQ(e.rfind("/axes/1/values: \"combine\": \"zip\" needs axes of equal length", 0), 0u) << e;

    doc = base();
    doc["axes"].push_back({{"frames", {"0:3", "5:2"}}});
    EXPECT_EQ(errorOf(doc).rfind("/axes/1/frames/1: expected a frame index N or a range", 0), 0u);

    doc = base();
    doc["metrics"] = {"flip", "beauty"};
    EXPECT_EQ(errorOf(doc).rfind("/metrics/1: expected one of flip", 0), 0u);

    doc = base();
    doc.erase("reference");
    doc["metrics"] = {"gpu_ms", "ssim"};
    EXPECT_EQ(errorOf(doc).rfind("/metrics/1: metric 'ssim' compares with the reference", 0), 0u);

    doc = base();
    doc["combine"] = "cartesian";
    EXPECT_EQ(errorOf(doc).rfind("/combine: expected \"product\" or \"zip\"", 0), 0u);

    doc = base();
    doc["points"] = {{{"set", {{"fxaa.params.nope", 1}}}}};
    EXPECT_EQ(errorOf(doc).rfind("/points/0/set/fxaa.params.nope: --set fxaa.params.nope", 0), 0u);

    doc = base();
    doc["axes"].push_back({{"set", "fxaa.params.subpix"}, {"values", {1}}});
    EXPECT_EQ(errorOf(doc).rfind("/axes/1/name: axis name 'subpix' is used twice", 0), 0u);
}

TEST_F(SweepFileTest, ValuesOutOfRangeAreLeftToThePoint) {
    auto doc = base();
    doc["axes"][0]["values"] = {0.5, 7.0}; // subpix is in [0, 1]: that point fails when it runs, not the sweep
    EXPECT_EQ(expandPoints(parseSweepFile(write(doc))).size(), 2u);
}

TEST_F(SweepFileTest, ProductExpansion) {
    auto doc = base();
    doc["frame"] = {{"width", 160}, {"height", 90}};
    doc["axes"].push_back({{"name", "variant"},
                           {"variants", {(kSource / "graphs/fxaa_zoneplate.json").string(),
                                         (kSource / "graphs/variants/no_fxaa.json").string()}}});
    doc["axes"].push_back({{"frames", {"0:3", 2}}});
    doc["points"] = {{{"variant", (kSource / "graphs/variants/no_fxaa.json").string()}}};
    const SweepFile s = parseSweepFile(write(doc));
    const std::vector<Point> points = expandPoints(s);
    ASSERT_EQ(points.size(), 3u * 2u * 2u + 1u);
    // The first axis varies slowest.
    const std::vector<std::string> labels = {
        "subpix=0.25, variant=fxaa_zoneplate, frames=0:3", "subpix=0.25, variant=fxaa_zoneplate, frames=2",
        "subpix=0.25, variant=no_fxaa, frames=0:3",        "subpix=0.25, variant=no_fxaa, frames=2",
        "subpix=0.5, variant=fxaa_zoneplate, frames=0:3",  "subpix=0.5, variant=fxaa_zoneplate, frames=2",
        "subpix=0.5, variant=no_fxaa, frames=0:3",         "subpix=0.5, variant=no_fxaa, frames=2",
        "subpix=0.75, variant=fxaa_zoneplate, frames=0:3", "subpix=0.75, variant=fxaa_zoneplate, frames=2",
        "subpix=0.75, variant=no_fxaa, frames=0:3",        "subpix=0.75, variant=no_fxaa, frames=2",
        "variant=no_fxaa"};
    for (size_t i = 0; i < points.size(); ++i) {
        EXPECT_EQ(points[i].label, labels[i]);
        char id[8];
        std::snprintf(id, sizeof id, "p%04zu", i);
        EXPECT_EQ(points[i].id, id);
    }
    EXPECT_EQ(points[6].graph, (kSource / "graphs/variants/no_fxaa.json").lexically_normal());
    EXPECT_EQ(points[6].sets, (std::vector<std::string>{"frame.width=160", "frame.height=90", "fxaa.params.subpix=0.5"}));
    EXPECT_TRUE(points[6].frames.temporal);
    EXPECT_EQ(points[6].frames.first, 0u);
    EXPECT_EQ(points[6].frames.last, 3u);
    EXPECT_FALSE(points[7].frames.temporal);
    EXPECT_EQ(points[7].frames.last, 2u);
    EXPECT_EQ(points[12].sets, (std::vector<std::string>{"frame.width=160", "frame.height=90"}));
    EXPECT_EQ(points[12].values, (nlohmann::json{{"variant", "no_fxaa"}}));
    EXPECT_EQ(&findPoint(points, "p0007"), &points[7]);
    EXPECT_EQ(&findPoint(points, "7"), &points[7]);
    EXPECT_THROW(findPoint(points, "p0013"), UserError);
    // Defaults: flicker joins the metrics when a point renders a frame range.
    EXPECT_EQ(s.metrics, (std::vector<std::string>{"flip", "ssim", "psnr", "flicker", "gpu_ms", "memory"}));
}

TEST_F(SweepFileTest, ZipExpansion) {
    auto doc = base();
    doc["combine"] = "zip";
    doc["axes"].push_back({{"name", "edge"}, {"set", "fxaa.params.edge_threshold"}, {"values", {0.1, 0.2, 0.3}}});
    const std::vector<Point> points = expandPoints(parseSweepFile(write(doc)));
    ASSERT_EQ(points.size(), 3u);
    EXPECT_EQ(points[0].label, "subpix=0.25, edge=0.1");
    EXPECT_EQ(points[1].label, "subpix=0.5, edge=0.2");
    EXPECT_EQ(points[2].label, "subpix=0.75, edge=0.3");
    EXPECT_EQ(points[2].sets, (std::vector<std::string>{"fxaa.params.subpix=0.75", "fxaa.params.edge_threshold=0.3"}));
    EXPECT_EQ(points[1].values, (nlohmann::json{{"subpix", 0.5}, {"edge", 0.2}}));
}

// The report of a made-up table: one <svg class='plot'> per metric and axis plus the quality-versus-cost plot, and
// the Pareto front is the points no other beats in both FLIP and GPU ms.
TEST(SweepReport, PlotsAndParetoFront) {
    nlohmann::json table = {{"sweep", "s.json"},
                            {"metrics", {"flip", "gpu_ms"}},
                            {"columns", {"flip", "flip_weighted_median", "gpu_ms"}},
                            {"axes", {{{"name", "a"}}, {{"name", "b"}}}},
                            {"summary", {{"done", 4}, {"failed", 1}, {"pending", 0}}},
                            {"points", nlohmann::json::array()}};
    auto add = [&](const std::string& id, double a, const std::string& b, double flip, double ms) {
        table["points"].push_back({{"id", id},
                                   {"label", id},
                                   {"status", "done"},
                                   {"values", {{"a", a}, {"b", b}}},
                                   {"metrics", {{"flip", flip}, {"gpu_ms", ms}}}});
    };
    add("p0000", 1, "x", 0.30, 1.0); // front: cheapest
    add("p0001", 2, "x", 0.20, 2.0); // front
    add("p0002", 1, "y", 0.25, 3.0); // dominated by p0001
    add("p0003", 2, "y", 0.10, 4.0); // front: best
    table["points"].push_back({{"id", "p0004"}, {"label", "bad"}, {"status", "failed"}, {"error", "boom"},
                               {"exit_code", 1}, {"values", {{"a", 3}, {"b", "y"}}}});
    const std::string html = renderSweepReport(table);
    for (const char* metric : {"flip", "gpu_ms"})
        for (const char* axis : {"a", "b"})
            EXPECT_NE(html.find(std::string("class='plot' data-metric='") + metric + "' data-axis='" + axis + "'"),
                      std::string::npos)
                << metric << " vs " << axis;
    const std::regex plot("<svg class='plot'");
    EXPECT_EQ(std::distance(std::sregex_iterator(html.begin(), html.end(), plot), std::sregex_iterator()), 4);
    EXPECT_NE(html.find("on the front: p0000, p0001, p0003</figcaption>"), std::string::npos);
    EXPECT_NE(html.find("boom"), std::string::npos);
    EXPECT_EQ(html.find("<script"), std::string::npos);
    EXPECT_EQ(html.find("http://"), html.find("http://www.w3.org/2000/svg"));
}

} // namespace
} // namespace vitrine::sweep
