#pragma once

#include <string>
#include <vector>

// Runs Slurm's client commands (sbatch, squeue, sacct) for `vitrine sweep --slurm` and captures what they print.
namespace vitrine::sweep {

struct Captured {
    int status = -1;       // exit status (128 + signal when killed)
    bool notFound = false; // argv[0] is not on PATH (or not executable)
    std::string out, err;
};

// Runs argv (argv[0] looked up on PATH) with stdin from /dev/null and waits for it; stdout and stderr separately.
Captured capture(const std::vector<std::string>& argv);

// argv as one line for messages, arguments with blanks quoted.
std::string joinArgv(const std::vector<std::string>& argv);

} // namespace vitrine::sweep
