#pragma once
// `rig judge OUT_DIR|TRACE... [--out NEW_DIR] [--check]`: judges recorded traces
// again (harness/judge/judge_trace.h, with each trace's system's judge), with today's metric code, and writes the same
// results contract as `rig run` (results.json, junit.xml, report.txt, report.html).
//   OUT_DIR   a `rig run --out` directory: every cases/*/trace.sqlite in it, in
//             the order of its results.json (or by name when there is none)
//   TRACE     one trace file
//   --out     where the new results go (nothing is written without it)
//   --check   compare with OUT_DIR/results.json: every metric bit for bit, what
//             was not measured, the verdicts, the failures and the digests; any
//             difference is printed and makes the exit status 5
// Exit status: 5 when --check found a difference (the judging changed: a CI
// must not read it as a controller's failure), else 1 when a case failed, 3
// when none failed but one was invalid, 0 when every case passed; 2 for bad
// arguments or a trace that cannot be read. With --check the last line says
// which.
#include <filesystem>
#include <iosfwd>
#include <string>
#include <vector>

#include "harness/cli/subcommand.h"

namespace rig::harness {

struct JudgeCommandOptions {
    std::vector<std::string> inputs;
    std::filesystem::path out_dir;  // empty: print only
    bool check = false;
};

int run_judge_command(const JudgeCommandOptions& options, std::ostream& out, std::ostream& err);

// A re-judging whose results differ from those recorded (rig judge --check,
// rig merge): the judge's code or the traces changed, not the controller.
inline constexpr int kExitRejudgedDiffers = 5;

// `rig merge SHARD_OUT... --out DIR`: the outputs of `rig run --shard I/N`
// joined into one run directory, as one `rig run` of all the cases would have
// written it: every shard's cases/NAME/ copied into DIR/cases/, each trace
// judged again and checked against its shard's results.json (every metric,
// verdict and digest), then DIR's results.json, junit.xml and reports. A case
// name found in two shards, a shard without results.json, or a DIR that is not
// new or empty are refused before anything is written (exit 2). Exit as
// `rig judge --check`: 5 if a case differs from its shard, else 1 if a case
// failed, 3 if only invalid; the last line says which.
// The outputs of `rig sweep --shard I/N` (a sweep.json in each) are joined
// into one sweep instead (harness/report/sweep_shard.h): every shard of one
// sweep, once, or nothing is written (exit 2); a mix of run and sweep outputs
// is refused. Exit as `rig sweep`: 1 if a run did not pass.
struct MergeCommandOptions {
    std::vector<std::string> shard_dirs;
    std::filesystem::path out_dir;
};
int run_merge_command(const MergeCommandOptions& options, std::ostream& out, std::ostream& err);

class JudgeCommand final : public Subcommand {
public:
    explicit JudgeCommand(CLI::App& app);
    JudgeCommand(const JudgeCommand&) = delete;  // CLI11 holds pointers into options_
    JudgeCommand& operator=(const JudgeCommand&) = delete;
    bool parsed() const override;
    int run() override;

private:
    CLI::App* command_ = nullptr;
    JudgeCommandOptions options_;
};

class MergeCommand final : public Subcommand {
public:
    explicit MergeCommand(CLI::App& app);
    MergeCommand(const MergeCommand&) = delete;
    MergeCommand& operator=(const MergeCommand&) = delete;
    bool parsed() const override;
    int run() override;

private:
    CLI::App* command_ = nullptr;
    MergeCommandOptions options_;
};

}  // namespace rig::harness
