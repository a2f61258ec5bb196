#pragma once

#include "core/image/image.hpp"

#include <nlohmann/json.hpp>

#include <array>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

// Named image regions and their luminance ratio: "the sunlit floor is 10 % short" instead of one whole-frame number.
// A regions file (`compare --regions FILE`, e.g. graphs/regions/museum.regions.json) names parts of a shot by
// polygons in normalised image coordinates (x right, y down, 0..1, so one file serves every resolution), optionally
// split by the reference's own brightness (sunlit against shaded floor):
// {
//   "format": "vitrine-regions/1",
//   "description": string (optional),
//   "regions": [{"name": string, "doc": string (optional),
//                "polygons": [[[x, y], [x, y], [x, y], ...], ...],       (a pixel is in when its centre is in any)
//                "reference_above_median": number (optional), "reference_below_median": number (optional)}]
// }
// reference_above_median k keeps the pixels whose reference luminance (3×3 box-filtered, so path-tracing noise does
// not decide) is above k × the median of that luminance over the region's polygons; below_median likewise.
namespace vitrine::compare {

struct Region {
    std::string name;
    std::string doc;
    std::vector<std::vector<std::array<double, 2>>> polygons;
    std::optional<double> referenceAboveMedian;
    std::optional<double> referenceBelowMedian;
};

struct RegionSet {
    std::string source; // the file, for messages and the report
    std::string description;
    std::vector<Region> regions;
};

// Parses a regions document; errors (UserError) name `source`, the JSON pointer and what was expected.
RegionSet parseRegions(const nlohmann::json& doc, const std::string& source);
// Reads and parses a regions file (UserError when it cannot be read or is not JSON).
RegionSet loadRegions(const std::filesystem::path& path);

// Which pixels of a width × height image each region holds (row-major masks), given the reference image that
// reference_*_median split by.
std::vector<std::vector<uint8_t>> regionMasks(const RegionSet& set, const Image& reference);

struct RegionRatio {
    std::string name;
    int pixels = 0;            // in the region (0: the region is empty at this size; the ratio is NaN)
    double test = 0.0;         // mean Rec. 709 luminance of the test over the region
    double reference = 0.0;    // of the reference
    double ratio = 0.0;        // test / reference (NaN when the reference's mean is 0)
    double flip = 0.0;         // mean of the pair's FLIP error map over the region (NaN without a map, or empty)
};

// The mean luminance of test and reference over each region (masks from regionMasks(set, reference)) and, given
// the pair's FLIP error map (comparePair's flipErrorMap, channel 0; same size), its mean over each region: "FLIP
// on the floor" as well as over the frame. Throws UserError when the images differ in size.
std::vector<RegionRatio> regionLuminanceRatios(const RegionSet& set, const Image& test, const Image& reference,
                                               const Image* flipErrorMap = nullptr);

// The regions drawn over `base` (each region tinted in its own colour, its outline white): which pixels each
// region took, for the report.
Image regionOverlay(const RegionSet& set, const Image& base);

} // namespace vitrine::compare
