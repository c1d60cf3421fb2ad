#include "harness/commands/bench_command.h"

#include <CLI/CLI.hpp>

#include <iostream>

#include "harness/commands/run_command.h"
#include "rig/host/dds_pingpong.h"

namespace rig::harness {

SpeedBenchCommand::SpeedBenchCommand(CLI::App& app) {
    command_ = app.add_subcommand(
        "bench", "what lockstep costs: runs cases in process and in-process (SIL) mode beside a DDS ping-pong floor");
    command_->add_option("cases", options_.cases, "lockstep case files");
    command_->add_option("--repeat", options_.repeat, "runs per case and mode")->check(CLI::Range(1, 1000));
    command_->add_option("--pingpong-rounds", options_.pingpong.rounds, "timed DDS round trips")
        ->check(CLI::Range(10, 1000000));
    command_->add_option("--out", options_.out_dir, "traces and bench.json");
    command_->add_flag("--dds-security", options_.dds_security,
                       "also process mode and the ping-pong with DDS-Security (credentials in OUT/security)");
    command_->add_flag("--pong", pong_, "internal: be the ping-pong's second process")->group("");
    command_->add_option("--domain", domain_, "internal: the second process's domain")->group("");
}

bool SpeedBenchCommand::parsed() const { return command_->parsed(); }

int SpeedBenchCommand::run() {
    try {
        if (pong_) return run_dds_pong(domain_, options_.pingpong.rounds);
        SpeedBenchOptions options = options_;
        options.run = default_run_options();
        options.pingpong.pong_executable = own_directory() / "rig";
        options.pingpong.log_dir = options.out_dir;
        return run_speed_bench(options, std::cout, std::cerr);
    } catch (const std::exception& error) {
        std::cerr << "rig bench: " << error.what() << "\n";
        return 1;
    }
}

}  // namespace rig::harness
