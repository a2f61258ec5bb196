#pragma once

#include <chrono>
#include <cstdio>
#include <functional>
#include <string>

namespace vitrine {

enum class LogLevel { Debug, Info, Warning, Error };

// Process-wide verbosity; the CLI sets it from --verbose / --quiet.
void setLogLevel(LogLevel level);
LogLevel logLevel();
void log(LogLevel level, const std::string& message);
inline void logInfo(const std::string& m) { log(LogLevel::Info, m); }
inline void logWarning(const std::string& m) { log(LogLevel::Warning, m); }
inline void logDebug(const std::string& m) { log(LogLevel::Debug, m); }

// A one-line progress bar on stderr for long work (many frames, bakes). Redraws in place on a
// terminal; off a terminal (CI logs) it prints a line at 25 % steps so logs stay short.
class Progress {
public:
    Progress(std::string label, size_t total);
    ~Progress();
    Progress(const Progress&) = delete;
    Progress& operator=(const Progress&) = delete;

    void advance(size_t steps = 1);
    // Advances to `fraction` (0..1) of the total when that is further than done so far (for work that reports the
    // fraction it has done).
    void advanceTo(double fraction);
    void finish();
    size_t done() const { return mDone; }

private:
    void draw(bool force);
    void notify(bool force);

    std::string mLabel;
    size_t mTotal;
    size_t mDone = 0;
    int mLastQuarter = -1;
    bool mTerminal;
    bool mFinished = false;
    std::chrono::steady_clock::time_point mStart;
    std::chrono::steady_clock::time_point mLastDraw;
    std::chrono::steady_clock::time_point mLastNotify;
};

// Who else hears of long work: `vitrine serve` forwards a bake's progress to its clients. The observer is per thread
// (the thread that does the work calls it), given the id of the graph node doing the work (the outermost one when
// a node runs a graph of its own, as ibl.capture does; "" outside any node), the Progress label and its counts.
// Called at most every 100 ms per Progress, and at its start and end.
using ProgressObserver =
    std::function<void(const std::string& node, const std::string& label, size_t done, size_t total)>;

class ScopedProgressObserver {
public:
    explicit ScopedProgressObserver(ProgressObserver observer);
    ~ScopedProgressObserver();
    ScopedProgressObserver(const ScopedProgressObserver&) = delete;
    ScopedProgressObserver& operator=(const ScopedProgressObserver&) = delete;

private:
    ProgressObserver mPrevious;
};

// Marks the graph node this thread works for while it lives (the compiler around a node's setup, the executor around
// its execute). `node` must outlive the guard.
class ScopedProgressNode {
public:
    explicit ScopedProgressNode(const std::string& node);
    ~ScopedProgressNode();
    ScopedProgressNode(const ScopedProgressNode&) = delete;
    ScopedProgressNode& operator=(const ScopedProgressNode&) = delete;
};

} // namespace vitrine
