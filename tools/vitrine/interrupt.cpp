#include "tools/vitrine/interrupt.hpp"

#include <unistd.h>

#include <csignal>

namespace vitrine::cli {

namespace {

volatile std::sig_atomic_t gReceived = 0;
struct sigaction gPreviousInt, gPreviousTerm;

extern "C" void onInterrupt(int signal) {
    gReceived = signal;
    // write(2) is async-signal-safe; stdio is not.
    static const char kMessage[] =
        "\nvitrine: stopping after this frame (a converging path tracer keeps what it traced; again to quit at once)\n";
    ssize_t ignored = ::write(2, kMessage, sizeof kMessage - 1);
    (void)ignored;
}

} // namespace

InterruptHandlers::InterruptHandlers() {
    gReceived = 0;
    struct sigaction action {};
    action.sa_handler = onInterrupt;
    sigemptyset(&action.sa_mask);
    action.sa_flags = SA_RESETHAND | SA_RESTART; // one-shot: the second Ctrl-C gets the default action
    sigaction(SIGINT, &action, &gPreviousInt);
    sigaction(SIGTERM, &action, &gPreviousTerm);
}

InterruptHandlers::~InterruptHandlers() {
    sigaction(SIGINT, &gPreviousInt, nullptr);
    sigaction(SIGTERM, &gPreviousTerm, nullptr);
}

int InterruptHandlers::received() {
    return gReceived;
}

} // namespace vitrine::cli
