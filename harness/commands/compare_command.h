#pragma once
// `rig compare BASE HEAD [--out DIR]` (docs/regression.md): two outputs of
// rig run or rig sweep, case by case and metric by metric; which metrics
// regressed, improved, stayed or cannot be compared, and why
// (harness/regression/compare.h decides, compare_report.h writes).
#include <map>
#include <string>
#include <vector>

#include "harness/cli/subcommand.h"
#include "harness/regression/compare.h"

namespace rig::harness {

class CompareCommand final : public Subcommand {
public:
    explicit CompareCommand(CLI::App& app);
    CompareCommand(const CompareCommand&) = delete;  // CLI11 holds pointers into the options
    CompareCommand& operator=(const CompareCommand&) = delete;
    bool parsed() const override;
    // 0: no regression; 1: at least one; 2: usage or unreadable input; 4: outputs not written.
    int run() override;

private:
    CLI::App* command_ = nullptr;
    std::string base_;
    std::string head_;
    std::string out_dir_;
    std::string bmf_file_;
    std::vector<std::string> min_effects_;
    CompareSettings settings_;
    bool quiet_ = false;
};

}  // namespace rig::harness
