// DIR/report.html of a sweep: one SVG plot per recorded metric and axis, quality (FLIP) against cost (GPU ms) with the
// Pareto front, and a table of points with thumbnails and links to each point's compare report. Self-contained: inline
// CSS and SVG, no script, images by relative links into DIR/points/.
#include "tools/vitrine/sweep/collect.hpp"

#include "core/compare/report.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>

namespace vitrine::sweep {

namespace {

using compare::escapeHtml;
using nlohmann::json;

const char* kPalette[] = {"#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#17becf", "#8c564b", "#e377c2"};

std::string fmt(double v) {
    char buf[32];
    if (v != 0.0 && (std::fabs(v) >= 1e5 || std::fabs(v) < 1e-3)) std::snprintf(buf, sizeof buf, "%.3g", v);
    else std::snprintf(buf, sizeof buf, "%.4g", v);
    return buf;
}

std::string valueText(const json& v) {
    return v.is_string() ? v.get<std::string>() : v.dump();
}

// The main column of a recorded metric (what its plots show).
std::string mainColumn(const std::string& metric) {
    if (metric == "memory") return "device_bytes";
    return metric;
}

std::string unitOf(const std::string& column) {
    if (column == "gpu_ms") return "GPU ms (total)";
    if (column == "device_bytes") return "device memory (MiB)";
    if (column == "psnr") return "PSNR (dB)";
    if (column == "flip") return "FLIP mean (lower is better)";
    if (column == "ssim") return "SSIM";
    if (column == "flicker") return "flicker (mean |Δ| between frames)";
    return column;
}

std::optional<double> metricOf(const json& row, const std::string& column) {
    if (row.value("status", "") != "done" || !row.contains("metrics")) return std::nullopt;
    const json& m = row["metrics"];
    if (!m.contains(column) || !m[column].is_number()) return std::nullopt;
    double v = m[column].get<double>();
    if (column == "device_bytes") v /= 1024.0 * 1024.0;
    return v;
}

struct Range {
    double lo = 0, hi = 1;
    void fit(const std::vector<double>& v) {
        if (v.empty()) return;
        lo = *std::min_element(v.begin(), v.end());
        hi = *std::max_element(v.begin(), v.end());
        if (hi - lo < 1e-12 * std::max(1.0, std::fabs(hi))) {
            const double pad = std::max(std::fabs(hi) * 0.1, 1e-6);
            lo -= pad;
            hi += pad;
        } else {
            const double pad = (hi - lo) * 0.08;
            lo -= pad;
            hi += pad;
        }
    }
};

struct Frame {
    static constexpr double kW = 440, kH = 270, kLeft = 62, kRight = 14, kTop = 28, kBottom = 44;
    Range x, y;
    double px(double v) const { return kLeft + (v - x.lo) / (x.hi - x.lo) * (kW - kLeft - kRight); }
    double py(double v) const { return kH - kBottom - (v - y.lo) / (y.hi - y.lo) * (kH - kTop - kBottom); }
};

// Ticks at 1, 2 or 5 times a power of ten, about five across the range.
std::vector<double> niceTicks(const Range& r) {
    const double raw = (r.hi - r.lo) / 5.0;
    const double power = std::pow(10.0, std::floor(std::log10(raw)));
    const double step = raw / power < 1.5 ? power : raw / power < 3.5 ? 2 * power : raw / power < 7.5 ? 5 * power : 10 * power;
    std::vector<double> ticks;
    for (double v = std::ceil(r.lo / step) * step; v <= r.hi + step * 1e-9 && ticks.size() < 12; v += step)
        ticks.push_back(std::fabs(v) < step * 1e-9 ? 0.0 : v);
    return ticks;
}

void axesSvg(std::ostringstream& o, const Frame& f, const std::string& title, const std::string& xLabel,
             const std::string& yLabel, const std::vector<std::string>& categories) {
    o << "<text x='" << Frame::kW / 2 << "' y='16' class='t'>" << escapeHtml(title) << "</text>";
    o << "<rect x='" << Frame::kLeft << "' y='" << Frame::kTop << "' width='" << Frame::kW - Frame::kLeft - Frame::kRight
      << "' height='" << Frame::kH - Frame::kTop - Frame::kBottom << "' class='box'/>";
    for (double v : niceTicks(f.y)) {
        o << "<text x='" << Frame::kLeft - 4 << "' y='" << f.py(v) + 4 << "' class='yt'>" << fmt(v) << "</text>";
        o << "<line x1='" << Frame::kLeft << "' x2='" << Frame::kW - Frame::kRight << "' y1='" << f.py(v) << "' y2='"
          << f.py(v) << "' class='grid'/>";
    }
    if (categories.empty()) {
        for (double v : niceTicks(f.x)) {
            o << "<text x='" << f.px(v) << "' y='" << Frame::kH - Frame::kBottom + 16 << "' class='xt'>" << fmt(v)
              << "</text>";
        }
    } else {
        for (size_t i = 0; i < categories.size(); ++i)
            o << "<text x='" << f.px(static_cast<double>(i)) << "' y='" << Frame::kH - Frame::kBottom + 16
              << "' class='xt'>" << escapeHtml(categories[i]) << "</text>";
    }
    o << "<text x='" << (Frame::kLeft + Frame::kW - Frame::kRight) / 2 << "' y='" << Frame::kH - 6 << "' class='xl'>"
      << escapeHtml(xLabel) << "</text>";
    o << "<text transform='translate(14," << (Frame::kTop + Frame::kH - Frame::kBottom) / 2
      << ") rotate(-90)' class='xl'>" << escapeHtml(yLabel) << "</text>";
}

// One metric against one axis: a dot per point that has a value on the axis, points that differ only in this axis
// joined by a line (one colour per combination of the other axes).
std::string metricAxisPlot(const json& table, const std::string& metric, const std::string& axis) {
    const std::string column = mainColumn(metric);
    std::vector<std::string> categories;
    bool numeric = true;
    struct Dot {
        double x, y;
        std::string id, label, series;
    };
    std::vector<Dot> dots;
    std::vector<json> xs;
    for (const json& row : table["points"]) {
        if (!row["values"].contains(axis)) continue;
        const json& v = row["values"][axis];
        xs.push_back(v);
        if (!v.is_number()) numeric = false;
    }
    for (const json& v : xs)
        if (std::find(categories.begin(), categories.end(), valueText(v)) == categories.end())
            categories.push_back(valueText(v));
    size_t missing = 0;
    std::vector<Dot> levels; // points without a value on this axis (e.g. an extra variant): a dashed level line
    for (const json& row : table["points"]) {
        if (!row["values"].contains(axis)) {
            if (const auto y = metricOf(row, column)) levels.push_back({0, *y, row["id"], row["label"], ""});
            continue;
        }
        const auto y = metricOf(row, column);
        if (!y) {
            ++missing;
            continue;
        }
        const json& v = row["values"][axis];
        const double x = numeric ? v.get<double>()
                                 : static_cast<double>(std::find(categories.begin(), categories.end(), valueText(v)) -
                                                       categories.begin());
        json others = row["values"];
        others.erase(axis);
        dots.push_back({x, *y, row["id"], row["label"], others.dump()});
    }
    std::ostringstream o;
    o << "<figure><svg class='plot' data-metric='" << escapeHtml(metric) << "' data-axis='" << escapeHtml(axis)
      << "' xmlns='http://www.w3.org/2000/svg' width='" << Frame::kW << "' height='" << Frame::kH << "' viewBox='0 0 "
      << Frame::kW << " " << Frame::kH << "'>";
    Frame f;
    std::vector<double> xv, yv;
    for (const Dot& d : dots) {
        xv.push_back(d.x);
        yv.push_back(d.y);
    }
    if (numeric) f.x.fit(xv);
    else {
        f.x.lo = -0.5;
        f.x.hi = static_cast<double>(categories.size()) - 0.5;
    }
    for (const Dot& d : levels) yv.push_back(d.y);
    f.y.fit(yv);
    axesSvg(o, f, unitOf(column) + " vs " + axis, axis, unitOf(column), numeric ? std::vector<std::string>{} : categories);
    std::map<std::string, std::vector<const Dot*>> series;
    for (const Dot& d : dots) series[d.series].push_back(&d);
    size_t colour = 0;
    for (auto& [key, members] : series) {
        const char* c = kPalette[colour % 8];
        if (series.size() > 1) {
            // The legend: the other axes' values of this line.
            std::string text;
            const json others = json::parse(key);
            for (const auto& [name, value] : others.items())
                text += (text.empty() ? "" : ", ") + name + "=" + valueText(value);
            o << "<text x='" << Frame::kLeft + 6 << "' y='" << Frame::kTop + 13 + 12 * colour << "' fill='" << c
              << "' class='lg'>" << escapeHtml(text) << "</text>";
        }
        ++colour;
        std::sort(members.begin(), members.end(), [](const Dot* a, const Dot* b) { return a->x < b->x; });
        if (members.size() > 1) {
            o << "<polyline fill='none' stroke='" << c << "' stroke-width='1.5' points='";
            for (const Dot* d : members) o << f.px(d->x) << "," << f.py(d->y) << " ";
            o << "'/>";
        }
        for (const Dot* d : members)
            o << "<a href='#" << escapeHtml(d->id) << "'><circle cx='" << f.px(d->x) << "' cy='" << f.py(d->y)
              << "' r='4' fill='" << c << "'><title>" << escapeHtml(d->id + " " + d->label + ": " + fmt(d->y))
              << "</title></circle></a>";
    }
    for (const Dot& d : levels)
        o << "<a href='#" << escapeHtml(d.id) << "'><line x1='" << Frame::kLeft << "' x2='" << Frame::kW - Frame::kRight
          << "' y1='" << f.py(d.y) << "' y2='" << f.py(d.y) << "' class='level'><title>"
          << escapeHtml(d.id + " " + d.label + ": " + fmt(d.y)) << "</title></line></a><text x='"
          << Frame::kW - Frame::kRight - 3 << "' y='" << f.py(d.y) - 3 << "' class='ll'>" << escapeHtml(d.label)
          << "</text>";
    if (dots.empty())
        o << "<text x='" << Frame::kW / 2 << "' y='" << Frame::kH / 2 << "' class='t'>no finished point</text>";
    o << "</svg><figcaption>" << dots.size() << " point(s)";
    if (missing) o << "; " << missing << " without a value (failed or pending)";
    if (!levels.empty()) o << "; dashed: " << levels.size() << " point(s) outside this axis";
    if (series.size() > 1) o << "; a line joins points that differ only in " << escapeHtml(axis);
    o << "</figcaption></figure>\n";
    return o.str();
}

// Points no other point beats in both quality and cost (lower FLIP and lower GPU ms), by increasing cost.
std::vector<size_t> paretoFront(const std::vector<std::pair<double, double>>& costQuality) {
    std::vector<size_t> order(costQuality.size());
    for (size_t i = 0; i < order.size(); ++i) order[i] = i;
    std::sort(order.begin(), order.end(), [&](size_t a, size_t b) {
        return costQuality[a].first != costQuality[b].first ? costQuality[a].first < costQuality[b].first
                                                            : costQuality[a].second < costQuality[b].second;
    });
    std::vector<size_t> front;
    double best = INFINITY;
    for (size_t i : order)
        if (costQuality[i].second < best) {
            front.push_back(i);
            best = costQuality[i].second;
        }
    return front;
}

std::string paretoPlot(const json& table) {
    std::vector<std::pair<double, double>> cq;
    std::vector<const json*> rows;
    for (const json& row : table["points"]) {
        auto cost = metricOf(row, "gpu_ms"), quality = metricOf(row, "flip");
        if (!cost || !quality) continue;
        cq.push_back({*cost, *quality});
        rows.push_back(&row);
    }
    const std::vector<size_t> front = paretoFront(cq);
    std::ostringstream o;
    o << "<figure><svg class='plot pareto' data-metric='flip' data-axis='gpu_ms' xmlns='http://www.w3.org/2000/svg' "
         "width='"
      << Frame::kW << "' height='" << Frame::kH << "' viewBox='0 0 " << Frame::kW << " " << Frame::kH << "'>";
    Frame f;
    std::vector<double> xv, yv;
    for (auto [c, q] : cq) {
        xv.push_back(c);
        yv.push_back(q);
    }
    f.x.fit(xv);
    f.y.fit(yv);
    axesSvg(o, f, "quality vs cost (Pareto front in red)", "GPU ms (total)", "FLIP mean", {});
    if (front.size() > 1) {
        o << "<polyline fill='none' stroke='#d62728' stroke-width='1.5' points='";
        for (size_t i : front) o << f.px(cq[i].first) << "," << f.py(cq[i].second) << " ";
        o << "'/>";
    }
    for (size_t i = 0; i < cq.size(); ++i) {
        const bool onFront = std::find(front.begin(), front.end(), i) != front.end();
        const std::string id = (*rows[i])["id"], label = (*rows[i])["label"];
        o << "<a href='#" << escapeHtml(id) << "'><circle cx='" << f.px(cq[i].first) << "' cy='" << f.py(cq[i].second)
          << "' r='" << (onFront ? 6 : 4) << "' class='" << (onFront ? "front" : "dominated") << "'><title>"
          << escapeHtml(id + " " + label + ": " + fmt(cq[i].first) + " ms, FLIP " + fmt(cq[i].second)) << "</title></circle></a>";
        o << "<text x='" << f.px(cq[i].first) + 7 << "' y='" << f.py(cq[i].second) - 5 << "' class='pl'>"
          << escapeHtml(id) << "</text>";
    }
    o << "</svg><figcaption>" << cq.size() << " point(s); on the front: ";
    for (size_t k = 0; k < front.size(); ++k) o << (k ? ", " : "") << escapeHtml((*rows[front[k]])["id"].get<std::string>());
    o << "</figcaption></figure>\n";
    return o.str();
}

} // namespace

std::string renderSweepReport(const json& table) {
    std::ostringstream o;
    const std::string title = "vitrine sweep: " + table.value("sweep", std::string());
    o << "<!DOCTYPE html>\n<html lang='en'><head><meta charset='utf-8'><title>" << escapeHtml(title) << "</title>\n"
      << "<style>body{font:14px system-ui,sans-serif;margin:20px;color:#222}h1{font-size:20px}"
         "figure{display:inline-block;margin:6px;vertical-align:top}figcaption{font-size:12px;color:#555;max-width:440px}"
         "svg .box{fill:#fafafa;stroke:#999}svg .grid{stroke:#e4e4e4}svg text{font:11px sans-serif}"
         "svg .t{text-anchor:middle;font-weight:bold}svg .yt{text-anchor:end}svg .xt{text-anchor:middle}"
         "svg .xl{text-anchor:middle}svg .pl{font-size:10px;fill:#444}svg .front{fill:#d62728}"
         "svg .dominated{fill:#888}svg .level{stroke:#555;stroke-dasharray:5 3;stroke-width:1.5}"
         "svg .ll{text-anchor:end;font-size:10px;fill:#333}svg .lg{font-size:10px}table{border-collapse:collapse;font-size:13px}"
         "td,th{border:1px solid #ccc;padding:3px 6px;text-align:right}td.l,th.l{text-align:left}"
         "tr.failed{background:#fde2e2}tr.pending{background:#f3f3f3}img{image-rendering:pixelated;display:block}"
         "</style></head><body>\n";
    o << "<h1>" << escapeHtml(title) << "</h1>\n";
    if (table.contains("description") && table["description"].is_string())
        o << "<p>" << escapeHtml(table["description"].get<std::string>()) << "</p>\n";
    const json& s = table["summary"];
    o << "<p>graph " << escapeHtml(table.value("graph", std::string())) << "; reference "
      << escapeHtml(table.value("reference", std::string("none"))) << "; " << table["points"].size() << " points: "
      << s["done"] << " done, " << s["failed"] << " failed, " << s["pending"] << " pending.</p>\n";

    std::vector<std::string> axes;
    for (const json& a : table["axes"]) axes.push_back(a["name"]);
    o << "<h2>Metrics against each axis</h2>\n";
    for (const json& m : table["metrics"])
        for (const std::string& a : axes) o << metricAxisPlot(table, m, a);
    bool hasPareto = false;
    for (const json& m : table["metrics"]) hasPareto = hasPareto || m == "gpu_ms";
    bool hasFlip = false;
    for (const json& m : table["metrics"]) hasFlip = hasFlip || m == "flip";
    if (hasPareto && hasFlip) o << "<h2>Quality against cost</h2>\n" << paretoPlot(table);

    o << "<h2>Points</h2>\n<table><tr><th class='l'>id</th><th class='l'>label</th><th class='l'>status</th>";
    for (const json& c : table["columns"]) o << "<th>" << escapeHtml(c.get<std::string>()) << "</th>";
    o << "<th>point s</th><th class='l'>image</th><th class='l'>FLIP map</th></tr>\n";
    for (const json& row : table["points"]) {
        const std::string id = row["id"], status = row["status"];
        const std::string base = "points/" + id + "/";
        const json images = row.value("images", json::object());
        o << "<tr id='" << escapeHtml(id) << "' class='" << escapeHtml(status) << "'><td class='l'>";
        if (images.contains("report"))
            o << "<a href='" << escapeHtml(base + images["report"].get<std::string>()) << "'>" << escapeHtml(id) << "</a>";
        else o << "<a href='" << escapeHtml(base) << "'>" << escapeHtml(id) << "</a>";
        o << "</td><td class='l'>" << escapeHtml(row["label"].get<std::string>()) << "</td><td class='l'>"
          << escapeHtml(status);
        if (status == "failed")
            o << " (exit " << row.value("exit_code", -1) << "): " << escapeHtml(row.value("error", std::string()));
        o << "</td>";
        const json m = row.value("metrics", json::object());
        for (const json& c : table["columns"]) {
            const std::string name = c;
            o << "<td>";
            if (m.contains(name) && m[name].is_number())
                o << fmt(name.find("bytes") != std::string::npos ? m[name].get<double>() / (1024.0 * 1024.0)
                                                                  : m[name].get<double>())
                  << (name.find("bytes") != std::string::npos ? " MiB" : "");
            else if (m.contains(name) && m[name].is_null() && name == "psnr") o << "identical";
            o << "</td>";
        }
        const json phases = row.value("phases_ms", json::object());
        o << "<td>" << (phases.contains("total_ms") ? fmt(phases["total_ms"].get<double>() / 1000.0) : "") << "</td>";
        for (const char* key : {"image", "flip"}) {
            o << "<td class='l'>";
            if (images.contains(key)) {
                const std::string src = base + images[key].get<std::string>();
                o << "<a href='" << escapeHtml(src) << "'><img src='" << escapeHtml(src) << "' width='160' alt='"
                  << escapeHtml(id + " " + key) << "'></a>";
            }
            o << "</td>";
        }
        o << "</tr>\n";
    }
    o << "</table>\n<p>Each id links to the point's compare report (its image, the reference, |difference| and the "
         "FLIP map); sweep.json and sweep.csv hold the same table.</p>\n</body></html>\n";
    return o.str();
}

} // namespace vitrine::sweep
