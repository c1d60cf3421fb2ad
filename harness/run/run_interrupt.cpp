#include "harness/run/run_interrupt.h"

#include <signal.h>

#include <atomic>

namespace rig::harness {

namespace {

// Written by the handler: a lock-free atomic int is async-signal-safe.
std::atomic<int> interrupt_signal{0};
static_assert(std::atomic<int>::is_always_lock_free);

extern "C" void rig_run_interrupt_handler(int signal) {
    interrupt_signal.store(signal);
    // Back to the default action: a second Ctrl-C ends the rig at once.
    struct sigaction restore {};
    restore.sa_handler = SIG_DFL;
    sigemptyset(&restore.sa_mask);
    sigaction(signal, &restore, nullptr);
}

}  // namespace

void install_run_interrupt_handlers() {
    struct sigaction action {};
    action.sa_handler = rig_run_interrupt_handler;
    sigemptyset(&action.sa_mask);
    action.sa_flags = SA_RESTART;
    sigaction(SIGINT, &action, nullptr);
    sigaction(SIGTERM, &action, nullptr);
}

int run_interrupt_signal() { return interrupt_signal.load(); }

void set_run_interrupt_for_test(int signal) { interrupt_signal.store(signal); }

}  // namespace rig::harness
