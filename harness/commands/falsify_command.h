#pragma once
// `rig falsify` (issue 30, docs/falsify.md): searches a case's parameter
// space for the point with the smallest robustness margin to a limit
// (harness/falsify/).
//   rig falsify CASE --vary KEY=LO:HI... [--metric M]... [--budget N] [--seeds K] [--jobs J]
//               [--method crs2|direct|isres|random] [--start N] [--search-seed S] [--first]
//               [--set KEY=VALUE]... [--in-process] [--no-pin] [--quiet] --out DIR
//   rig falsify NAME.search.yaml [the same options, which override the file's; --vary and --set are the file's]
// Writes DIR/falsify.json, DIR/worst.yaml, DIR/falsify.html and prints a
// summary line. Exit 1 a falsifying point was found, 0 the budget ran out
// without one, 2 a usage, case or search file error (nothing ran), 4 the
// outputs could not be written, 128 + N after signal N.
#include <cstdint>
#include <string>
#include <vector>

#include "harness/cli/subcommand.h"
#include "harness/run/case_runner.h"

namespace CLI {
class App;
class Option;
}  // namespace CLI

namespace rig::harness {

class FalsifyCommand final : public Subcommand {
public:
    explicit FalsifyCommand(CLI::App& app);
    FalsifyCommand(const FalsifyCommand&) = delete;  // CLI11 holds pointers into the options
    FalsifyCommand& operator=(const FalsifyCommand&) = delete;
    bool parsed() const override;
    int run() override;

private:
    CLI::App* command_ = nullptr;
    RunOptions options_;
    std::string input_;
    std::vector<std::string> vary_texts_;
    std::vector<std::string> metrics_;
    std::vector<std::string> setting_texts_;
    std::uint64_t budget_ = 60;
    CLI::Option* budget_option_ = nullptr;
    std::uint64_t seeds_ = 0;
    CLI::Option* seeds_option_ = nullptr;
    std::string method_ = "crs2";
    CLI::Option* method_option_ = nullptr;
    std::uint64_t start_ = 0;
    CLI::Option* start_option_ = nullptr;
    std::uint64_t search_seed_ = 1;
    CLI::Option* search_seed_option_ = nullptr;
    bool first_ = false;
    bool quiet_ = false;
    std::string out_dir_;
};

}  // namespace rig::harness
