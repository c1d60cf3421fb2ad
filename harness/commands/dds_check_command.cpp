#include "harness/commands/dds_check_command.h"

#include <CLI/CLI.hpp>

#include <iostream>

#include "harness/commands/run_command.h"

namespace rig::harness {

DdsCheckCommand::DdsCheckCommand(CLI::App& app) {
    options_.echo_executable = own_directory() / "rig";
    options_.log_dir = std::filesystem::temp_directory_path();
    command_ = app.add_subcommand(
        "dds-check", "bench self-test: ping/pong with a second process over the loopback DDS profile");
    command_->add_option("--samples", options_.samples, "round trips")->check(CLI::Range(1, 100000));
    command_->add_option("--log-dir", options_.log_dir, "where the echo process writes its log");
    command_->add_flag("--echo", echo_, "internal: be the echo side")->group("");
    command_->add_option("--domain", domain_, "internal: the echo side's domain")->group("");
}

bool DdsCheckCommand::parsed() const { return command_->parsed(); }

int DdsCheckCommand::run() {
    try {
        if (echo_) return run_dds_echo(domain_, options_.samples, std::cout);
        return run_dds_check(options_, std::cout);
    } catch (const std::exception& error) {
        std::cerr << "rig dds-check: " << error.what() << "\n";
        return 1;
    }
}

}  // namespace rig::harness
