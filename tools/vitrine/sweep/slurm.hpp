#pragma once

#include "tools/vitrine/cli.hpp"
#include "tools/vitrine/sweep/sweep_file.hpp"

#include <nlohmann/json.hpp>

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

// `vitrine sweep FILE --slurm` (README "Sweeps on a Slurm cluster"): the points still to do become one Slurm job
// array (`sbatch --array`), each array task running `vitrine sweep FILE --out DIR --point ID` with this same binary;
// a second job that depends on the array (`--dependency=afterany:`) runs `vitrine sweep --collect DIR`. While they
// run, squeue (and sacct where the cluster keeps accounting) and the points' folders give a progress line. No daemon
// of our own: Slurm's client commands (sbatch, squeue, sacct) are all it calls.
namespace vitrine::sweep {

// Where the array goes and what each task asks for. From the sweep file's "slurm" block, then the command line.
struct SlurmOptions {
    std::string partition;               // --partition / "partition" ("" = the cluster's default)
    std::string time;                    // --time / "time": Slurm's time format, per task ("" = partition default)
    uint32_t gpusPerTask = 0;            // --gpus-per-task / "gpus_per_task" (0 = none asked)
    std::vector<std::string> sbatchArgs; // --sbatch-arg (repeatable) / "sbatch_args": passed to both sbatch calls
    bool wait = true;                    // --no-wait: submit, print the job ids and return
};

// The "slurm" block of a sweep file (`document` is the whole file; no block gives the defaults). UserError naming
// the file, the JSON pointer (/slurm/...) and what was expected.
SlurmOptions parseSlurmBlock(const std::filesystem::path& file, const nlohmann::json& document);

// The block's options overridden by the command line (--partition, --time, --gpus-per-task, --sbatch-arg,
// --no-wait). UserError for a malformed value.
SlurmOptions slurmOptions(const cli::Args& args, const SweepFile& sweep);

// The body of the array's batch script: `#SBATCH` lines, then the task -> point id lookup in `taskFile` (line
// SLURM_ARRAY_TASK_ID + 1) and the exec of `vitrine sweep FILE --out DIR --point ID`. Paths must be absolute.
// Exposed for the CPU test.
std::string arrayScript(const SlurmOptions& options, const std::string& jobName, size_t tasks,
                        const std::filesystem::path& vitrine, const std::filesystem::path& sweepFile,
                        const std::filesystem::path& outDir, const std::filesystem::path& taskFile,
                        const std::filesystem::path& logDir, const std::vector<std::string>& passThrough);

// The reference job's script: `vitrine sweep FILE --out DIR --reference-only`, once before the array (which depends
// on it with afterok, so a failed reference cancels the array).
std::string referenceScript(const SlurmOptions& options, const std::string& jobName,
                            const std::filesystem::path& vitrine, const std::filesystem::path& sweepFile,
                            const std::filesystem::path& outDir, const std::filesystem::path& logDir,
                            const std::vector<std::string>& passThrough);

// The collect job's script: `vitrine sweep --collect DIR` (dependency given on sbatch's command line).
std::string collectScript(const SlurmOptions& options, const std::string& jobName, const std::filesystem::path& vitrine,
                          const std::filesystem::path& outDir, const std::filesystem::path& logDir);

// Entry from `vitrine sweep FILE --slurm`: submits the points of `points` that are still to do (failed ones too with
// --retry-failed) and the collect job, then waits unless --no-wait. Returns the exit status: 0 when the collected
// table exists and every point succeeded, 3 when some point failed or has no result, 1 for bad input (sbatch missing
// or refusing the job: its stderr is in the message).
int runOnSlurm(const cli::Args& args, const SweepFile& sweep, const std::vector<Point>& points,
               const std::filesystem::path& outDir);

} // namespace vitrine::sweep
