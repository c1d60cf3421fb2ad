#pragma once
// `rig run` and `rig sweep`: case files (or folders of them) read and checked
// before anything starts, run (harness/run/case_runner.h) and judged, the
// results written (harness/report/) and the table printed.
//   rig run CASE_OR_DIR... [--out DIR] [--seed N] [--jobs N] [--in-process | --dds-security] [--domain N]
//                          [--set KEY=VALUE]... [--shard I/N] [--no-pin] [--quiet | --verbose]
//   rig sweep CASE_OR_DIR... --seeds N [--first-seed N] [--keep-traces failed|all|none] [--out DIR] [--jobs N]
//                          [--set KEY=VALUE]... [--shard I/N] [--in-process] [--no-pin] [--quiet]
// --set replaces a value every case file given writes (harness/spec/case_settings.h).
// Exit status of both: 0 all passed, 1 a case failed, 2 a usage or case-file
// error (nothing ran), 3 (run) nothing failed but a real-time case was invalid,
// 4 the results could not be written, 128 + N after signal N.
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "harness/cli/subcommand.h"
namespace CLI {
class Option;
}
#include "harness/run/case_runner.h"

namespace rig::harness {

// The run options every subcommand that runs cases starts from: the reference
// controllers beside this `rig` (bin/) and their plugins (lib/rig/).
RunOptions default_run_options();
// The folder `rig` runs from.
std::filesystem::path own_directory();

// `--set KEY=VALUE`, on `command` (rig run, rig sweep, rig falsify's base).
void add_setting_option(CLI::App& command, std::vector<std::string>& setting_texts);
// --set's texts parsed; nullopt after saying on standard error what is wrong
// with one (the caller exits 2).
std::optional<std::vector<KeySetting>> parse_setting_texts(const std::vector<std::string>& texts,
                                                           const std::string& command);

class RunCommand final : public Subcommand {
public:
    explicit RunCommand(CLI::App& app);
    RunCommand(const RunCommand&) = delete;  // CLI11 holds pointers into the options
    RunCommand& operator=(const RunCommand&) = delete;
    bool parsed() const override;
    int run() override;

private:
    CLI::App* command_ = nullptr;
    RunOptions options_;
    std::vector<std::string> inputs_;
    std::uint64_t seed_ = 0;
    CLI::Option* seed_option_ = nullptr;
    std::uint32_t domain_ = 0;
    CLI::Option* domain_option_ = nullptr;
    std::string shard_text_;
    CLI::Option* shard_option_ = nullptr;
    bool quiet_ = false;
    bool verbose_ = false;
    bool dds_security_ = false;
    std::string bmf_file_;
    std::vector<std::string> setting_texts_;
};

class SweepCommand final : public Subcommand {
public:
    explicit SweepCommand(CLI::App& app);
    SweepCommand(const SweepCommand&) = delete;
    SweepCommand& operator=(const SweepCommand&) = delete;
    bool parsed() const override;
    int run() override;

private:
    CLI::App* command_ = nullptr;
    RunOptions options_;
    std::vector<std::string> inputs_;
    std::uint64_t seeds_ = 0;
    std::uint64_t first_seed_ = 1;
    std::string keep_traces_ = "failed";
    std::string shard_text_;
    CLI::Option* shard_option_ = nullptr;
    bool quiet_ = false;
    std::string bmf_file_;
    std::vector<std::string> setting_texts_;
};

// The help text of --no-pin, shared with `rig bench`.
extern const char* const kNoPinHelp;

}  // namespace rig::harness
