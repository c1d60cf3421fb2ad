#pragma once
// SIGINT and SIGTERM during `rig run`: the run is not killed but told to stop.
// The running cases end at their next round as "interrupted" (their traces kept,
// with every sample up to then), the cases not yet started are reported as not
// run, results.json and junit.xml are written, and `rig run` exits 128 + the
// signal number (130 for SIGINT, 143 for SIGTERM). A second signal is not caught:
// it ends the rig at once, as the user asked twice.
namespace rig::harness {

// Installs the handlers (once per process).
void install_run_interrupt_handlers();
// The signal that asked the run to stop, or 0.
int run_interrupt_signal();
// For tests: as if `signal` had arrived (0 clears).
void set_run_interrupt_for_test(int signal);

}  // namespace rig::harness
