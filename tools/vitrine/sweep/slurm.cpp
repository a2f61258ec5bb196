#include "tools/vitrine/sweep/slurm.hpp"

#include "core/base/atomic_file.hpp"
#include "core/base/error.hpp"
#include "tools/vitrine/interrupt.hpp"
#include "tools/vitrine/sweep/collect.hpp"
#include "tools/vitrine/sweep/driver.hpp"
#include "tools/vitrine/sweep/point.hpp"
#include "tools/vitrine/sweep/slurm_process.hpp"

#include <unistd.h>

#include <cctype>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <thread>

namespace vitrine::sweep {

namespace fs = std::filesystem;

namespace {

using Clock = std::chrono::steady_clock;

// Single-quoted for sh: safe for any path (a ' becomes '\'').
std::string shellQuote(const std::string& s) {
    std::string q = "'";
    for (char c : s)
        q += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return q + "'";
}

// One `#SBATCH` line per option; sbatch splits these lines on blanks, so an option with a blank, a quote or a
// newline in it would not arrive as written: refused here rather than mangled.
std::string sbatchLine(const std::string& option) {
    if (option.find_first_of(" \t\n\r'\"\\") != std::string::npos)
        throw UserError("sbatch option '" + option +
                        "': blanks, quotes and backslashes are not supported in sbatch "
                        "options written into the batch script");
    return "#SBATCH " + option + "\n";
}

std::string commonLines(const SlurmOptions& o, const std::string& jobName, bool gpus) {
    std::string s = sbatchLine("--job-name=" + jobName) + sbatchLine("--ntasks=1");
    if (!o.partition.empty()) s += sbatchLine("--partition=" + o.partition);
    if (!o.time.empty()) s += sbatchLine("--time=" + o.time);
    if (gpus && o.gpusPerTask > 0) s += sbatchLine("--gpus-per-task=" + std::to_string(o.gpusPerTask));
    for (const std::string& a : o.sbatchArgs)
        s += sbatchLine(a);
    return s;
}

std::string jobNameOf(const SweepFile& sweep) {
    std::string name = "vitrine-sweep-" + sweep.file.stem().string();
    for (char& c : name)
        if (!std::isalnum(static_cast<unsigned char>(c)) && c != '-' && c != '_' && c != '.') c = '_';
    return name;
}

std::string clockText(double seconds) {
    const long s = static_cast<long>(seconds + 0.5);
    char buf[32];
    if (s >= 3600)
        std::snprintf(buf, sizeof buf, "%ld:%02ld:%02ld", s / 3600, s / 60 % 60, s % 60);
    else
        std::snprintf(buf, sizeof buf, "%ld:%02ld", s / 60, s % 60);
    return buf;
}

// What the local driver reads from a point's folder (driver.cpp): metrics.json = done, error.json = failed.
enum class PointState { Todo, Done, Failed };
PointState pointState(const fs::path& outDir, const Point& p) {
    std::error_code ec;
    const fs::path dir = outDir / "points" / p.id;
    if (fs::exists(dir / "metrics.json", ec)) return PointState::Done;
    if (fs::exists(dir / "error.json", ec)) return PointState::Failed;
    return PointState::Todo;
}

// "1234" or "1234;cluster" from `sbatch --parsable`.
std::string submit(const std::vector<std::string>& argv, const fs::path& script) {
    std::vector<std::string> cmd = argv;
    cmd.push_back(script.string());
    const Captured r = capture(cmd);
    if (r.notFound)
        throw UserError("--slurm: '" + cmd[0] +
                        "' not found on PATH: submitting needs Slurm's client commands "
                        "(Debian: slurm-client) on this machine, configured for the cluster");
    std::string id = r.out.substr(0, r.out.find_first_of(";\n"));
    if (r.status != 0 || id.empty() || id.find_first_not_of("0123456789") != std::string::npos)
        throw UserError("--slurm: `" + joinArgv(cmd) + "` failed (exit status " + std::to_string(r.status) + "):\n" +
                        r.err + r.out);
    return id;
}

struct QueueState {
    bool ok = false;                     // squeue answered
    std::map<std::string, size_t> array; // state (PENDING, RUNNING, ...) -> tasks of the array still queued
    std::string reference, collect;      // those jobs' states, "" once they left the queue
    std::string reason;                  // the array's pending reason when it is not Resources/Priority
    std::string error;                   // squeue's stderr when it failed
};

QueueState queryQueue(const std::string& ref, const std::string& array, const std::string& collectJob) {
    QueueState q;
    // All of this user's jobs, filtered here: `squeue -j` fails once every listed job has left the queue.
    const Captured r = capture({"squeue", "--me", "-h", "-r", "-o", "%F|%i|%T|%r"});
    if (r.status != 0) {
        q.error = r.err.empty() ? "exit status " + std::to_string(r.status) : r.err;
        return q;
    }
    q.ok = true;
    std::istringstream lines(r.out);
    for (std::string line; std::getline(lines, line);) {
        std::vector<std::string> f;
        std::stringstream ls(line);
        for (std::string x; std::getline(ls, x, '|');)
            f.push_back(x);
        if (f.size() < 4) continue;
        if (!array.empty() && f[0] == array) {
            ++q.array[f[2]];
            if (f[2] == "PENDING" && f[3] != "Resources" && f[3] != "Priority" && f[3] != "None" &&
                f[3] != "Dependency" && f[3] != "JobArrayTaskLimit")
                q.reason = f[3];
        } else if (f[1] == collectJob) {
            q.collect = f[2];
        } else if (!ref.empty() && f[1] == ref) {
            q.reference = f[2];
        }
    }
    return q;
}

// Final states of the array's tasks from sacct, when the cluster keeps accounting ("" otherwise): task -> state.
std::map<std::string, std::string> accountedStates(const std::string& array) {
    std::map<std::string, std::string> states;
    const Captured r = capture({"sacct", "-n", "-P", "-X", "-j", array, "-o", "JobID,State"});
    if (r.status != 0) return states;
    std::istringstream lines(r.out);
    for (std::string line; std::getline(lines, line);) {
        const size_t bar = line.find('|'), under = line.find('_');
        if (bar == std::string::npos || under == std::string::npos || under > bar) continue;
        states[line.substr(under + 1, bar - under - 1)] = line.substr(bar + 1);
    }
    return states;
}

std::string tailOf(const fs::path& file, size_t bytes) {
    std::ifstream in(file, std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    std::string s = ss.str();
    if (s.size() > bytes) s = "…" + s.substr(s.size() - bytes);
    while (!s.empty() && (s.back() == '\n' || s.back() == ' '))
        s.pop_back();
    return s;
}

} // namespace

SlurmOptions parseSlurmBlock(const fs::path& file, const nlohmann::json& document) {
    SlurmOptions o;
    if (!document.is_object() || !document.contains("slurm")) return o;
    const nlohmann::json& b = document["slurm"];
    const std::string at = file.string() + ": /slurm";
    if (!b.is_object()) throw UserError(at + ": expected an object with partition, time, gpus_per_task, sbatch_args");
    for (const auto& [key, value] : b.items()) {
        const std::string where = at + "/" + key;
        if (key == "partition" || key == "time") {
            if (!value.is_string() || value.get<std::string>().empty())
                throw UserError(where + ": expected a non-empty string" +
                                (key == "time" ? std::string(" (Slurm's time format, e.g. \"00:30:00\")") : ""));
            (key == "partition" ? o.partition : o.time) = value.get<std::string>();
        } else if (key == "gpus_per_task") {
            if (!value.is_number_unsigned()) throw UserError(where + ": expected a whole number >= 0");
            o.gpusPerTask = value.get<uint32_t>();
        } else if (key == "sbatch_args") {
            if (!value.is_array()) throw UserError(where + ": expected an array of strings, e.g. [\"--account=x\"]");
            for (size_t i = 0; i < value.size(); ++i) {
                if (!value[i].is_string() || value[i].get<std::string>().rfind("--", 0) != 0)
                    throw UserError(where + "/" + std::to_string(i) + ": expected an sbatch option \"--name=value\"");
                o.sbatchArgs.push_back(value[i].get<std::string>());
            }
        } else {
            throw UserError(where + ": unknown key (expected partition, time, gpus_per_task, sbatch_args)");
        }
    }
    return o;
}

SlurmOptions slurmOptions(const cli::Args& args, const SweepFile& sweep) {
    SlurmOptions o = parseSlurmBlock(sweep.file, sweep.document);
    if (args.has("partition")) o.partition = args.get("partition");
    if (args.has("time")) o.time = args.get("time");
    if (args.has("gpus-per-task")) {
        const std::string v = args.get("gpus-per-task");
        if (v.empty() || v.find_first_not_of("0123456789") != std::string::npos || v.size() > 6)
            throw UserError("--gpus-per-task: expected a whole number, got '" + v + "'");
        o.gpusPerTask = static_cast<uint32_t>(std::stoul(v));
    }
    for (const std::string& a : args.all("sbatch-arg")) {
        if (a.rfind("--", 0) != 0) throw UserError("--sbatch-arg '" + a + "': expected an sbatch option --name=value");
        o.sbatchArgs.push_back(a);
    }
    for (const std::string& a : o.sbatchArgs)
        sbatchLine(a); // refuse what the script could not carry, before submitting
    o.wait = !args.has("no-wait");
    return o;
}

std::string arrayScript(const SlurmOptions& options, const std::string& jobName, size_t tasks, const fs::path& vitrine,
                        const fs::path& sweepFile, const fs::path& outDir, const fs::path& taskFile,
                        const fs::path& logDir, const std::vector<std::string>& passThrough) {
    std::string s = "#!/bin/sh\n# vitrine sweep --slurm: array task i runs the point on line i+1 of the task file.\n";
    s += sbatchLine("--array=0-" + std::to_string(tasks - 1));
    s += sbatchLine("--output=" + (logDir / "%A_%a.out").string());
    s += commonLines(options, jobName, true);
    s += "id=$(sed -n \"$((SLURM_ARRAY_TASK_ID + 1))p\" " + shellQuote(taskFile.string()) + ")\n";
    s += "if [ -z \"$id\" ]; then echo \"no point for array task $SLURM_ARRAY_TASK_ID in " + taskFile.string() +
         "\" >&2; exit 2; fi\n";
    s += "echo \"array task $SLURM_ARRAY_TASK_ID: point $id on $(hostname)\"\n";
    s += "exec " + shellQuote(vitrine.string()) + " sweep " + shellQuote(sweepFile.string()) + " --out " +
         shellQuote(outDir.string()) + " --point \"$id\"";
    for (const std::string& a : passThrough)
        s += " " + shellQuote(a);
    return s + "\n";
}

std::string referenceScript(const SlurmOptions& options, const std::string& jobName, const fs::path& vitrine,
                            const fs::path& sweepFile, const fs::path& outDir, const fs::path& logDir,
                            const std::vector<std::string>& passThrough) {
    std::string s = "#!/bin/sh\n# vitrine sweep --slurm: the reference, once, before the array.\n";
    s += sbatchLine("--output=" + (logDir / "reference-%j.out").string());
    s += commonLines(options, jobName + "-reference", true);
    s += "exec " + shellQuote(vitrine.string()) + " sweep " + shellQuote(sweepFile.string()) + " --out " +
         shellQuote(outDir.string()) + " --reference-only";
    for (const std::string& a : passThrough)
        s += " " + shellQuote(a);
    return s + "\n";
}

std::string collectScript(const SlurmOptions& options, const std::string& jobName, const fs::path& vitrine,
                          const fs::path& outDir, const fs::path& logDir) {
    std::string s = "#!/bin/sh\n# vitrine sweep --slurm: the table and report once the array has ended.\n";
    s += sbatchLine("--output=" + (logDir / "collect-%j.out").string());
    s += commonLines(options, jobName + "-collect", false);
    s += "exec " + shellQuote(vitrine.string()) + " sweep --collect " + shellQuote(outDir.string()) + "\n";
    return s;
}

int runOnSlurm(const cli::Args& args, const SweepFile& sweep, const std::vector<Point>& points,
               const fs::path& outDirArg) {
    const SlurmOptions options = slurmOptions(args, sweep);
    std::error_code ec;
    fs::create_directories(outDirArg, ec);
    const fs::path outDir = fs::absolute(outDirArg).lexically_normal();
    const fs::path sweepFile = fs::absolute(sweep.file).lexically_normal();
    const fs::path vitrine = fs::read_symlink("/proc/self/exe", ec);
    if (ec) throw InternalError("cannot find the vitrine executable (/proc/self/exe): " + ec.message());
    const bool retryFailed = args.has("retry-failed");
    std::vector<std::string> passThrough = {"--quiet"};
    if (args.has("validate")) passThrough.push_back("--validate");
    if (args.has("device")) passThrough.insert(passThrough.end(), {"--device", args.get("device")});

    const nlohmann::json plan = planOf(sweep, points);
    checkSamePlan(outDir, plan); // before trusting any point's files
    std::vector<const Point*> todo;
    size_t done = 0, failedBefore = 0;
    for (const Point& p : points) {
        const PointState s = pointState(outDir, p);
        if (s == PointState::Done)
            ++done;
        else if (s == PointState::Failed && !retryFailed)
            ++failedBefore;
        else
            todo.push_back(&p);
    }
    writePlan(outDir, plan);
    for (const Point* p : todo)
        fs::remove(outDir / "points" / p->id / "error.json", ec);

    // Each submission gets its own numbered folder: a second `--slurm` while the first array runs must not change
    // the task -> point file the first one reads.
    const fs::path slurmDir = outDir / "slurm";
    fs::create_directories(slurmDir, ec);
    unsigned n = 1;
    while (fs::exists(slurmDir / std::to_string(n), ec))
        ++n;
    const fs::path subDir = slurmDir / std::to_string(n);
    const fs::path logDir = subDir / "logs";
    fs::create_directories(logDir, ec);
    if (!fs::is_directory(logDir)) throw UserError(logDir.string() + ": cannot create the folder");
    const std::string jobName = jobNameOf(sweep);

    std::printf("%zu points: %zu done earlier (skipped), %zu failed earlier (%s), %zu to submit as a Slurm job array\n",
                points.size(), done, failedBefore, failedBefore ? "skipped; --retry-failed reruns them" : "none",
                todo.size());
    std::fflush(stdout);

    std::string refJob, arrayJob;
    if (!todo.empty()) {
        std::string tasks;
        for (const Point* p : todo)
            tasks += p->id + "\n";
        writeFileAtomically(subDir / "tasks.txt", tasks);
        std::vector<std::string> sbatch = {"sbatch", "--parsable"};
        if (sweep.reference) {
            const fs::path script = subDir / "reference.sh";
            writeFileAtomically(script,
                                referenceScript(options, jobName, vitrine, sweepFile, outDir, logDir, passThrough));
            refJob = submit(sbatch, script);
            sbatch.push_back("--dependency=afterok:" + refJob);
            sbatch.push_back("--kill-on-invalid-dep=yes"); // a failed reference cancels the array
        }
        const fs::path script = subDir / "array.sh";
        writeFileAtomically(script, arrayScript(options, jobName, todo.size(), vitrine, sweepFile, outDir,
                                                subDir / "tasks.txt", logDir, passThrough));
        arrayJob = submit(sbatch, script);
    }
    const fs::path collectSh = subDir / "collect.sh";
    writeFileAtomically(collectSh, collectScript(options, jobName, vitrine, outDir, logDir));
    std::vector<std::string> collectCmd = {"sbatch", "--parsable"};
    if (!arrayJob.empty()) collectCmd.push_back("--dependency=afterany:" + arrayJob);
    const std::string collectJob = submit(collectCmd, collectSh);
    writeFileAtomically(
        subDir / "jobs.json",
        nlohmann::json{{"reference", refJob}, {"array", arrayJob}, {"collect", collectJob}, {"points", todo.size()}}
                .dump(2) +
            "\n");
    std::printf("submitted: %s%s%s collect job %s; scripts and logs in %s\n",
                refJob.empty() ? "" : ("reference job " + refJob + ", ").c_str(),
                arrayJob.empty() ? "no array (nothing to run),"
                                 : ("array job " + arrayJob + " (" + std::to_string(todo.size()) + " tasks),").c_str(),
                "", collectJob.c_str(), subDir.string().c_str());
    std::fflush(stdout);
    if (!options.wait) {
        std::printf("not waiting (--no-wait): `squeue -j %s` shows them; the table will be %s\n",
                    (arrayJob.empty() ? collectJob : arrayJob + "," + collectJob).c_str(),
                    (outDir / "sweep.json").string().c_str());
        return 0;
    }

    cli::InterruptHandlers interrupts;
    const bool tty = isatty(2);
    const auto start = Clock::now();
    std::string lastLine;
    size_t ok = 0, bad = 0, squeueFailures = 0;
    while (true) {
        const QueueState q = queryQueue(refJob, arrayJob, collectJob);
        ok = bad = 0;
        for (const Point* p : todo) {
            const PointState s = pointState(outDir, *p);
            ok += s == PointState::Done;
            bad += s == PointState::Failed;
        }
        const size_t pending = q.array.count("PENDING") ? q.array.at("PENDING") : 0;
        const size_t running = (q.array.count("RUNNING") ? q.array.at("RUNNING") : 0) +
                               (q.array.count("COMPLETING") ? q.array.at("COMPLETING") : 0);
        std::string line = "[slurm " + (arrayJob.empty() ? collectJob : arrayJob) + "] " + std::to_string(ok) + "/" +
                           std::to_string(todo.size()) + " done, " + std::to_string(bad) + " failed, " +
                           std::to_string(running) + " running, " + std::to_string(pending) + " pending";
        if (!q.reference.empty()) line += ", reference " + q.reference;
        line += ", collect " + (q.collect.empty() ? std::string("ended") : q.collect);
        if (!q.reason.empty()) line += " (waiting: " + q.reason + ")";
        if (!q.ok) {
            if (++squeueFailures == 30)
                throw UserError("--slurm: squeue failed 30 times in a row while waiting (the jobs may still run; "
                                "`vitrine sweep --collect " +
                                outDir.string() + "` gathers what they wrote): " + q.error);
            std::this_thread::sleep_for(std::chrono::seconds(2));
            continue;
        }
        squeueFailures = 0;
        const bool finished = q.collect.empty();
        if (tty) {
            std::fprintf(stderr, "\r%s, %s elapsed   ", line.c_str(),
                         clockText(std::chrono::duration<double>(Clock::now() - start).count()).c_str());
        } else if (line != lastLine) {
            std::fprintf(stderr, "%s, %s elapsed\n", line.c_str(),
                         clockText(std::chrono::duration<double>(Clock::now() - start).count()).c_str());
        }
        lastLine = line;
        if (finished) break;
        if (cli::InterruptHandlers::received()) {
            std::fprintf(stderr,
                         "\nstopped waiting; the jobs go on (`scancel %s` stops them) and the collect job "
                         "writes %s when the array ends\n",
                         (arrayJob.empty() ? collectJob : arrayJob + " " + collectJob).c_str(),
                         (outDir / "sweep.json").string().c_str());
            return cli::kExitInterrupted;
        }
        std::this_thread::sleep_for(std::chrono::seconds(tty ? 1 : 2));
    }
    if (tty) std::fprintf(stderr, "\n");
    const double wall = std::chrono::duration<double>(Clock::now() - start).count();

    // Tasks Slurm ended without a result in their folder (time limit, node failure, cancelled, a failed reference):
    // recorded as failed with what Slurm says, so that the table shows them and --retry-failed reruns them.
    const std::map<std::string, std::string> accounted =
        arrayJob.empty() ? std::map<std::string, std::string>{} : accountedStates(arrayJob);
    size_t lost = 0;
    for (size_t i = 0; i < todo.size(); ++i) {
        if (pointState(outDir, *todo[i]) != PointState::Todo) continue;
        ++lost;
        const std::string task = std::to_string(i);
        const fs::path log = logDir / (arrayJob + "_" + task + ".out");
        std::string why = "Slurm array task " + arrayJob + "_" + task + " ended without a result";
        if (accounted.count(task)) why += " (sacct: " + accounted.at(task) + ")";
        if (fs::exists(log, ec))
            why += "; log " + log.string() + ": " + tailOf(log, 1500);
        else
            why += "; it never started (cancelled" +
                   (refJob.empty() ? std::string()
                                   : ", or the reference job " + refJob +
                                         " failed: " + (logDir / ("reference-" + refJob + ".out")).string()) +
                   ")";
        writePointError(outDir / "points" / todo[i]->id, *todo[i], why, 2);
    }
    const CollectSummary summary = collect(outDir); // again, here: the lost points are in the table now
    if (lost) std::fprintf(stderr, "%zu point(s) ended without a result; recorded as failed\n", lost);
    const fs::path collectLog = logDir / ("collect-" + collectJob + ".out");
    if (!fs::exists(outDir / "sweep.json", ec))
        throw UserError("the collect job " + collectJob + " wrote no " + (outDir / "sweep.json").string() + "; log " +
                        collectLog.string() + ":\n" + tailOf(collectLog, 2000));
    std::printf("%zu done, %zu failed, %zu pending; this submission: %zu point(s) in %s through Slurm\nwrote %s\n"
                "      %s\n",
                summary.done, summary.failed, summary.pending, todo.size(), clockText(wall).c_str(),
                (outDir / "sweep.json").string().c_str(), (outDir / "report.html").string().c_str());
    return summary.failed || summary.pending ? 3 : 0;
}

} // namespace vitrine::sweep
