#include "core/compare/report.hpp"

#include "core/base/atomic_file.hpp"
#include "core/base/error.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <set>

namespace vitrine::compare {

namespace {

std::string escapePointerToken(const std::string& key) {
    std::string out;
    for (char c : key) {
        if (c == '~')
            out += "~0";
        else if (c == '/')
            out += "~1";
        else
            out += c;
    }
    return out;
}

// The editor's layout blocks: "/ui" and "/nodes/<id>/ui".
bool isUiBlock(const std::vector<std::string>& parents, const std::string& key) {
    return key == "ui" && (parents.empty() || (parents.size() == 2 && parents[0] == "nodes"));
}

void diffValues(const nlohmann::json& a, const nlohmann::json& b, std::vector<std::string>& parents,
                const std::string& pointer, std::vector<GraphChange>& out) {
    if (a.is_object() && b.is_object()) {
        std::set<std::string> keys;
        for (const auto& [key, value] : a.items())
            keys.insert(key);
        for (const auto& [key, value] : b.items())
            keys.insert(key);
        for (const std::string& key : keys) {
            if (isUiBlock(parents, key)) continue;
            const std::string child = pointer + "/" + escapePointerToken(key);
            const bool inA = a.contains(key), inB = b.contains(key);
            if (inA && !inB) {
                out.push_back({GraphChange::Kind::Removed, child, a.at(key), {}});
            } else if (!inA && inB) {
                out.push_back({GraphChange::Kind::Added, child, {}, b.at(key)});
            } else {
                parents.push_back(key);
                diffValues(a.at(key), b.at(key), parents, child, out);
                parents.pop_back();
            }
        }
        return;
    }
    if (a.is_array() && b.is_array()) {
        const size_t common = std::min(a.size(), b.size());
        for (size_t i = 0; i < std::max(a.size(), b.size()); ++i) {
            const std::string child = pointer + "/" + std::to_string(i);
            if (i >= common && i < a.size()) {
                out.push_back({GraphChange::Kind::Removed, child, a[i], {}});
            } else if (i >= common) {
                out.push_back({GraphChange::Kind::Added, child, {}, b[i]});
            } else {
                parents.push_back(std::to_string(i));
                diffValues(a[i], b[i], parents, child, out);
                parents.pop_back();
            }
        }
        return;
    }
    if (a != b) out.push_back({GraphChange::Kind::Changed, pointer, a, b});
}

const char* kindName(GraphChange::Kind kind) {
    switch (kind) {
    case GraphChange::Kind::Added:
        return "added";
    case GraphChange::Kind::Removed:
        return "removed";
    case GraphChange::Kind::Changed:
        return "changed";
    }
    return "changed";
}

// JSON has no infinity; metrics.json documents null for it.
nlohmann::json finiteOrNull(double value) {
    return std::isfinite(value) ? nlohmann::json(value) : nlohmann::json(nullptr);
}

nlohmann::json imageJson(const ReportImage& image) {
    return {{"label", image.label}, {"width", image.width}, {"height", image.height}};
}

nlohmann::json flipJson(const FlipStatistics& flip, bool hdr, double pixelsPerDegree) {
    return {{"mode", hdr ? "hdr" : "ldr"},
            {"pixelsPerDegree", pixelsPerDegree},
            {"mean", flip.mean},
            {"weightedMedian", flip.weightedMedian},
            {"q1", flip.q1},
            {"q3", flip.q3},
            {"min", flip.minimum},
            {"max", flip.maximum}};
}

nlohmann::json blocksJson(const BlockRatioStatistics& b) {
    return {{"size", b.blockSize},          {"blocksX", b.blocksX},
            {"blocksY", b.blocksY},         {"lit", b.litBlocks},
            {"dark", b.darkBlocks},         {"floor", b.floor},
            {"tolerance", kBlockTolerance}, {"withinShare", b.withinShare},
            {"meanAbsLog2", b.meanAbsLog2}, {"meanAbsRelative", b.meanAbsRelative}};
}

const char* statusName(NoiseFloor::Status status) {
    switch (status) {
    case NoiseFloor::Status::Measured:
        return "measured";
    case NoiseFloor::Status::Unknown:
        return "unknown";
    case NoiseFloor::Status::Skipped:
        return "skipped";
    }
    return "unknown";
}

} // namespace

PairComparison comparePair(const std::string& testLabel, const Image& test, const std::string& referenceLabel,
                           const Image& reference, const PairOptions& options) {
    PairComparison result;
    PairMetrics& m = result.metrics;
    m.test = testLabel;
    m.reference = referenceLabel;
    m.psnr = psnr(test, reference, options.psnrPeak);
    m.ssim = ssim(test, reference).mean;
    m.hdrFlip = options.hdr;
    m.pixelsPerDegree = options.pixelsPerDegree;
    FlipResult flip;
    if (options.hdr) {
        HdrFlipOptions hdrOptions;
        hdrOptions.pixelsPerDegree = options.pixelsPerDegree;
        flip = hdrFlip(reference, test, hdrOptions);
    } else {
        flip = ldrFlip(reference, test, options.pixelsPerDegree);
    }
    m.flip = flip;
    result.flipErrorMap = std::move(flip.errorMap);
    result.blockRatio = blockLuminanceRatio(test, reference);
    m.blocks = result.blockRatio;
    return result;
}

std::vector<GraphChange> diffGraphs(const nlohmann::json& a, const nlohmann::json& b) {
    std::vector<GraphChange> changes;
    std::vector<std::string> parents;
    diffValues(a, b, parents, "", changes);
    return changes;
}

nlohmann::json metricsJson(const ReportInput& input) {
    nlohmann::json doc;
    doc["format"] = "vitrine-compare/1";
    doc["title"] = input.title;
    doc["images"] = {{"a", imageJson(input.a)}, {"b", imageJson(input.b)}};
    if (input.reference) doc["images"]["reference"] = imageJson(*input.reference);
    if (input.referenceHalf) doc["images"]["referenceHalf"] = imageJson(*input.referenceHalf);

    doc["pairs"] = nlohmann::json::array();
    for (const PairMetrics& m : input.metrics) {
        doc["pairs"].push_back({
            {"test", m.test},
            {"reference", m.reference},
            {"psnr", finiteOrNull(m.psnr)},
            {"ssim", m.ssim},
            {"flip", flipJson(m.flip, m.hdrFlip, m.pixelsPerDegree)},
            {"blocks", blocksJson(m.blocks)},
            {"withinReferenceNoise",
             m.withinReferenceNoise ? nlohmann::json(*m.withinReferenceNoise) : nlohmann::json(nullptr)},
        });
    }

    doc["noiseFloor"] = nullptr;
    if (input.noiseFloor) {
        const NoiseFloor& n = *input.noiseFloor;
        nlohmann::json floor = {{"status", statusName(n.status)}, {"reason", n.reason}, {"factor", n.factor}};
        if (n.status == NoiseFloor::Status::Measured && n.pair) {
            floor["half"] = n.pair->test;
            floor["flip"] = flipJson(n.pair->flip, n.pair->hdrFlip, n.pair->pixelsPerDegree);
            floor["blocks"] = blocksJson(n.pair->blocks);
        }
        doc["noiseFloor"] = std::move(floor);
    }

    doc["regions"] = nullptr;
    if (input.regions) {
        nlohmann::json pairs = nlohmann::json::array();
        for (const RegionTable::Pair& p : input.regions->pairs) {
            nlohmann::json list = nlohmann::json::array();
            for (const RegionRatio& r : p.regions)
                list.push_back({{"name", r.name},
                                {"pixels", r.pixels},
                                {"test", finiteOrNull(r.test)},
                                {"reference", finiteOrNull(r.reference)},
                                {"ratio", finiteOrNull(r.ratio)},
                                {"flip", finiteOrNull(r.flip)}});
            pairs.push_back({{"test", p.test}, {"reference", p.reference}, {"regions", list}});
        }
        doc["regions"] = {{"source", input.regions->source}, {"pairs", pairs}};
    }

    doc["temporal"] = nlohmann::json::array();
    for (const TemporalMetrics& t : input.temporal) {
        nlohmann::json values = nlohmann::json::array();
        for (double v : t.errorPerFrame)
            values.push_back(finiteOrNull(v));
        doc["temporal"].push_back({
            {"label", t.label},
            {"frames", t.frameCount},
            {"flicker", t.flicker},
            {"flickerMotionCompensated",
             t.flickerMotionCompensated ? nlohmann::json(*t.flickerMotionCompensated) : nlohmann::json(nullptr)},
            {"errorPerFrame",
             {{"metric", t.errorMetric == FrameMetric::Psnr ? "psnr" : "flip-mean"}, {"values", values}}},
        });
    }

    doc["graphChanges"] = nlohmann::json::array();
    const bool haveGraphs = !input.graphA.is_null() && !input.graphB.is_null();
    for (const GraphChange& c : haveGraphs ? diffGraphs(input.graphA, input.graphB) : std::vector<GraphChange>{}) {
        nlohmann::json change = {{"op", kindName(c.kind)}, {"pointer", c.pointer}};
        if (c.kind != GraphChange::Kind::Added) change["before"] = c.before;
        if (c.kind != GraphChange::Kind::Removed) change["after"] = c.after;
        doc["graphChanges"].push_back(std::move(change));
    }
    return doc;
}

void writeReport(const std::filesystem::path& path, const ReportInput& input) {
    writeFileAtomically(path, renderReportHtml(input));
}

std::string escapeHtml(std::string_view text) {
    std::string out;
    out.reserve(text.size());
    for (char c : text) {
        switch (c) {
        case '&':
            out += "&amp;";
            break;
        case '<':
            out += "&lt;";
            break;
        case '>':
            out += "&gt;";
            break;
        case '"':
            out += "&quot;";
            break;
        case '\'':
            out += "&#39;";
            break;
        default:
            out += c;
        }
    }
    return out;
}

std::string base64Encode(std::span<const unsigned char> bytes) {
    static constexpr char kAlphabet[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out;
    out.reserve((bytes.size() + 2) / 3 * 4);
    size_t i = 0;
    for (; i + 2 < bytes.size(); i += 3) {
        const unsigned v = (bytes[i] << 16) | (bytes[i + 1] << 8) | bytes[i + 2];
        out += kAlphabet[(v >> 18) & 63];
        out += kAlphabet[(v >> 12) & 63];
        out += kAlphabet[(v >> 6) & 63];
        out += kAlphabet[v & 63];
    }
    if (i + 1 == bytes.size()) {
        const unsigned v = bytes[i] << 16;
        out += kAlphabet[(v >> 18) & 63];
        out += kAlphabet[(v >> 12) & 63];
        out += "==";
    } else if (i + 2 == bytes.size()) {
        const unsigned v = (bytes[i] << 16) | (bytes[i + 1] << 8);
        out += kAlphabet[(v >> 18) & 63];
        out += kAlphabet[(v >> 12) & 63];
        out += kAlphabet[(v >> 6) & 63];
        out += '=';
    }
    return out;
}

} // namespace vitrine::compare
