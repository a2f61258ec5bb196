#pragma once

#include "tools/vitrine/cli.hpp"
#include "tools/vitrine/sweep/sweep_file.hpp"

#include <filesystem>
#include <vector>

// One point of a sweep, in this process: what `vitrine sweep FILE --out DIR --point ID` runs (the local driver starts
// one such process per point; Slurm array tasks run the same command). Writes DIR/points/ID/metrics.json (and the
// kept images) or, when the point fails, DIR/points/ID/error.json; never both.
namespace vitrine::sweep {

// Renders the point, compares it with the reference and writes its folder. Returns the exit status: 0 done, 1 the
// point's input is wrong (bad --set value, ...), 2 internal failure or Vulkan validation messages; error.json
// records the message and status.
int runPoint(const SweepFile& sweep, const Point& point, const std::filesystem::path& outDir, const cli::Args& args);

// Renders the reference frames every point in `points` needs (one render per distinct frame range) into
// DIR/reference/, unless already there; points whose graph does not load are left to fail in their own process.
// What the local driver runs once before the points (`--reference-only`), so that N processes do not render it N
// times.
void renderReferences(const SweepFile& sweep, const std::vector<Point>& points, const std::filesystem::path& outDir,
                      const cli::Args& args);

// Exit status of a point process: the folder's error.json is written by the point itself (runPoint) or, when the
// process died without writing it, by the driver.
void writePointError(const std::filesystem::path& pointDir, const Point& point, const std::string& message,
                     int exitCode);

} // namespace vitrine::sweep
