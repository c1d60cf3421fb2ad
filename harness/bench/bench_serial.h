#pragma once
// `rig pty`: bench wiring from pseudo-terminals, for a person at the bench or a
// script (a null-modem cable between two programs that only speak serial).
//
//   rig pty [--link-a PATH] [--link-b PATH] [--baud N] [--frame 8N1]
//       Creates a linked pair (rig/wire/pty_pair.h PtyLink), prints both slave paths
//       (and the symlinks), forwards until SIGINT/SIGTERM, exits 0.
//   rig pty --single [--link-a PATH]
//       One pty: what a program writes to it appears on standard output, and
//       standard input is written to it (a terminal on the rig's side).
//
// Output, one path per line, so scripts can read it:
//   pty a: /dev/pts/5 (symlink /tmp/gnss0)
//   pty b: /dev/pts/6
#include <iosfwd>
#include <string>

#include "harness/cli/subcommand.h"

namespace rig::harness {

struct PtyBenchOptions {
    bool single = false;
    std::string link_a;  // empty: no symlink
    std::string link_b;
    int baud = 115200;   // nominal: a pty moves bytes at memory speed
    std::string frame = "8N1";
};

// Blocks until SIGINT or SIGTERM arrives; returns the exit status (0 after a
// signal, 1 when the ptys cannot be set up, 2 for bad options), printing
// errors to `err`.
int run_pty_bench(const PtyBenchOptions& options, std::ostream& out, std::ostream& err);

// The subcommand, registered in harness/commands/main.cpp's table: declares `rig pty` on `app`.
class PtyBenchCommand final : public Subcommand {
public:
    explicit PtyBenchCommand(CLI::App& app);
    PtyBenchCommand(const PtyBenchCommand&) = delete;  // CLI11 holds pointers into options_
    PtyBenchCommand& operator=(const PtyBenchCommand&) = delete;
    bool parsed() const override;
    int run() override;

private:
    CLI::App* command_ = nullptr;
    PtyBenchOptions options_;
};

}  // namespace rig::harness
