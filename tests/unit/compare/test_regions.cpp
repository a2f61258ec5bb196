// compare --regions (core/compare/regions.hpp): the region file's errors name the JSON pointer; masks and ratios
// against counts and means computed here by hand on synthetic images; the shipped museum regions parse and each
// region takes pixels at the sizes the README uses.
#include "core/base/error.hpp"
#include "core/compare/regions.hpp"
#include "test_images.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

namespace vitrine::compare {
namespace {

using testing::constantImage;

nlohmann::json rect(double x0, double y0, double x1, double y1) {
    return nlohmann::json::array({nlohmann::json::array({x0, y0}), nlohmann::json::array({x1, y0}),
                                  nlohmann::json::array({x1, y1}), nlohmann::json::array({x0, y1})});
}

std::string errorOf(const nlohmann::json& doc) {
    try {
        parseRegions(doc, "r.json");
    } catch (const UserError& e) {
        return e.what();
    }
    return "";
}

TEST(Regions, BadFilesNameTheJsonPointer) {
    EXPECT_NE(errorOf(nlohmann::json::array()).find("r.json: /: expected a JSON object"), std::string::npos);
    EXPECT_NE(errorOf({{"format", "x"}}).find("/format"), std::string::npos);
    nlohmann::json doc = {{"format", "vitrine-regions/1"}, {"regions", nlohmann::json::array()}};
    EXPECT_NE(errorOf(doc).find("/regions: expected a non-empty array"), std::string::npos);
    doc["regions"] = {{{"name", "a"}, {"polygons", {rect(0, 0, 0.5, 0.5)}}}};
    EXPECT_EQ(errorOf(doc), "");
    doc["regions"][0]["polygons"][0][2] = nlohmann::json::array({1.5, 0.2});
    EXPECT_NE(errorOf(doc).find("/regions/0/polygons/0/2: expected coordinates within 0..1"), std::string::npos);
    doc["regions"][0]["polygons"][0] = nlohmann::json::array({nlohmann::json::array({0, 0}), nlohmann::json::array({1, 1})});
    EXPECT_NE(errorOf(doc).find("/regions/0/polygons/0: expected a polygon"), std::string::npos);
    doc["regions"][0]["polygons"] = {rect(0, 0, 1, 1)};
    doc["regions"][0]["colour"] = "red";
    EXPECT_NE(errorOf(doc).find("/regions/0/colour: unknown key"), std::string::npos);
    doc["regions"][0].erase("colour");
    doc["regions"][0]["reference_above_median"] = -1;
    EXPECT_NE(errorOf(doc).find("/regions/0/reference_above_median: expected a number > 0"), std::string::npos);
    doc["regions"][0].erase("reference_above_median");
    doc["regions"].push_back(doc["regions"][0]);
    EXPECT_NE(errorOf(doc).find("/regions/1/name: \"a\" is named twice"), std::string::npos);
    EXPECT_THROW(loadRegions("/nonexistent/museum.regions.json"), UserError);
}

// Two halves of a 40 x 20 image: the test is 0.8x the reference on the left and 1.5x on the right; a triangle
// takes the pixels whose centres lie under its diagonal.
TEST(Regions, RatiosAreTheMeanLuminanceOverTheRegionsPixels) {
    const int w = 40, h = 20;
    Image reference = constantImage(w, h, 0.0f, 0.0f, 0.0f);
    Image test = reference;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const float base = 1.0f + 0.1f * static_cast<float>((x * 7 + y * 3) % 5); // varies inside each half
            for (int c = 0; c < 3; ++c) {
                reference.at(x, y)[c] = base * (c == 2 ? 0.5f : 1.0f);
                test.at(x, y)[c] = reference.at(x, y)[c] * (x < w / 2 ? 0.8f : 1.5f);
            }
        }
    nlohmann::json doc = {{"format", "vitrine-regions/1"},
                          {"regions",
                           {{{"name", "left"}, {"polygons", {rect(0, 0, 0.5, 1)}}},
                            {{"name", "right"}, {"polygons", {rect(0.5, 0, 1, 1)}}},
                            {{"name", "both"}, {"polygons", {rect(0, 0, 0.25, 1), rect(0.75, 0, 1, 1)}}},
                            {{"name", "triangle"},
                             {"polygons", {nlohmann::json::array({nlohmann::json::array({0, 0}),
                                                                  nlohmann::json::array({1, 1}),
                                                                  nlohmann::json::array({0, 1})})}}},
                            {{"name", "outside"}, {"polygons", {rect(0.0, 0.0, 0.01, 0.01)}}}}}};
    const RegionSet set = parseRegions(doc, "test");
    const auto ratios = regionLuminanceRatios(set, test, reference);
    ASSERT_EQ(ratios.size(), 5u);
    EXPECT_EQ(ratios[0].pixels, 400);
    EXPECT_NEAR(ratios[0].ratio, 0.8, 1e-6);
    EXPECT_NEAR(ratios[1].ratio, 1.5, 1e-6);
    // The union of two polygons, and the by-hand mean over the triangle's pixels.
    EXPECT_EQ(ratios[2].pixels, 400);
    double lt = 0.0, lr = 0.0;
    int n = 0;
    auto lum = [](const float* p) { return 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2]; };
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            if ((y + 0.5) / h > (x + 0.5) / w) {
                lt += lum(test.at(x, y));
                lr += lum(reference.at(x, y));
                ++n;
            }
    EXPECT_EQ(ratios[3].pixels, n);
    EXPECT_NEAR(ratios[3].ratio, lt / lr, 1e-9);
    EXPECT_NEAR(ratios[3].reference, lr / n, 1e-6);
    // A region smaller than a pixel centre's spacing is empty: NaN, not 0 or 1.
    EXPECT_EQ(ratios[4].pixels, 0);
    EXPECT_TRUE(std::isnan(ratios[4].ratio));
    EXPECT_THROW(regionLuminanceRatios(set, constantImage(4, 4, 1, 1, 1), reference), UserError);
}

// reference_above_median / below: a floor of dark and bright tiles (a sunlit stripe at 10x) splits by the
// reference's brightness; a single bright pixel (path-tracing noise) does not decide thanks to the 3x3 filter.
TEST(Regions, SplitByTheReferencesBrightness) {
    const int w = 32, h = 32;
    Image reference = constantImage(w, h, 1.0f, 1.0f, 1.0f);
    for (int y = 0; y < h; ++y)
        for (int x = 24; x < w; ++x)
            for (int c = 0; c < 3; ++c) reference.at(x, y)[c] = 10.0f;
    for (int c = 0; c < 3; ++c) reference.at(5, 5)[c] = 6.0f; // a firefly: 3x3 mean 1.56, below 2x the median
    nlohmann::json doc = {{"format", "vitrine-regions/1"},
                          {"regions",
                           {{{"name", "sun"}, {"polygons", {rect(0, 0, 1, 1)}}, {"reference_above_median", 2.0}},
                            {{"name", "shade"}, {"polygons", {rect(0, 0, 1, 1)}}, {"reference_below_median", 2.0}}}}};
    const RegionSet set = parseRegions(doc, "test");
    const auto masks = regionMasks(set, reference);
    int sun = 0, shade = 0;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            sun += masks[0][static_cast<size_t>(y) * w + x];
            shade += masks[1][static_cast<size_t>(y) * w + x];
        }
    // Column 23's 3x3 mean is 4 (one bright column of three): above 2x the median (1), so it counts as sun.
    EXPECT_EQ(sun, 9 * h);
    EXPECT_EQ(shade, 23 * h);
    EXPECT_EQ(masks[1][5 * w + 5], 1);
}

// Given the pair's FLIP error map, each region's mean of it; without one, NaN; a map of another size is refused.
TEST(Regions, FlipIsTheErrorMapsMeanOverEachRegion) {
    const RegionSet set = parseRegions(nlohmann::json::parse(R"({"format": "vitrine-regions/1", "regions": [
        {"name": "left", "polygons": [[[0, 0], [0.25, 0], [0.25, 1], [0, 1]]]},
        {"name": "rest", "polygons": [[[0.25, 0], [1, 0], [1, 1], [0.25, 1]]]},
        {"name": "nothing", "polygons": [[[0.01, 0.01], [0.02, 0.01], [0.01, 0.02]]]}]})"),
                                       "test");
    const int w = 8, h = 4;
    const Image flat = constantImage(w, h, 1.0f, 1.0f, 1.0f);
    Image error = constantImage(w, h, 0.0f, 0.0f, 0.0f);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            error.at(x, y)[0] = 0.01f * static_cast<float>(x + 10 * y); // channel 0 is the error
            error.at(x, y)[1] = error.at(x, y)[2] = 0.9f;               // the others are not read
        }
    const auto rows = regionLuminanceRatios(set, flat, flat, &error);
    ASSERT_EQ(rows.size(), 3u);
    // left: x 0..1, y 0..3 -> mean x 0.5, mean y 1.5; rest: x 2..7 (mean 4.5).
    EXPECT_NEAR(rows[0].flip, 0.01 * (0.5 + 15.0), 1e-6);
    EXPECT_NEAR(rows[1].flip, 0.01 * (4.5 + 15.0), 1e-6);
    EXPECT_TRUE(std::isnan(rows[2].flip)) << "an empty region has no mean";
    EXPECT_TRUE(std::isnan(regionLuminanceRatios(set, flat, flat)[0].flip)) << "no map, no FLIP";
    const Image small = constantImage(w / 2, h, 0.0f, 0.0f, 0.0f);
    EXPECT_THROW(regionLuminanceRatios(set, flat, flat, &small), UserError);
}

TEST(Regions, TheMuseumsRegionsParseAndEachTakesPixels) {
    const RegionSet set = loadRegions(std::string(VITRINE_SOURCE_DIR) + "/graphs/regions/museum.regions.json");
    EXPECT_GE(set.regions.size(), 7u);
    for (const auto& [w, h] : {std::pair{320, 180}, std::pair{640, 360}}) {
        const Image flat = constantImage(w, h, 1.0f, 1.0f, 1.0f);
        for (const RegionRatio& r : regionLuminanceRatios(set, flat, flat)) {
            EXPECT_GT(r.pixels, w * h / 400) << r.name << " at " << w << "x" << h;
            EXPECT_NEAR(r.ratio, 1.0, 1e-9) << r.name;
        }
    }
}

} // namespace
} // namespace vitrine::compare
