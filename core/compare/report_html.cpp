#include "core/compare/report.hpp"

#include "core/base/error.hpp"
#include "core/compare/blocks.hpp"
#include "core/compare/magma.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

// The HTML of report.html. Every piece of caller text goes through escapeHtml(); the script only copies image
// sources between <img> elements and reads labels back from data- attributes, so no caller text reaches JS source.
namespace vitrine::compare {

namespace {

constexpr const char* kStyle = R"css(
:root { color-scheme: dark; --bg: #16171b; --panel: #202228; --text: #e6e6e6; --dim: #9aa0aa; --accent: #f5a742; }
* { box-sizing: border-box; }
body { margin: 0; padding: 24px; background: var(--bg); color: var(--text);
       font: 14px/1.45 system-ui, -apple-system, "Segoe UI", Roboto, sans-serif; }
h1 { margin: 0 0 4px; font-size: 22px; }
h2 { margin: 32px 0 12px; font-size: 17px; border-bottom: 1px solid #333; padding-bottom: 4px; }
.dim { color: var(--dim); }
.row { display: flex; flex-wrap: wrap; gap: 16px; align-items: flex-start; }
figure.card { margin: 0; padding: 8px; background: var(--panel); border-radius: 6px; }
figure.card img { display: block; max-width: min(100%, 640px); height: auto; image-rendering: pixelated; }
figcaption { margin-top: 6px; font-weight: 600; }
.controls { display: flex; gap: 16px; align-items: center; margin-bottom: 8px; flex-wrap: wrap; }
.split-scroll { max-width: 100%; overflow: auto; }
.split { position: relative; display: inline-block; cursor: ew-resize; touch-action: none; user-select: none;
         line-height: 0; }
.split img { display: block; image-rendering: pixelated; pointer-events: none; }
.split img.top { position: absolute; left: 0; top: 0; width: 100%; height: 100%; clip-path: inset(0 50% 0 0); }
.split .handle { position: absolute; top: 0; bottom: 0; left: 50%; width: 2px; margin-left: -1px;
                 background: var(--accent); box-shadow: 0 0 3px #000; }
.split .tag { position: absolute; top: 6px; padding: 2px 6px; font: 12px/1.3 system-ui, sans-serif;
              background: rgba(0, 0, 0, .6); border-radius: 3px; }
.split .tag.left { left: 6px; } .split .tag.right { right: 6px; }
#split-range { width: min(100%, 640px); }
.colorbar { width: 320px; height: 14px; border-radius: 2px; }
.ticks { width: 320px; display: flex; justify-content: space-between; font-size: 12px; color: var(--dim); }
table { border-collapse: collapse; background: var(--panel); }
.table-scroll { max-width: 100%; overflow-x: auto; }
th, td { padding: 5px 10px; border-bottom: 1px solid #333; text-align: right; white-space: nowrap; }
th:first-child, td:first-child { text-align: left; }
th { color: var(--dim); font-weight: 600; }
ul.changes { list-style: none; padding: 0; margin: 0; }
ul.changes li { padding: 4px 0; border-bottom: 1px solid #2a2a2a; }
.op { display: inline-block; min-width: 64px; font-size: 12px; font-weight: 700; text-transform: uppercase; }
.op.added { color: #7bd88f; } .op.removed { color: #fc6a6a; } .op.changed { color: var(--accent); }
code { font-family: ui-monospace, Menlo, Consolas, monospace; font-size: 13px; }
code.old { color: #fc9a9a; } code.new { color: #9ae6a8; }
.noise { font-size: 12px; font-weight: 700; padding: 1px 6px; border-radius: 3px; }
.noise.within { background: #2f5d3a; color: #c9f2d2; } .noise.beyond { background: #5d2f2f; color: #f2c9c9; }
svg.spark polyline { fill: none; stroke: var(--accent); stroke-width: 1.5; }
)css";

// Keeps the split view on the images already in the page instead of embedding their data twice.
constexpr const char* kScript = R"js(
(function () {
  const view = document.getElementById('split-view');
  if (!view) return;
  const top = document.getElementById('split-top'), bottom = document.getElementById('split-bottom');
  const handle = document.getElementById('split-handle'), range = document.getElementById('split-range');
  const leftTag = document.getElementById('split-left-label'), rightTag = document.getElementById('split-right-label');
  const pair = document.getElementById('split-pair'), zoom = document.getElementById('split-zoom');
  function setSplit(fraction) {
    const f = Math.min(1, Math.max(0, fraction));
    top.style.clipPath = 'inset(0 ' + (100 - f * 100) + '% 0 0)';
    handle.style.left = (f * 100) + '%';
    range.value = Math.round(f * 1000);
  }
  function setZoom() {
    const z = parseFloat(zoom.value);
    bottom.style.width = (bottom.naturalWidth * z) + 'px';
  }
  function setPair() {
    const ids = pair.value.split('|');
    const left = document.getElementById(ids[0]), right = document.getElementById(ids[1]);
    top.src = left.src; bottom.src = right.src;
    leftTag.textContent = left.dataset.label; rightTag.textContent = right.dataset.label;
  }
  let dragging = false;
  function fromPointer(e) {
    const r = view.getBoundingClientRect();
    setSplit((e.clientX - r.left) / r.width);
  }
  view.addEventListener('pointerdown', function (e) { dragging = true; view.setPointerCapture(e.pointerId); fromPointer(e); });
  view.addEventListener('pointermove', function (e) { if (dragging) fromPointer(e); });
  view.addEventListener('pointerup', function () { dragging = false; });
  view.addEventListener('pointercancel', function () { dragging = false; });
  range.addEventListener('input', function () { setSplit(range.value / 1000); });
  pair.addEventListener('change', setPair);
  zoom.addEventListener('change', setZoom);
  bottom.addEventListener('load', setZoom);
  setPair();
  setSplit(0.5);
})();
)js";

std::string number(double value, int digits) {
    if (std::isnan(value)) return "n/a";
    if (std::isinf(value)) return value > 0 ? "&infin;" : "&minus;&infin;";
    char buffer[64];
    std::snprintf(buffer, sizeof buffer, "%.*f", digits, value);
    return buffer;
}

std::string dataUri(const ReportImage& image) {
    return "data:image/png;base64," + base64Encode(image.png);
}

void requirePng(const ReportImage& image, const std::string& role) {
    if (image.png.empty())
        throw UserError("compare report: image " + role + " ('" + image.label +
                        "') has no PNG bytes (expected an encoded PNG file)");
}

std::string card(const ReportImage& image, const std::string& id) {
    const std::string label = escapeHtml(image.label);
    std::string html = "<figure class=\"card\"><img id=\"" + id + "\" src=\"" + dataUri(image) + "\" width=\"" +
                       std::to_string(image.width) + "\" height=\"" + std::to_string(image.height) + "\" alt=\"" +
                       label + "\" data-label=\"" + label + "\"><figcaption>" + label + " <span class=\"dim\">" +
                       std::to_string(image.width) + "&times;" + std::to_string(image.height) +
                       "</span></figcaption></figure>\n";
    return html;
}

std::string hexColor(const detail::Rgb& rgb) {
    char buffer[8];
    auto byte = [](float v) { return static_cast<int>(std::lround(std::clamp(v, 0.0f, 1.0f) * 255.0f)); };
    std::snprintf(buffer, sizeof buffer, "#%02x%02x%02x", byte(rgb[0]), byte(rgb[1]), byte(rgb[2]));
    return buffer;
}

std::string colorBar() {
    std::string gradient = "linear-gradient(to right";
    constexpr int kStops = 16;
    for (int i = 0; i <= kStops; ++i) {
        const int index = i * 255 / kStops;
        gradient += ", " + hexColor(detail::magmaSrgb(index)) + " " + number(100.0 * i / kStops, 2) + "%";
    }
    gradient += ")";
    return "<div class=\"colorbar\" style=\"background: " + gradient +
           "\" title=\"FLIP error, 0 (left) to 1 (right)\"></div>\n<div class=\"ticks\"><span>0</span><span>0.25"
           "</span><span>0.5</span><span>0.75</span><span>1</span></div>\n";
}

// Blue (darker) – white – red (brighter), as blockRatioHeatMap() colours blocks.
std::string blockColorBar() {
    std::string gradient = "linear-gradient(to right";
    constexpr int kStops = 8;
    for (int i = 0; i <= kStops; ++i) {
        const SrgbColor c = blockRatioColor(-1.0 + 2.0 * i / kStops);
        gradient += ", " + hexColor({static_cast<float>(c.r), static_cast<float>(c.g), static_cast<float>(c.b)}) + " " +
                    number(100.0 * i / kStops, 2) + "%";
    }
    gradient += ")";
    const SrgbColor grey = blockRatioColor(std::nan(""));
    return "<div class=\"colorbar\" style=\"background: " + gradient +
           "\" title=\"log2(test / reference) of block luminance, -1 stop (left) to +1 stop (right)\"></div>\n"
           "<div class=\"ticks\"><span>&minus;1 stop (darker)</span><span>0</span><span>+1 stop (brighter)</span>"
           "</div>\n<p class=\"dim\">Mean luminance of each " +
           std::to_string(kBlockSize) + "&times;" + std::to_string(kBlockSize) +
           " px block, test over reference, saturated at &plusmn;1 stop; <span style=\"color: " +
           hexColor({static_cast<float>(grey.r), static_cast<float>(grey.g), static_cast<float>(grey.b)}) +
           "\">&#9632;</span> grey: both below the luminance floor (black).</p>\n";
}

std::string noiseBadge(const PairMetrics& m) {
    if (!m.withinReferenceNoise) return "";
    return *m.withinReferenceNoise ? "<span class=\"noise within\">within reference noise</span>"
                                   : "<span class=\"noise beyond\">beyond reference noise</span>";
}

// compare --regions: one row per region, one column per pair (mean luminance test / reference, and the pair's FLIP
// mean over the region).
std::string regionsSection(const RegionTable& t) {
    std::string html = "<h3>Regions</h3>\n<p class=\"dim\">Mean luminance ratio per region (test / reference) and, "
                       "after it, the pair's FLIP mean over the region, from " +
                       escapeHtml(t.source) + (t.description.empty() ? "" : ": " + escapeHtml(t.description)) +
                       "</p>\n<div class=\"table-scroll\"><table><tr><th>region</th><th>pixels</th>";
    for (const RegionTable::Pair& p : t.pairs)
        html += "<th>" + escapeHtml(p.test) + " / " + escapeHtml(p.reference) + "</th>";
    html += "</tr>\n";
    const size_t rows = t.pairs.empty() ? 0 : t.pairs.front().regions.size();
    for (size_t r = 0; r < rows; ++r) {
        html += "<tr><td>" + escapeHtml(t.pairs.front().regions[r].name) + "</td><td>" +
                std::to_string(t.pairs.front().regions[r].pixels) + "</td>";
        for (const RegionTable::Pair& p : t.pairs) {
            char cell[64];
            const double v = p.regions[r].ratio, f = p.regions[r].flip;
            if (std::isfinite(v) && std::isfinite(f))
                std::snprintf(cell, sizeof cell, "%.3f · FLIP %.4f", v, f);
            else if (std::isfinite(v))
                std::snprintf(cell, sizeof cell, "%.3f", v);
            else std::snprintf(cell, sizeof cell, "–");
            html += std::string("<td>") + cell + "</td>";
        }
        html += "</tr>\n";
    }
    html += "</table></div>\n";
    if (t.overlay) {
        requirePng(*t.overlay, "regions overlay");
        html += "<div class=\"row\">" + card(*t.overlay, "img-regions") + "</div>\n";
    }
    return html;
}

std::string noiseFloorSection(const NoiseFloor& n) {
    std::string html = "<p id=\"noise-floor\">Noise floor: ";
    if (n.status == NoiseFloor::Status::Measured && n.pair) {
        html += "FLIP mean <b>" + number(n.pair->flip.mean, 5) + "</b> between the reference and " +
                escapeHtml(n.pair->test) + " (" + escapeHtml(n.reason) + "); blocks within &plusmn;" +
                number(100.0 * kBlockTolerance, 0) + " %: " + number(100.0 * n.pair->blocks.withinShare, 1) +
                " %, mean |log2 ratio| " + number(n.pair->blocks.meanAbsLog2, 4) +
                ". Pairs against the reference whose FLIP mean is at most " + number(n.factor, 1) +
                "&times; the floor (" + number(n.factor * n.pair->flip.mean, 5) +
                ") are within reference noise: FLIP cannot tell them from the reference.";
    } else {
        html += std::string(n.status == NoiseFloor::Status::Skipped ? "skipped" : "unknown") + " (" +
                escapeHtml(n.reason) + ").";
    }
    return html + "</p>\n";
}

std::string splitSection(const std::vector<std::pair<std::string, const ReportImage*>>& images) {
    std::string options;
    for (size_t i = 0; i < images.size(); ++i) {
        for (size_t j = i + 1; j < images.size(); ++j) {
            options += "<option value=\"" + images[i].first + "|" + images[j].first + "\">" +
                       escapeHtml(images[i].second->label) + " | " + escapeHtml(images[j].second->label) + "</option>";
        }
    }
    return "<section id=\"split\"><h2>Split view</h2>\n<div class=\"controls\"><label>Pair <select id=\"split-pair\">" +
           options +
           "</select></label><label>Zoom <select id=\"split-zoom\"><option value=\"1\">1&times;</option>"
           "<option value=\"2\">2&times;</option><option value=\"4\">4&times;</option>"
           "<option value=\"8\">8&times;</option></select></label>"
           "<span class=\"dim\">Drag on the image to move the split.</span></div>\n"
           "<div class=\"split-scroll\"><div class=\"split\" id=\"split-view\"><img id=\"split-bottom\" alt=\"\">"
           "<img id=\"split-top\" class=\"top\" alt=\"\"><div class=\"handle\" id=\"split-handle\"></div>"
           "<span class=\"tag left\" id=\"split-left-label\"></span>"
           "<span class=\"tag right\" id=\"split-right-label\"></span></div></div>\n"
           "<input type=\"range\" id=\"split-range\" min=\"0\" max=\"1000\" value=\"500\" "
           "aria-label=\"Split position\">\n</section>\n";
}

std::string metricsTable(const std::vector<PairMetrics>& metrics) {
    std::string html = "<table><thead><tr><th>Pair</th><th>PSNR (dB)</th><th>SSIM</th><th>FLIP mean</th>"
                       "<th>FLIP weighted median</th><th>FLIP Q1</th><th>FLIP Q3</th><th>FLIP min</th>"
                       "<th>FLIP max</th><th>FLIP variant</th><th>Blocks within &plusmn;15 %</th>"
                       "<th>Mean |log2 block ratio|</th><th>Reference noise</th></tr></thead><tbody>\n";
    for (const PairMetrics& m : metrics) {
        html += "<tr><td>" + escapeHtml(m.test) + " vs " + escapeHtml(m.reference) + "</td><td>" + number(m.psnr, 2) +
                "</td><td>" + number(m.ssim, 5) + "</td><td>" + number(m.flip.mean, 5) + "</td><td>" +
                number(m.flip.weightedMedian, 5) + "</td><td>" + number(m.flip.q1, 5) + "</td><td>" +
                number(m.flip.q3, 5) + "</td><td>" + number(m.flip.minimum, 5) + "</td><td>" +
                number(m.flip.maximum, 5) + "</td><td>" + (m.hdrFlip ? "HDR" : "LDR") + ", " +
                number(m.pixelsPerDegree, 1) + " ppd</td><td>" + number(100.0 * m.blocks.withinShare, 1) +
                " %</td><td>" + number(m.blocks.meanAbsLog2, 4) + "</td><td>" + noiseBadge(m) + "</td></tr>\n";
    }
    return html + "</tbody></table>\n";
}

// A small line chart of the per-frame error; infinite values (identical frames) are drawn at the top.
std::string sparkline(const std::vector<double>& values) {
    if (values.empty()) return "<span class=\"dim\">no reference</span>";
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (double v : values) {
        if (std::isfinite(v)) {
            lo = std::min(lo, v);
            hi = std::max(hi, v);
        }
    }
    if (!std::isfinite(lo)) lo = hi = 0.0;
    constexpr double kWidth = 240.0, kHeight = 40.0;
    std::string points;
    for (size_t i = 0; i < values.size(); ++i) {
        const double v = std::isfinite(values[i]) ? values[i] : (values[i] > 0 ? hi : lo);
        const double x = values.size() > 1 ? kWidth * i / (values.size() - 1) : kWidth / 2;
        const double y = hi > lo ? kHeight - 2 - (kHeight - 4) * (v - lo) / (hi - lo) : kHeight / 2;
        points += number(x, 1) + "," + number(y, 1) + " ";
    }
    return "<svg class=\"spark\" width=\"240\" height=\"40\" viewBox=\"0 0 240 40\"><polyline points=\"" + points +
           "\"/></svg> <span class=\"dim\">" + number(lo, 4) + " &ndash; " + number(hi, 4) + "</span>";
}

std::string temporalTable(const std::vector<TemporalMetrics>& temporal) {
    std::string html = "<table><thead><tr><th>Sequence</th><th>Frames</th><th>Flicker</th>"
                       "<th>Motion-compensated flicker</th><th>Error per frame</th></tr></thead><tbody>\n";
    for (const TemporalMetrics& t : temporal) {
        const char* metric = t.errorMetric == FrameMetric::Psnr ? "PSNR dB" : "FLIP mean";
        html += "<tr><td>" + escapeHtml(t.label) + "</td><td>" + std::to_string(t.frameCount) + "</td><td>" +
                number(t.flicker, 5) + "</td><td>" +
                (t.flickerMotionCompensated ? number(*t.flickerMotionCompensated, 5) : std::string("n/a")) +
                "</td><td>" + (t.errorPerFrame.empty() ? "" : std::string(metric) + " ") + sparkline(t.errorPerFrame) +
                "</td></tr>\n";
    }
    return html + "</tbody></table>\n";
}

// Long values (a whole node added) are cut so the list stays readable; metrics.json keeps them whole.
std::string shortJson(const nlohmann::json& value) {
    constexpr size_t kMax = 240;
    std::string text = value.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
    if (text.size() > kMax) text = text.substr(0, kMax) + " …";
    return escapeHtml(text);
}

std::string changesSection(const ReportInput& input) {
    std::string html = "<section id=\"changes\"><h2>What differs</h2>\n";
    if (input.graphA.is_null() || input.graphB.is_null())
        return html + "<p class=\"dim\">The graph documents were not given.</p></section>\n";
    const std::vector<GraphChange> changes = diffGraphs(input.graphA, input.graphB);
    if (changes.empty())
        return html + "<p class=\"dim\">The two graphs are identical (editor layout blocks ignored).</p></section>\n";
    html += "<ul class=\"changes\">\n";
    for (const GraphChange& c : changes) {
        const std::string pointer = "<code>" + escapeHtml(c.pointer.empty() ? "/" : c.pointer) + "</code>";
        switch (c.kind) {
        case GraphChange::Kind::Added:
            html += "<li><span class=\"op added\">added</span> " + pointer + " = <code class=\"new\">" +
                    shortJson(c.after) + "</code></li>\n";
            break;
        case GraphChange::Kind::Removed:
            html += "<li><span class=\"op removed\">removed</span> " + pointer + " (was <code class=\"old\">" +
                    shortJson(c.before) + "</code>)</li>\n";
            break;
        case GraphChange::Kind::Changed:
            html += "<li><span class=\"op changed\">changed</span> " + pointer + ": <code class=\"old\">" +
                    shortJson(c.before) + "</code> &rarr; <code class=\"new\">" + shortJson(c.after) + "</code></li>\n";
            break;
        }
    }
    return html + "</ul></section>\n";
}

} // namespace

std::string renderReportHtml(const ReportInput& input) {
    requirePng(input.a, "A");
    requirePng(input.b, "B");
    if (input.reference) requirePng(*input.reference, "reference");

    std::vector<std::pair<std::string, const ReportImage*>> images = {{"img-a", &input.a}, {"img-b", &input.b}};
    if (input.reference) images.emplace_back("img-reference", &*input.reference);
    if (input.reference && input.referenceHalf) {
        requirePng(*input.referenceHalf, "reference half");
        images.emplace_back("img-reference-half", &*input.referenceHalf);
    }

    const std::string title = escapeHtml(input.title);
    std::string html = "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
                       "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n<title>" +
                       title + "</title>\n<style>" + kStyle + "</style>\n</head>\n<body>\n<header><h1>" + title +
                       "</h1><div class=\"dim\">vitrine compare &mdash; self-contained report</div></header>\n";

    html += "<section id=\"images\"><h2>Images</h2>\n<div class=\"row\">\n";
    for (const auto& [id, image] : images)
        html += card(*image, id);
    html += "</div></section>\n";

    html += splitSection(images);

    if (!input.differenceMaps.empty() || !input.flipMaps.empty() || !input.blockMaps.empty()) {
        html += "<section id=\"errors\"><h2>Error maps</h2>\n";
        if (!input.differenceMaps.empty()) {
            html += "<h3>Absolute difference</h3>\n<div class=\"row\">\n";
            for (size_t i = 0; i < input.differenceMaps.size(); ++i) {
                requirePng(input.differenceMaps[i], "difference map");
                html += card(input.differenceMaps[i], "img-difference-" + std::to_string(i));
            }
            html += "</div>\n";
        }
        if (!input.flipMaps.empty()) {
            html += "<h3>FLIP</h3>\n<div class=\"row\">\n";
            for (size_t i = 0; i < input.flipMaps.size(); ++i) {
                requirePng(input.flipMaps[i], "FLIP map");
                html += card(input.flipMaps[i], "img-flip-" + std::to_string(i));
            }
            html += "</div>\n" + colorBar();
        }
        if (!input.blockMaps.empty()) {
            html += "<h3>Block luminance ratio</h3>\n<div class=\"row\">\n";
            for (size_t i = 0; i < input.blockMaps.size(); ++i) {
                requirePng(input.blockMaps[i], "block ratio map");
                html += card(input.blockMaps[i], "img-blocks-" + std::to_string(i));
            }
            html += "</div>\n" + blockColorBar();
        }
        html += "</section>\n";
    }

    html += "<section id=\"metrics\"><h2>Metrics</h2>\n";
    html += input.metrics.empty() ? "<p class=\"dim\">No metrics were computed.</p>\n"
                                  : "<div class=\"table-scroll\">" + metricsTable(input.metrics) + "</div>\n";
    if (input.noiseFloor) html += noiseFloorSection(*input.noiseFloor);
    if (!input.temporal.empty()) html += "<h3>Temporal</h3>\n" + temporalTable(input.temporal);
    if (input.regions) html += regionsSection(*input.regions);
    html += "</section>\n";

    html += changesSection(input);
    html += "<script>" + std::string(kScript) + "</script>\n</body>\n</html>\n";
    return html;
}

} // namespace vitrine::compare
