#include "tools/vitrine/sweep/collect.hpp"

#include "core/base/atomic_file.hpp"
#include "core/base/error.hpp"

#include <cmath>
#include <fstream>
#include <sstream>

namespace vitrine::sweep {

namespace fs = std::filesystem;

namespace {

nlohmann::json readJson(const fs::path& path) {
    std::ifstream in(path);
    if (!in) throw UserError(path.string() + ": cannot read");
    try {
        return nlohmann::json::parse(in);
    } catch (const nlohmann::json::parse_error& e) {
        throw UserError(path.string() + ": not valid JSON: " + e.what());
    }
}

std::string csvField(const nlohmann::json& v) {
    std::string s;
    if (v.is_null()) return "";
    if (v.is_string()) s = v.get<std::string>();
    else if (v.is_number_float()) {
        char buf[40];
        std::snprintf(buf, sizeof buf, "%.9g", v.get<double>());
        s = buf;
    } else s = v.dump();
    if (s.find_first_of(",\"\n") == std::string::npos) return s;
    std::string quoted = "\"";
    for (char c : s) quoted += c == '"' ? std::string("\"\"") : std::string(1, c);
    return quoted + "\"";
}

// The columns of sweep.csv and the report for one recorded metric name of the sweep file.
std::vector<std::string> columnsOf(const std::string& metric) {
    if (metric == "flip") return {"flip", "flip_weighted_median"};
    if (metric == "memory") return {"device_bytes", "max_rss_bytes"};
    return {metric};
}

} // namespace

void checkSamePlan(const fs::path& outDir, const nlohmann::json& plan) {
    std::ifstream in(outDir / "sweep-plan.json");
    if (!in) return;
    const nlohmann::json old = nlohmann::json::parse(in, nullptr, false);
    if (!old.is_object() || !old.contains("points") || !old["points"].is_array()) return;
    for (const auto& o : old["points"])
        for (const auto& n : plan["points"])
            if (o.value("id", "") == n["id"] &&
                (o.value("graph", "") != n["graph"] || o.value("sets", nlohmann::json()) != n["sets"] ||
                 o.value("frames", "") != n["frames"]))
                throw UserError(outDir.string() + " holds the results of another sweep: point " +
                                n["id"].get<std::string>() + " was '" + o.value("label", "") + "' there, is '" +
                                n["label"].get<std::string>() + "' here; choose another --out or delete it");
}

void writePlan(const fs::path& outDir, const nlohmann::json& plan) {
    std::error_code ec;
    fs::create_directories(outDir / "points", ec);
    writeFileAtomically(outDir / "sweep-plan.json", plan.dump(2) + "\n");
}

CollectSummary collect(const fs::path& outDir) {
    const fs::path planPath = outDir / "sweep-plan.json";
    std::error_code ec;
    if (!fs::is_regular_file(planPath, ec))
        throw UserError(outDir.string() + ": no sweep-plan.json; expected the --out folder of `vitrine sweep FILE`");
    const nlohmann::json plan = readJson(planPath);
    CollectSummary summary;
    nlohmann::json table = plan;
    table["format"] = "vitrine-sweep-result/1";
    nlohmann::json columns = nlohmann::json::array();
    for (const auto& m : plan["metrics"])
        for (const std::string& c : columnsOf(m)) columns.push_back(c);
    table["columns"] = columns;
    table["points"] = nlohmann::json::array();
    for (const auto& p : plan["points"]) {
        nlohmann::json row = p;
        const fs::path dir = outDir / "points" / p["id"].get<std::string>();
        if (fs::is_regular_file(dir / "metrics.json", ec)) {
            const nlohmann::json m = readJson(dir / "metrics.json");
            row["status"] = "done";
            row["metrics"] = m.value("metrics", nlohmann::json::object());
            row["phases_ms"] = m.value("phases_ms", nlohmann::json::object());
            row["images"] = m.value("images", nlohmann::json::object());
            if (m.contains("gpu_ms_per_node")) row["gpu_ms_per_node"] = m["gpu_ms_per_node"];
            ++summary.done;
        } else if (fs::is_regular_file(dir / "error.json", ec)) {
            const nlohmann::json e = readJson(dir / "error.json");
            row["status"] = "failed";
            row["error"] = e.value("error", std::string());
            row["exit_code"] = e.value("exit_code", -1);
            ++summary.failed;
        } else {
            row["status"] = "pending";
            ++summary.pending;
        }
        if (fs::is_regular_file(dir / "driver.json", ec)) row["wall_ms"] = readJson(dir / "driver.json").value("wall_ms", 0.0);
        table["points"].push_back(row);
    }
    table["summary"] = {{"done", summary.done}, {"failed", summary.failed}, {"pending", summary.pending}};
    writeFileAtomically(outDir / "sweep.json", table.dump(2) + "\n");

    std::ostringstream csv;
    csv << "id,label,status";
    for (const auto& a : plan["axes"]) csv << "," << csvField(a["name"]);
    for (const auto& c : columns) csv << "," << csvField(c);
    csv << ",total_ms,exit_code,error\n";
    for (const auto& row : table["points"]) {
        csv << csvField(row["id"]) << "," << csvField(row["label"]) << "," << csvField(row["status"]);
        for (const auto& a : plan["axes"]) csv << "," << csvField(row["values"].value(a["name"].get<std::string>(), nlohmann::json()));
        const nlohmann::json metrics = row.value("metrics", nlohmann::json::object());
        for (const auto& c : columns) csv << "," << csvField(metrics.value(c.get<std::string>(), nlohmann::json()));
        const nlohmann::json phases = row.value("phases_ms", nlohmann::json::object());
        csv << "," << csvField(phases.value("total_ms", nlohmann::json())) << ","
            << csvField(row.value("exit_code", nlohmann::json())) << "," << csvField(row.value("error", nlohmann::json()))
            << "\n";
    }
    writeFileAtomically(outDir / "sweep.csv", csv.str());
    writeFileAtomically(outDir / "report.html", renderSweepReport(table));
    return summary;
}

} // namespace vitrine::sweep
