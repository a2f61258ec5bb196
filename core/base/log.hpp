#pragma once

#include <chrono>
#include <cstdio>
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
    void finish();

private:
    void draw(bool force);

    std::string mLabel;
    size_t mTotal;
    size_t mDone = 0;
    int mLastQuarter = -1;
    bool mTerminal;
    bool mFinished = false;
    std::chrono::steady_clock::time_point mStart;
    std::chrono::steady_clock::time_point mLastDraw;
};

} // namespace vitrine
