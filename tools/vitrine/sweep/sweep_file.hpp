#pragma once

#include <nlohmann/json.hpp>

#include <cstdint>
#include <filesystem>
#include <optional>
#include <set>
#include <string>
#include <vector>

// The sweep file (`"format": "vitrine-sweep/1"`, README "Sweeps"): a base graph, an optional reference graph, axes
// (a `--set` key with values, variant files, frame ranges) combined as a product or zipped, extra points, the metrics
// to record and the images to keep. parseSweepFile() validates it (errors name the file, the JSON pointer and what
// was expected); expandPoints() lists the points in a stable order. Used by `vitrine sweep` (driver, --point,
// --collect) and by the CPU tests; no GPU here.
namespace vitrine::sweep {

// Which frames a point renders: the graph's own (the still is its last frame), one still frame N (N + 1 frames
// rendered) or FIRST:LAST (LAST + 1 frames rendered; flicker over FIRST..LAST, the still is LAST): what
// `vitrine compare --frame N` / `--frames A:B` do.
struct FrameSpec {
    bool graphDefault = true;
    bool temporal = false;
    uint32_t first = 0;
    uint32_t last = 0;
    std::string text() const; // "" (graph default), "7" or "0:15"
};

// "7" or "0:15" (also the JSON number 7). std::nullopt when `value` is neither.
std::optional<FrameSpec> parseFrameSpec(const nlohmann::json& value);

enum class AxisKind { Set, Variant, Frames };

struct Axis {
    std::string name;
    AxisKind kind = AxisKind::Set;
    std::string key;                  // Set: e.g. "fxaa.params.subpix"
    std::vector<nlohmann::json> values; // Set: JSON values; Variant: file names as written; Frames: "0:15" / 7
    std::vector<std::filesystem::path> variantPaths; // Variant: resolved from the sweep file's directory
    std::vector<FrameSpec> frameSpecs;                // Frames
};

// One point of the sweep, what one process renders.
struct Point {
    std::string id;    // "p0003": the index in expansion order, stable for a given sweep file
    std::string label; // "subpix=0.5, variant=no_fxaa"
    std::filesystem::path graph;   // the base graph or the variant file
    std::vector<std::string> sets; // --set assignments in order: frame size, fixed sets, axis sets
    FrameSpec frames;
    nlohmann::json values = nlohmann::json::object(); // axis name -> value (variants: the file's stem)
};

struct SweepFile {
    std::filesystem::path file;
    std::string description;
    std::filesystem::path graph;
    std::optional<std::filesystem::path> reference;
    std::string output; // the graph output compared; "" picks it like `vitrine compare`
    uint32_t width = 0; // 0: the graph's own
    uint32_t height = 0;
    std::vector<std::string> sets; // fixed --set assignments for every point (not the reference)
    FrameSpec frames;
    std::vector<Axis> axes;
    bool zip = false;
    std::vector<Point> extraPoints; // "points": explicit points after the axes' expansion (id and label filled later)
    std::vector<std::string> metrics; // in the file's order: flip, ssim, psnr, flicker, gpu_ms, memory
    std::set<std::string> keep;       // image, reference, diff, flip, report
    nlohmann::json document;

    bool wants(const std::string& metric) const;
    // The --set assignments of the frame size ("frame.width=W", ...), for points and the reference alike.
    std::vector<std::string> sizeSets() const;
};

inline constexpr const char* kFormat = "vitrine-sweep/1";
extern const std::vector<std::string> kMetricNames;
extern const std::vector<std::string> kKeepNames;

// Reads and validates `path`. UserError naming the file, the JSON pointer and what was expected: not JSON, wrong
// "format", unknown keys, unknown axis kind, a --set key whose node is not in the base graph or whose param the
// node's type does not have, a missing graph or variant file, zip axes of unequal length, an unknown metric.
// Values of --set axes are not range-checked here: a value the graph rejects makes that point fail, not the sweep.
SweepFile parseSweepFile(const std::filesystem::path& path);

// Every point: the axes combined (product: the first axis varies slowest; zip: the i-th values together), then the
// extra points. Ids p0000, p0001, ... in this order.
std::vector<Point> expandPoints(const SweepFile& sweep);

// The point with this id ("p0003") or index ("3"); UserError listing the range when there is none.
const Point& findPoint(const std::vector<Point>& points, const std::string& idOrIndex);

} // namespace vitrine::sweep
