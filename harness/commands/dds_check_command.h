#pragma once
// `rig dds-check [--samples N] [--log-dir DIR]`: the bench's self-test, a
// ping/pong with a second process of `rig` over the loopback DDS profile
// (rig/host/dds_check.h). `--echo` makes this process the second side.
#include <cstdint>

#include "harness/cli/subcommand.h"
#include "rig/host/dds_check.h"

namespace rig::harness {

class DdsCheckCommand final : public Subcommand {
public:
    explicit DdsCheckCommand(CLI::App& app);
    DdsCheckCommand(const DdsCheckCommand&) = delete;  // CLI11 holds pointers into options_
    DdsCheckCommand& operator=(const DdsCheckCommand&) = delete;
    bool parsed() const override;
    int run() override;

private:
    CLI::App* command_ = nullptr;
    DdsCheckOptions options_;
    bool echo_ = false;
    std::uint32_t domain_ = 0;
};

}  // namespace rig::harness
