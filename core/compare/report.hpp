#pragma once

#include "core/compare/blocks.hpp"
#include "core/compare/metrics.hpp"
#include "core/compare/regions.hpp"

#include <nlohmann/json.hpp>

#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

// The output of `vitrine compare A B [--reference R]`: one self-contained report.html (inline CSS and JS, images as
// data: URIs, nothing fetched from the network) and the metrics.json document. The CLI computes the metrics with
// comparePair()/flicker()/errorPerFrame(), encodes the images as PNG with core/image, fills a ReportInput and calls
// writeReport() and metricsJson(). This module never encodes PNG itself.
namespace vitrine::compare {

struct ReportImage {
    std::string label;              // shown as the caption; any text, it is escaped
    std::vector<unsigned char> png; // the bytes of a PNG file
    int width = 0;
    int height = 0;
};

// PSNR, SSIM, FLIP and the block luminance ratio of one image against another.
struct PairMetrics {
    std::string test;      // label of the image judged, e.g. "A"
    std::string reference; // label of what it is judged against, e.g. "B" or "reference"
    double psnr = 0.0;     // dB; +infinity when the images are identical
    double ssim = 0.0;
    FlipStatistics flip;
    bool hdrFlip = false; // HDR-FLIP (scene-referred inputs) rather than LDR-FLIP
    double pixelsPerDegree = kDefaultPixelsPerDegree;
    BlockRatioStatistics blocks; // test / reference, per 16×16 block (core/compare/blocks.hpp)
    // Against the reference, when its noise floor was measured: FLIP mean <= kNoiseFloorFactor × the floor's FLIP
    // mean. Unset for pairs not against the reference and when the floor is unknown or was skipped.
    std::optional<bool> withinReferenceNoise;
};

// A pair whose FLIP mean is at most this many times the noise floor's is "within reference noise".
inline constexpr double kNoiseFloorFactor = 1.5;

// The noise of the reference itself: FLIP (and the block measure) between the reference and a second, independent
// reference half (the same graph with every render.pathtrace node's seed changed, or a --reference-half file).
struct NoiseFloor {
    enum class Status { Measured, Unknown, Skipped };
    Status status = Status::Unknown;
    std::string reason; // why Unknown or Skipped; how the second half was made when Measured
    double factor = kNoiseFloorFactor;
    // Measured only: the second half (test) against the reference; pair->flip.mean is the noise floor.
    std::optional<PairMetrics> pair;

    // flipMean <= factor × the floor's FLIP mean; false unless Measured.
    bool contains(double flipMean) const {
        return status == Status::Measured && pair && flipMean <= factor * pair->flip.mean;
    }
};

struct PairOptions {
    bool hdr = false; // use HDR-FLIP with automatic exposures; otherwise LDR-FLIP (inputs display-referred)
    double pixelsPerDegree = kDefaultPixelsPerDegree;
    double psnrPeak = 1.0;
};

struct PairComparison {
    PairMetrics metrics;
    Image flipErrorMap;          // for flipColorMap() and the report
    BlockRatioResult blockRatio; // for blockRatioHeatMap() and the report
};

// Runs the metrics on one pair; FLIP treats `reference` as the paper's reference image, and the block ratio is
// test / reference.
PairComparison comparePair(const std::string& testLabel, const Image& test, const std::string& referenceLabel,
                           const Image& reference, const PairOptions& options = {});

// Temporal stability of one rendered sequence (e.g. A's frames).
struct TemporalMetrics {
    std::string label;
    int frameCount = 0;
    double flicker = 0.0;
    std::optional<double> flickerMotionCompensated; // absent when no velocities were rendered
    FrameMetric errorMetric = FrameMetric::Psnr;
    std::vector<double> errorPerFrame; // against the reference sequence; empty when there is none
};

// One difference between two graph documents.
struct GraphChange {
    enum class Kind { Added, Removed, Changed };
    Kind kind = Kind::Changed;
    std::string pointer;   // RFC 6901 JSON pointer, e.g. "/nodes/aa/type"
    nlohmann::json before; // the old value (unset for Added)
    nlohmann::json after;  // the new value (unset for Removed)
};

// What differs between two graph documents, in document order (object keys sorted, array elements by index). Pass
// the resolved documents (after "extends" and merge patches) so the list shows what actually renders differently.
// The editor-only "ui" blocks (top level and per node) are ignored because the renderer ignores them. Array
// elements are compared index by index: an insertion shows as changes of the following elements.
std::vector<GraphChange> diffGraphs(const nlohmann::json& a, const nlohmann::json& b);

// compare --regions: the mean luminance ratio of each named region, for each pair (test / reference).
struct RegionTable {
    std::string source;      // the regions file
    std::string description; // its description
    struct Pair {
        std::string test, reference;
        std::vector<RegionRatio> regions;
    };
    std::vector<Pair> pairs;
    std::optional<ReportImage> overlay; // regionOverlay() of the reference (or B) as PNG
};

struct ReportInput {
    std::string title = "vitrine compare";
    ReportImage a;
    ReportImage b;
    std::optional<ReportImage> reference;
    std::vector<ReportImage> differenceMaps;  // e.g. falseColor(absoluteDifference(A, B), …) as PNG
    std::vector<ReportImage> flipMaps;        // flipColorMap() of FLIP error maps as PNG; shown with a colour bar
    std::vector<ReportImage> blockMaps;       // blockRatioHeatMap() of each pair as PNG; shown with a colour bar
    std::optional<ReportImage> referenceHalf; // the second reference half, when the noise floor was measured
    std::vector<PairMetrics> metrics;         // A vs B, A vs R, B vs R …
    std::optional<NoiseFloor> noiseFloor;     // set whenever there is a reference
    std::vector<TemporalMetrics> temporal;
    std::optional<RegionTable> regions;
    nlohmann::json graphA; // graph documents for "what differs"; null when not known
    nlohmann::json graphB;
};

// The HTML page writeReport() writes. Throws UserError when A or B has no PNG bytes.
std::string renderReportHtml(const ReportInput& input);

// Writes renderReportHtml(input) to `path` (typically DIR/report.html). Throws UserError when it cannot be written.
void writeReport(const std::filesystem::path& path, const ReportInput& input);

// The metrics.json document, for scripts and CI thresholds:
// {
//   "format": "vitrine-compare/1",
//   "title": string,
//   "images": {"a": IMAGE, "b": IMAGE, "reference": IMAGE (only with a reference),
//              "referenceHalf": IMAGE (only when the noise floor was measured)},
//             IMAGE = {"label": string, "width": int, "height": int}
//   "pairs": [{"test": label, "reference": label,
//              "psnr": number | null (null: identical images, PSNR = +inf), "ssim": number,
//              "flip": FLIP,
//              "blocks": BLOCKS (test / reference),
//              "withinReferenceNoise": bool | null (null: not a pair against the reference, or no noise floor)}],
//             FLIP = {"mode": "ldr" | "hdr", "pixelsPerDegree": number, "mean": number,
//                     "weightedMedian": number, "q1": number, "q3": number, "min": number, "max": number}
//             BLOCKS = {"size": int (px, 16), "blocksX": int, "blocksY": int, "lit": int, "dark": int,
//                       "floor": number (absolute luminance: 1 % of the reference's mean luminance),
//                       "tolerance": 0.15, "withinShare": number (share of lit blocks with |ratio - 1| <= 0.15),
//                       "meanAbsLog2": number (stops), "meanAbsRelative": number (mean |ratio - 1|)}
//   "noiseFloor": null (no reference) |
//                 {"status": "measured" | "unknown" | "skipped", "reason": string, "factor": 1.5,
//                  "half": label (measured only), "flip": FLIP (measured only: reference half vs reference),
//                  "blocks": BLOCKS (measured only)},
//   "temporal": [{"label": string, "frames": int, "flicker": number,
//                 "flickerMotionCompensated": number | null (null: no velocities),
//                 "errorPerFrame": {"metric": "psnr" | "flip-mean", "values": [number | null, …]}}],
//   "graphChanges": [{"op": "added" | "removed" | "changed", "pointer": string,
//                     "before": any (not for "added"), "after": any (not for "removed")}]
//                   (an empty array when the graphs are equal or either was not given)
// }
nlohmann::json metricsJson(const ReportInput& input);

// Text → HTML text or attribute value: escapes & < > " '.
std::string escapeHtml(std::string_view text);

// RFC 4648 base64 with padding, for data: URIs.
std::string base64Encode(std::span<const unsigned char> bytes);

} // namespace vitrine::compare
