#include "tools/vitrine/sweep/driver.hpp"

#include "core/base/atomic_file.hpp"
#include "core/base/error.hpp"
#include "tools/vitrine/interrupt.hpp"
#include "tools/vitrine/sweep/collect.hpp"
#include "tools/vitrine/sweep/point.hpp"

#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <fstream>
#include <map>
#include <sstream>
#include <thread>

namespace vitrine::sweep {

namespace fs = std::filesystem;

namespace {

using Clock = std::chrono::steady_clock;

volatile std::sig_atomic_t gSignals = 0;
extern "C" void onSweepSignal(int) {
    ++gSignals;
    static const char kFirst[] = "\nvitrine sweep: no new points; waiting for the running ones (again to stop them)\n";
    static const char kSecond[] = "\nvitrine sweep: stopping the running points\n";
    ssize_t ignored = gSignals == 1 ? ::write(2, kFirst, sizeof kFirst - 1) : ::write(2, kSecond, sizeof kSecond - 1);
    (void)ignored;
}

// SIGINT / SIGTERM counted while alive; point processes run in their own process group, so Ctrl-C on the terminal
// reaches the driver only and it decides: the first lets the running points finish, the second stops them.
class SignalCounter {
public:
    SignalCounter() {
        gSignals = 0;
        struct sigaction a {};
        a.sa_handler = onSweepSignal;
        sigemptyset(&a.sa_mask);
        a.sa_flags = SA_RESTART;
        sigaction(SIGINT, &a, &mInt);
        sigaction(SIGTERM, &a, &mTerm);
    }
    ~SignalCounter() {
        sigaction(SIGINT, &mInt, nullptr);
        sigaction(SIGTERM, &mTerm, nullptr);
    }

private:
    struct sigaction mInt {}, mTerm {};
};

std::string clockText(double seconds) {
    const long s = static_cast<long>(seconds + 0.5);
    char buf[32];
    if (s >= 3600) std::snprintf(buf, sizeof buf, "%ld:%02ld:%02ld", s / 3600, s / 60 % 60, s % 60);
    else std::snprintf(buf, sizeof buf, "%ld:%02ld", s / 60, s % 60);
    return buf;
}

fs::path selfExecutable() {
    std::error_code ec;
    fs::path p = fs::read_symlink("/proc/self/exe", ec);
    if (ec) throw std::runtime_error("cannot find the vitrine executable (/proc/self/exe): " + ec.message());
    return p;
}

std::string tail(const fs::path& file, size_t bytes) {
    std::ifstream in(file, std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    std::string s = ss.str();
    if (s.size() > bytes) s = "…" + s.substr(s.size() - bytes);
    while (!s.empty() && (s.back() == '\n' || s.back() == ' ')) s.pop_back();
    return s;
}

// Starts `argv` with stdout and stderr into `log`, in its own process group. The parent's clock goes in the
// environment (VITRINE_SWEEP_SPAWN_NS) so the point can report its start-up time.
pid_t spawn(const std::vector<std::string>& argv, const fs::path& log) {
    timespec now{};
    clock_gettime(CLOCK_REALTIME, &now);
    const std::string stamp =
        std::to_string(static_cast<long long>(now.tv_sec) * 1000000000LL + static_cast<long long>(now.tv_nsec));
    std::vector<char*> args;
    for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
    args.push_back(nullptr);
    const pid_t pid = fork();
    if (pid < 0) throw std::runtime_error(std::string("fork: ") + std::strerror(errno));
    if (pid == 0) {
        setpgid(0, 0);
        const int fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
        if (fd >= 0) {
            dup2(fd, 1);
            dup2(fd, 2);
            ::close(fd);
        }
        setenv("VITRINE_SWEEP_SPAWN_NS", stamp.c_str(), 1);
        execv(args[0], args.data());
        std::fprintf(stderr, "exec %s: %s\n", args[0], std::strerror(errno));
        _exit(127);
    }
    setpgid(pid, pid);
    return pid;
}

struct Running {
    const Point* point;
    Clock::time_point started;
};

} // namespace

nlohmann::json planOf(const SweepFile& sweep, const std::vector<Point>& points) {
    nlohmann::json plan;
    plan["format"] = "vitrine-sweep-plan/1";
    plan["sweep"] = sweep.file.string();
    plan["description"] = sweep.description;
    plan["graph"] = sweep.graph.string();
    if (sweep.reference) plan["reference"] = sweep.reference->string();
    plan["metrics"] = sweep.metrics;
    plan["keep"] = sweep.keep;
    plan["combine"] = sweep.zip ? "zip" : "product";
    plan["axes"] = nlohmann::json::array();
    for (const Axis& a : sweep.axes) {
        const char* kind = a.kind == AxisKind::Set ? "set" : a.kind == AxisKind::Variant ? "variants" : "frames";
        nlohmann::json values = nlohmann::json::array();
        for (size_t i = 0; i < a.values.size(); ++i)
            values.push_back(a.kind == AxisKind::Variant ? nlohmann::json(a.variantPaths[i].stem().string()) : a.values[i]);
        plan["axes"].push_back({{"name", a.name}, {"kind", kind}, {"key", a.key}, {"values", values}});
    }
    plan["points"] = nlohmann::json::array();
    for (const Point& p : points)
        plan["points"].push_back({{"id", p.id},
                                  {"label", p.label},
                                  {"values", p.values},
                                  {"graph", p.graph.string()},
                                  {"sets", p.sets},
                                  {"frames", p.frames.text()}});
    return plan;
}

int runSweep(const SweepFile& sweep, const std::vector<Point>& points, const DriverOptions& options) {
    const nlohmann::json plan = planOf(sweep, points);
    checkSamePlan(options.outDir, plan);
    writePlan(options.outDir, plan);
    std::vector<const Point*> todo;
    size_t done = 0, failedBefore = 0;
    std::error_code ec;
    for (const Point& p : points) {
        const fs::path dir = options.outDir / "points" / p.id;
        if (fs::exists(dir / "metrics.json", ec)) ++done;
        else if (fs::exists(dir / "error.json", ec) && !options.retryFailed) ++failedBefore;
        else todo.push_back(&p);
    }
    std::printf("%zu points: %zu done earlier (skipped), %zu failed earlier (%s), %zu to run with --jobs %u\n",
                points.size(), done, failedBefore, failedBefore ? "skipped; --retry-failed reruns them" : "none",
                todo.size(), options.jobs);
    std::fflush(stdout);

    const std::string exe = selfExecutable().string();
    auto pointArgv = [&](const std::vector<std::string>& extra, size_t slot) {
        std::vector<std::string> argv = {exe, "sweep", fs::absolute(options.sweepFile).string(), "--out",
                                         fs::absolute(options.outDir).string()};
        argv.insert(argv.end(), extra.begin(), extra.end());
        if (!options.devices.empty()) {
            argv.push_back("--device");
            argv.push_back(options.devices[slot % options.devices.size()]);
        }
        argv.insert(argv.end(), options.passThrough.begin(), options.passThrough.end());
        return argv;
    };

    SignalCounter signals;
    const bool tty = isatty(2);
    const auto sweepStart = Clock::now();
    if (sweep.reference && !todo.empty()) {
        // The reference once, before the points (each point would otherwise render it).
        fs::create_directories(options.outDir / "reference", ec);
        const fs::path log = options.outDir / "reference" / "log.txt";
        std::fprintf(stderr, "rendering the reference %s\n", sweep.reference->string().c_str());
        const auto t = Clock::now();
        const pid_t pid = spawn(pointArgv({"--reference-only"}, 0), log);
        int status = 0;
        while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
            if (gSignals >= 2) kill(pid, SIGTERM);
        }
        if (gSignals) {
            std::fprintf(stderr, "stopped while rendering the reference\n");
            return cli::kExitInterrupted;
        }
        if (!WIFEXITED(status) || WEXITSTATUS(status) != 0)
            throw UserError("the reference " + sweep.reference->string() + " failed (" + log.string() +
                            "):\n" + tail(log, 2000));
        std::fprintf(stderr, "reference ready in %.1f s\n",
                     std::chrono::duration<double>(Clock::now() - t).count());
    }

    std::map<pid_t, Running> running;
    size_t next = 0, finished = 0, failed = 0;
    double finishedSeconds = 0;
    std::vector<size_t> freeSlots;
    for (unsigned s = options.jobs; s-- > 0;) freeSlots.push_back(s);
    std::map<pid_t, size_t> slotOf;
    auto progress = [&](bool final) {
        const double elapsed = std::chrono::duration<double>(Clock::now() - sweepStart).count();
        const size_t remaining = todo.size() - finished;
        std::string eta = "?";
        if (finished > 0)
            eta = clockText(finishedSeconds / finished * static_cast<double>(remaining) /
                            std::min<double>(options.jobs, std::max<size_t>(remaining, 1)));
        if (tty) {
            const int width = 30;
            const int filled = todo.empty() ? width : static_cast<int>(width * finished / todo.size());
            std::fprintf(stderr, "\r[%s%s] %zu/%zu points, %zu failed, %zu running, %s elapsed, ETA %s   ",
                         std::string(filled, '#').c_str(), std::string(width - filled, '.').c_str(), finished,
                         todo.size(), failed, running.size(), clockText(elapsed).c_str(),
                         final ? "0:00" : eta.c_str());
            if (final) std::fprintf(stderr, "\n");
        }
        return eta;
    };
    auto lastDraw = Clock::now() - std::chrono::seconds(1);
    while (true) {
        while (gSignals == 0 && next < todo.size() && running.size() < options.jobs) {
            const Point* p = todo[next++];
            const fs::path dir = options.outDir / "points" / p->id;
            fs::create_directories(dir, ec);
            fs::remove(dir / "error.json", ec);
            const size_t slot = freeSlots.back();
            freeSlots.pop_back();
            const pid_t pid = spawn(pointArgv({"--point", p->id, "--quiet"}, slot), dir / "log.txt");
            running[pid] = {p, Clock::now()};
            slotOf[pid] = slot;
        }
        if (running.empty()) break;
        int status = 0;
        const pid_t pid = waitpid(-1, &status, WNOHANG);
        if (pid <= 0) {
            if (gSignals >= 2)
                for (const auto& [child, r] : running) kill(-child, SIGTERM);
            if (tty && Clock::now() - lastDraw > std::chrono::milliseconds(500)) {
                progress(false);
                lastDraw = Clock::now();
            }
            std::this_thread::sleep_for(std::chrono::milliseconds(100));
            continue;
        }
        auto it = running.find(pid);
        if (it == running.end()) continue;
        const Running r = it->second;
        running.erase(it);
        freeSlots.push_back(slotOf[pid]);
        slotOf.erase(pid);
        const double seconds = std::chrono::duration<double>(Clock::now() - r.started).count();
        const fs::path dir = options.outDir / "points" / r.point->id;
        const bool interrupted = gSignals >= 2 && WIFSIGNALED(status);
        const bool ok = WIFEXITED(status) && WEXITSTATUS(status) == 0 && fs::exists(dir / "metrics.json", ec);
        writeFileAtomically(dir / "driver.json", nlohmann::json{{"wall_ms", seconds * 1000.0},
                                                                {"exit_status", WIFEXITED(status) ? WEXITSTATUS(status) : -1},
                                                                {"signal", WIFSIGNALED(status) ? WTERMSIG(status) : 0}}
                                                         .dump(2) + "\n");
        std::string outcome = "done";
        if (interrupted) {
            outcome = "stopped (pending)";
        } else if (!ok) {
            ++failed;
            outcome = "FAILED";
            if (!fs::exists(dir / "error.json", ec)) {
                const std::string why = WIFSIGNALED(status)
                                            ? "killed by signal " + std::to_string(WTERMSIG(status))
                                            : "exit status " + std::to_string(WEXITSTATUS(status)) + " without metrics.json";
                writePointError(dir, *r.point, why + "; log: " + tail(dir / "log.txt", 1500),
                                WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status));
            }
        }
        ++finished;
        finishedSeconds += seconds;
        const std::string eta = progress(false);
        if (!tty || outcome != "done") {
            std::fprintf(stderr, "%s%s %s: %s in %.1f s (%zu/%zu, ETA %s)\n", tty ? "\r" : "", r.point->id.c_str(),
                         r.point->label.c_str(), outcome.c_str(), seconds, finished, todo.size(), eta.c_str());
            if (outcome == "FAILED") {
                std::ifstream in(dir / "error.json");
                nlohmann::json e = nlohmann::json::parse(in, nullptr, false);
                if (e.is_object()) std::fprintf(stderr, "    %s\n", e.value("error", std::string()).c_str());
            }
        }
    }
    if (tty) progress(true);
    const double wall = std::chrono::duration<double>(Clock::now() - sweepStart).count();
    const CollectSummary summary = collect(options.outDir);
    std::printf("%zu done, %zu failed, %zu pending; this run: %zu point(s) in %s (--jobs %u)\nwrote %s\n", summary.done,
                summary.failed, summary.pending, finished, clockText(wall).c_str(), options.jobs,
                (options.outDir / "report.html").string().c_str());
    if (gSignals) return cli::kExitInterrupted;
    return summary.failed ? 3 : 0;
}

} // namespace vitrine::sweep
