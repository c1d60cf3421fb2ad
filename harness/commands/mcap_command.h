#pragma once
// `rig mcap OUT_DIR|TRACE... [--out FILE]`: each trace as MCAP beside it (or
// at FILE), for Foxglove or PlotJuggler (harness/trace/trace_mcap.h writes it;
// docs/trace-format.md "MCAP").
#include <string>
#include <vector>

#include "harness/cli/subcommand.h"

namespace rig::harness {

class McapCommand final : public Subcommand {
public:
    explicit McapCommand(CLI::App& app);
    McapCommand(const McapCommand&) = delete;  // CLI11 holds pointers into the options
    McapCommand& operator=(const McapCommand&) = delete;
    bool parsed() const override;
    // 0 when every trace was written, 1 when one could not be, 2 for bad arguments.
    int run() override;

private:
    CLI::App* command_ = nullptr;
    std::vector<std::string> inputs_;
    std::string out_file_;
};

}  // namespace rig::harness
