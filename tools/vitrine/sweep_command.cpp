// `vitrine sweep FILE`: quality-versus-cost studies over --set values, variant files and frame ranges (README
// "Sweeps"). The sweep file and its expansion: sweep/sweep_file; one point in this process: sweep/point; the local
// driver (a process per point): sweep/driver; the table and report: sweep/collect and sweep/report.
#include "core/base/error.hpp"
#include "tools/vitrine/cli.hpp"
#include "tools/vitrine/sweep/collect.hpp"
#include "tools/vitrine/sweep/driver.hpp"
#include "tools/vitrine/sweep/point.hpp"
#include "tools/vitrine/sweep/slurm.hpp"
#include "tools/vitrine/sweep/sweep_file.hpp"

#include <cstdio>
#include <sstream>

namespace vitrine::cli {

namespace fs = std::filesystem;

int sweepCommand(const Args& args) {
    if (args.has("collect")) {
        if (!args.positional.empty()) throw UserError("sweep --collect DIR: expected no sweep file");
        const sweep::CollectSummary s = sweep::collect(args.get("collect"));
        std::printf("%zu done, %zu failed, %zu pending\nwrote %s\n", s.done, s.failed, s.pending,
                    (fs::path(args.get("collect")) / "report.html").string().c_str());
        return 0;
    }
    if (args.positional.size() != 1) throw UserError("sweep: expected one sweep FILE (vitrine-sweep/1 JSON)");
    const fs::path file = args.positional[0];
    const sweep::SweepFile sweep = sweep::parseSweepFile(file);
    sweep::parseSlurmBlock(sweep.file, sweep.document); // its errors whether or not this run uses --slurm
    const std::vector<sweep::Point> points = sweep::expandPoints(sweep);
    const fs::path outDir = args.get("out", (fs::path("out") / "sweep" / file.stem()).string());
    if (args.has("list")) {
        for (const sweep::Point& p : points) std::printf("%s  %s\n", p.id.c_str(), p.label.c_str());
        return 0;
    }
    if (args.has("point")) return sweep::runPoint(sweep, sweep::findPoint(points, args.get("point")), outDir, args);
    if (args.has("reference-only")) {
        sweep::renderReferences(sweep, points, outDir, args);
        return 0;
    }
    if (args.has("slurm")) return sweep::runOnSlurm(args, sweep, points, outDir);
    sweep::DriverOptions options;
    options.sweepFile = file;
    options.outDir = outDir;
    options.jobs = args.getUint("jobs", 1);
    if (options.jobs == 0) throw UserError("--jobs: expected at least 1");
    options.retryFailed = args.has("retry-failed");
    if (args.has("devices")) {
        std::stringstream list(args.get("devices"));
        for (std::string d; std::getline(list, d, ',');)
            if (!d.empty()) options.devices.push_back(d);
        if (options.devices.empty()) throw UserError("--devices: expected a comma-separated list, e.g. 0,1");
    } else if (args.has("device")) {
        options.devices.push_back(args.get("device"));
    }
    if (args.has("validate")) options.passThrough.push_back("--validate");
    return sweep::runSweep(sweep, points, options);
}

} // namespace vitrine::cli
