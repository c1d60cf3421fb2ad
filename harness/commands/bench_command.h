#pragma once
// `rig bench CASE... [--repeat N] [--pingpong-rounds N] [--dds-security] [--out DIR]`:
// what lockstep costs, per round, in process mode and in process (SIL), beside
// a two-process DDS ping-pong as its floor (harness/run/speed_bench.h;
// docs/speed.md). `--pong` makes this process the ping-pong's second side.
#include <cstdint>

#include "harness/cli/subcommand.h"
#include "harness/run/speed_bench.h"

namespace rig::harness {

class SpeedBenchCommand final : public Subcommand {
public:
    explicit SpeedBenchCommand(CLI::App& app);
    SpeedBenchCommand(const SpeedBenchCommand&) = delete;  // CLI11 holds pointers into options_
    SpeedBenchCommand& operator=(const SpeedBenchCommand&) = delete;
    bool parsed() const override;
    int run() override;
    bool security_from_environment() const override { return pong_; }

private:
    CLI::App* command_ = nullptr;
    SpeedBenchOptions options_;
    bool pong_ = false;
    std::uint32_t domain_ = 0;
};

}  // namespace rig::harness
