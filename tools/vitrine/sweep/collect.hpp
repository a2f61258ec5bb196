#pragma once

#include <nlohmann/json.hpp>

#include <filesystem>
#include <string>

// `vitrine sweep --collect DIR`: gathers DIR/points/*/metrics.json (done) and error.json (failed) into one table,
// following the plan the driver wrote (DIR/sweep-plan.json, so that points never run show as "pending"), and writes
// DIR/sweep.json, DIR/sweep.csv and DIR/report.html. CPU only: runs where the points' files are (a login node).
namespace vitrine::sweep {

struct CollectSummary {
    size_t done = 0;
    size_t failed = 0;
    size_t pending = 0;
};

// Resuming (locally or on Slurm) trusts the files in DIR/points/: throws UserError when DIR's plan gave one of
// `plan`'s ids to another point (another sweep's results).
void checkSamePlan(const std::filesystem::path& outDir, const nlohmann::json& plan);

// Writes the plan: the sweep file, its axes and metrics, and every point's id, label and values.
void writePlan(const std::filesystem::path& outDir, const nlohmann::json& plan);

// Reads DIR/sweep-plan.json and the points' files; writes the three outputs. UserError when DIR has no plan.
CollectSummary collect(const std::filesystem::path& outDir);

// The report page for a sweep.json document (`table`), with image links relative to DIR.
std::string renderSweepReport(const nlohmann::json& table);

} // namespace vitrine::sweep
