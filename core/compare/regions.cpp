// Named regions and their luminance ratio (see regions.hpp).
#include "core/compare/regions.hpp"
#include "core/base/error.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>

namespace vitrine::compare {
namespace {

double luminance(const float* p) {
    auto c = [](float v) { return std::isfinite(v) && v > 0.0f ? static_cast<double>(v) : 0.0; };
    return 0.2126 * c(p[0]) + 0.7152 * c(p[1]) + 0.0722 * c(p[2]);
}

[[noreturn]] void fail(const std::string& source, const std::string& pointer, const std::string& what) {
    throw UserError(source + ": " + (pointer.empty() ? "/" : pointer) + ": " + what);
}

// Even-odd rule on the polygon's edges.
bool inside(const std::vector<std::array<double, 2>>& poly, double x, double y) {
    bool in = false;
    for (size_t i = 0, j = poly.size() - 1; i < poly.size(); j = i++) {
        const auto& a = poly[i];
        const auto& b = poly[j];
        if ((a[1] > y) != (b[1] > y) && x < (b[0] - a[0]) * (y - a[1]) / (b[1] - a[1]) + a[0]) in = !in;
    }
    return in;
}

} // namespace

RegionSet parseRegions(const nlohmann::json& doc, const std::string& source) {
    if (!doc.is_object()) fail(source, "", "expected a JSON object with \"format\" and \"regions\"");
    if (!doc.contains("format") || doc["format"] != "vitrine-regions/1")
        fail(source, "/format", "expected \"vitrine-regions/1\"");
    for (const auto& [key, value] : doc.items())
        if (key != "format" && key != "regions" && key != "description" && key != "$comment")
            fail(source, "/" + key, "unknown key (expected format, description, regions)");
    RegionSet set;
    set.source = source;
    if (doc.contains("description")) {
        if (!doc["description"].is_string()) fail(source, "/description", "expected a string");
        set.description = doc["description"].get<std::string>();
    }
    if (!doc.contains("regions") || !doc["regions"].is_array() || doc["regions"].empty())
        fail(source, "/regions", "expected a non-empty array of regions");
    for (size_t r = 0; r < doc["regions"].size(); ++r) {
        const nlohmann::json& jr = doc["regions"][r];
        const std::string at = "/regions/" + std::to_string(r);
        if (!jr.is_object()) fail(source, at, "expected an object with \"name\" and \"polygons\"");
        Region region;
        for (const auto& [key, value] : jr.items()) {
            const std::string p = at + "/" + key;
            if (key == "name") {
                if (!value.is_string() || value.get<std::string>().empty()) fail(source, p, "expected a non-empty string");
                region.name = value.get<std::string>();
            } else if (key == "doc") {
                if (!value.is_string()) fail(source, p, "expected a string");
                region.doc = value.get<std::string>();
            } else if (key == "reference_above_median" || key == "reference_below_median") {
                if (!value.is_number() || !(value.get<double>() > 0.0)) fail(source, p, "expected a number > 0");
                (key == "reference_above_median" ? region.referenceAboveMedian : region.referenceBelowMedian) =
                    value.get<double>();
            } else if (key == "polygons") {
                if (!value.is_array() || value.empty()) fail(source, p, "expected a non-empty array of polygons");
                for (size_t k = 0; k < value.size(); ++k) {
                    const std::string pk = p + "/" + std::to_string(k);
                    if (!value[k].is_array() || value[k].size() < 3)
                        fail(source, pk, "expected a polygon: an array of at least 3 [x, y] points");
                    std::vector<std::array<double, 2>> poly;
                    for (size_t v = 0; v < value[k].size(); ++v) {
                        const nlohmann::json& pt = value[k][v];
                        if (!pt.is_array() || pt.size() != 2 || !pt[0].is_number() || !pt[1].is_number())
                            fail(source, pk + "/" + std::to_string(v),
                                 "expected a point [x, y] in normalised image coordinates (0..1)");
                        const double x = pt[0].get<double>(), y = pt[1].get<double>();
                        if (x < 0.0 || x > 1.0 || y < 0.0 || y > 1.0)
                            fail(source, pk + "/" + std::to_string(v), "expected coordinates within 0..1");
                        poly.push_back({x, y});
                    }
                    region.polygons.push_back(std::move(poly));
                }
            } else {
                fail(source, p,
                     "unknown key (expected name, doc, polygons, reference_above_median, reference_below_median)");
            }
        }
        if (region.name.empty()) fail(source, at + "/name", "missing: every region needs a name");
        if (region.polygons.empty()) fail(source, at + "/polygons", "missing: every region needs polygons");
        for (const Region& other : set.regions)
            if (other.name == region.name) fail(source, at + "/name", "\"" + region.name + "\" is named twice");
        set.regions.push_back(std::move(region));
    }
    return set;
}

RegionSet loadRegions(const std::filesystem::path& path) {
    std::ifstream in(path);
    if (!in) throw UserError(path.string() + ": cannot read the regions file");
    std::stringstream text;
    text << in.rdbuf();
    nlohmann::json doc;
    try {
        doc = nlohmann::json::parse(text.str());
    } catch (const nlohmann::json::parse_error& e) {
        throw UserError(path.string() + ": not JSON: " + e.what());
    }
    return parseRegions(doc, path.string());
}

std::vector<std::vector<uint8_t>> regionMasks(const RegionSet& set, const Image& reference) {
    const int w = reference.width, h = reference.height;
    // The reference's luminance, 3x3 box-filtered.
    std::vector<double> smooth(static_cast<size_t>(w) * h, 0.0);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            double sum = 0.0;
            int n = 0;
            for (int dy = -1; dy <= 1; ++dy)
                for (int dx = -1; dx <= 1; ++dx) {
                    const int sx = x + dx, sy = y + dy;
                    if (sx < 0 || sy < 0 || sx >= w || sy >= h) continue;
                    sum += luminance(reference.at(sx, sy));
                    ++n;
                }
            smooth[static_cast<size_t>(y) * w + x] = sum / n;
        }
    std::vector<std::vector<uint8_t>> masks;
    for (const Region& region : set.regions) {
        std::vector<uint8_t> mask(static_cast<size_t>(w) * h, 0);
        std::vector<double> values;
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                const double u = (x + 0.5) / w, v = (y + 0.5) / h;
                for (const auto& poly : region.polygons)
                    if (inside(poly, u, v)) {
                        mask[static_cast<size_t>(y) * w + x] = 1;
                        values.push_back(smooth[static_cast<size_t>(y) * w + x]);
                        break;
                    }
            }
        if ((region.referenceAboveMedian || region.referenceBelowMedian) && !values.empty()) {
            auto mid = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
            std::nth_element(values.begin(), mid, values.end());
            const double median = *mid;
            for (size_t i = 0; i < mask.size(); ++i) {
                if (!mask[i]) continue;
                if (region.referenceAboveMedian && !(smooth[i] > *region.referenceAboveMedian * median)) mask[i] = 0;
                if (region.referenceBelowMedian && !(smooth[i] < *region.referenceBelowMedian * median)) mask[i] = 0;
            }
        }
        masks.push_back(std::move(mask));
    }
    return masks;
}

std::vector<RegionRatio> regionLuminanceRatios(const RegionSet& set, const Image& test, const Image& reference,
                                               const Image* flipErrorMap) {
    if (test.width != reference.width || test.height != reference.height || test.empty())
        throw UserError("compare --regions: the images differ in size (" + std::to_string(test.width) + "x" +
                        std::to_string(test.height) + " and " + std::to_string(reference.width) + "x" +
                        std::to_string(reference.height) + ")");
    if (flipErrorMap && (flipErrorMap->width != test.width || flipErrorMap->height != test.height))
        throw UserError("compare --regions: the FLIP error map is " + std::to_string(flipErrorMap->width) + "x" +
                        std::to_string(flipErrorMap->height) + ", the images " + std::to_string(test.width) + "x" +
                        std::to_string(test.height));
    const auto masks = regionMasks(set, reference);
    std::vector<RegionRatio> out;
    for (size_t r = 0; r < set.regions.size(); ++r) {
        RegionRatio rr;
        rr.name = set.regions[r].name;
        double lt = 0.0, lr = 0.0, flip = 0.0;
        for (int y = 0; y < test.height; ++y)
            for (int x = 0; x < test.width; ++x) {
                if (!masks[r][static_cast<size_t>(y) * test.width + x]) continue;
                lt += luminance(test.at(x, y));
                lr += luminance(reference.at(x, y));
                if (flipErrorMap) flip += flipErrorMap->at(x, y)[0];
                ++rr.pixels;
            }
        const double nan = std::numeric_limits<double>::quiet_NaN();
        rr.test = rr.pixels ? lt / rr.pixels : nan;
        rr.reference = rr.pixels ? lr / rr.pixels : nan;
        rr.ratio = rr.pixels && lr > 0.0 ? lt / lr : nan;
        rr.flip = rr.pixels && flipErrorMap ? flip / rr.pixels : nan;
        out.push_back(rr);
    }
    return out;
}

Image regionOverlay(const RegionSet& set, const Image& base) {
    Image out = base;
    const int w = base.width, h = base.height;
    const auto masks = regionMasks(set, base);
    static const float kColors[8][3] = {{1, 0.3f, 0.3f}, {0.3f, 1, 0.3f}, {0.3f, 0.5f, 1}, {1, 1, 0.2f},
                                        {1, 0.3f, 1},    {0.2f, 1, 1},    {1, 0.6f, 0.2f}, {0.6f, 0.4f, 1}};
    for (size_t r = 0; r < masks.size(); ++r) {
        const float* c = kColors[r % 8];
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                const size_t i = static_cast<size_t>(y) * w + x;
                if (!masks[r][i]) continue;
                float* p = out.at(x, y);
                const bool edge = x == 0 || y == 0 || x == w - 1 || y == h - 1 || !masks[r][i - 1] ||
                                  !masks[r][i + 1] || !masks[r][i - w] || !masks[r][i + w];
                for (int k = 0; k < 3; ++k) p[k] = edge ? 1.0f : 0.5f * p[k] + 0.5f * c[k] * std::max(p[k], 0.05f) * 4.0f;
            }
    }
    return out;
}

} // namespace vitrine::compare
