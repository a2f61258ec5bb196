#include "core/base/log.hpp"

#include <unistd.h>

#include <algorithm>
#include <vector>

namespace vitrine {

namespace {
LogLevel gLevel = LogLevel::Info;
thread_local ProgressObserver tObserver;
thread_local std::vector<const std::string*> tNodes;
} // namespace

ScopedProgressObserver::ScopedProgressObserver(ProgressObserver observer) : mPrevious(std::move(tObserver)) {
    tObserver = std::move(observer);
}
ScopedProgressObserver::~ScopedProgressObserver() { tObserver = std::move(mPrevious); }

ScopedProgressNode::ScopedProgressNode(const std::string& node) { tNodes.push_back(&node); }
ScopedProgressNode::~ScopedProgressNode() { tNodes.pop_back(); }

void setLogLevel(LogLevel level) { gLevel = level; }
LogLevel logLevel() { return gLevel; }

void log(LogLevel level, const std::string& message) {
    if (level < gLevel) return;
    static const char* kPrefix[] = {"debug: ", "", "warning: ", "error: "};
    std::fprintf(stderr, "%s%s\n", kPrefix[static_cast<int>(level)], message.c_str());
}

Progress::Progress(std::string label, size_t total)
    : mLabel(std::move(label)), mTotal(total), mTerminal(isatty(STDERR_FILENO) != 0),
      mStart(std::chrono::steady_clock::now()), mLastDraw(mStart), mLastNotify(mStart) {
    if (gLevel <= LogLevel::Info && mTotal > 1) draw(true);
    notify(true);
}

Progress::~Progress() { finish(); }

void Progress::advance(size_t steps) {
    mDone += steps;
    if (mDone > mTotal) mDone = mTotal;
    draw(false);
    notify(false);
}

void Progress::advanceTo(double fraction) {
    const size_t target = static_cast<size_t>(std::clamp(fraction, 0.0, 1.0) * static_cast<double>(mTotal));
    if (target > mDone) advance(target - mDone);
}

void Progress::finish() {
    if (mFinished) return;
    mFinished = true;
    mDone = mTotal;
    notify(true);
    if (gLevel > LogLevel::Info || mTotal <= 1) return;
    draw(true);
    if (mTerminal) std::fputc('\n', stderr);
}

void Progress::notify(bool force) {
    if (!tObserver) return;
    auto now = std::chrono::steady_clock::now();
    if (!force && now - mLastNotify < std::chrono::milliseconds(100) && mDone != mTotal) return;
    mLastNotify = now;
    tObserver(tNodes.empty() ? std::string() : *tNodes.front(), mLabel, mDone, mTotal);
}

void Progress::draw(bool force) {
    if (gLevel > LogLevel::Info || mTotal <= 1) return;
    auto now = std::chrono::steady_clock::now();
    double elapsed = std::chrono::duration<double>(now - mStart).count();
    if (mTerminal) {
        if (!force && now - mLastDraw < std::chrono::milliseconds(100) && mDone != mTotal) return;
        mLastDraw = now;
        const int width = 30;
        int filled = static_cast<int>(width * mDone / mTotal);
        std::string bar(filled, '#');
        bar.resize(width, '.');
        // The time left, from the rate so far, once some work is done.
        char left[48] = "";
        if (mDone > 0 && mDone < mTotal && elapsed > 0.5)
            std::snprintf(left, sizeof left, ", ~%.0fs left", elapsed * static_cast<double>(mTotal - mDone) / mDone);
        std::fprintf(stderr, "\r%s [%s] %zu/%zu  %.1fs%s   ", mLabel.c_str(), bar.c_str(), mDone, mTotal, elapsed, left);
        std::fflush(stderr);
    } else {
        int quarter = static_cast<int>(4 * mDone / mTotal);
        if (quarter == mLastQuarter) return;
        mLastQuarter = quarter;
        std::fprintf(stderr, "%s: %zu/%zu (%.1fs)\n", mLabel.c_str(), mDone, mTotal, elapsed);
    }
}

} // namespace vitrine
