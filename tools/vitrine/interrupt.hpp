#pragma once

namespace vitrine::cli {

// Exit status of a run stopped by Ctrl-C (SIGINT) or SIGTERM: 128 + SIGINT, what shells report for Ctrl-C.
inline constexpr int kExitInterrupted = 130;

// While alive, the first SIGINT or SIGTERM only sets a flag that `run`'s frame loop checks after each frame: the run
// stops at that frame boundary with the finished frames' files written. Work inside the frame that can end early sees
// it too (ExecuteContext::stopRequested): render.pathtrace converging to its target stops after its batch and keeps its
// partial result in the bake cache for the next run. The handler is one-shot, so a second signal
// ends the process at once (files are written atomically, so that leaves no half-written file either). The previous
// handlers come back on destruction. Installed by runCommand, and by main around compareCommand (which stops after the
// render in progress and compares nothing; the Python module calls compareCommand without them); other commands keep
// the default behaviour.
class InterruptHandlers {
public:
    InterruptHandlers();
    ~InterruptHandlers();
    InterruptHandlers(const InterruptHandlers&) = delete;
    InterruptHandlers& operator=(const InterruptHandlers&) = delete;

    // The signal received since construction (SIGINT or SIGTERM), or 0.
    static int received();
};

} // namespace vitrine::cli
