#pragma once

#include "tools/vitrine/cli.hpp"
#include "tools/vitrine/sweep/sweep_file.hpp"

#include <filesystem>
#include <vector>

// The local driver of `vitrine sweep FILE`: runs each pending point as its own process (this same binary with
// `--point ID`), --jobs at once, with a progress bar and an ETA, then collects the table and the report.
namespace vitrine::sweep {

struct DriverOptions {
    std::filesystem::path sweepFile;
    std::filesystem::path outDir;
    unsigned jobs = 1;
    bool retryFailed = false;
    std::vector<std::string> devices; // --devices 0,1: point processes take them in turn; empty: --device or none
    std::vector<std::string> passThrough; // --validate, --verbose … for every point process
};

// Exit status: 0 every point done, 3 some failed (recorded in their folders and the table), 130 stopped by Ctrl-C.
int runSweep(const SweepFile& sweep, const std::vector<Point>& points, const DriverOptions& options);

// The plan document (sweep-plan.json) for these points.
nlohmann::json planOf(const SweepFile& sweep, const std::vector<Point>& points);

} // namespace vitrine::sweep
