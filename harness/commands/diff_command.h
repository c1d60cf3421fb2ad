#pragma once
// `rig diff A B [CASE] [--html FILE] [--window SECONDS]` (docs/diff.md): two
// runs of one case, sample against sample (harness/trace/trace_diff.h): "what
// did my commit change?".
//   A B       two trace files, or two `rig run --out` directories
//   CASE      with two directories: the case (its run name) to compare; not
//             needed when each holds that one case only
//   --html    also write a page with the case's key signals of both runs over
//             each other around the instant they part
//   --window  seconds drawn on either side of that instant (default 5)
// It prints whether the runs differ in case file, seed, mode, controller or
// rig; the first sample where they part (simulated time, topic, both values);
// which topics part and in what order, and whether the controller parted
// first or the devices and plant did (then the case or the rig changed, not
// the controller); and both runs' metrics (a run directory's results.json,
// or judged from a bare trace as `rig judge` does).
// Exit status: 0 when every sample is the same (same behaviour), 1 when the
// runs part, 2 for bad arguments, an input that cannot be read, or two traces
// of different cases.
#include <filesystem>
#include <iosfwd>
#include <string>
#include <vector>

#include "harness/cli/subcommand.h"

namespace rig::harness {

struct DiffCommandOptions {
    std::vector<std::string> inputs;
    std::filesystem::path html_file;  // empty: no page
    double window_s = 5.0;
};

int run_diff_command(const DiffCommandOptions& options, std::ostream& out, std::ostream& err);

class DiffCommand final : public Subcommand {
public:
    explicit DiffCommand(CLI::App& app);
    DiffCommand(const DiffCommand&) = delete;  // CLI11 holds pointers into options_
    DiffCommand& operator=(const DiffCommand&) = delete;
    bool parsed() const override;
    int run() override;

private:
    CLI::App* command_ = nullptr;
    DiffCommandOptions options_;
};

}  // namespace rig::harness
