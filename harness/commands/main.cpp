// `rig`: the rig's one command line (README "Running one case", `rig --help`).
// The table of subcommands is below; each lives beside what it runs:
//   rig run, rig sweep          harness/commands/run_command.h
//   rig judge, rig merge        harness/commands/judge_command.h
//   rig diff                    harness/commands/diff_command.h
//   rig compare                 harness/commands/compare_command.h
//   rig bench                   harness/commands/bench_command.h
//   rig dds-check               harness/commands/dds_check_command.h
//   rig mcap                    harness/commands/mcap_command.h
//   rig history                 harness/commands/history_command.h
//   rig falsify                 harness/commands/falsify_command.h
//   rig nmea decode             harness/bench/nmea_decode_tool.h
//   rig pty, rig hid, rig emulate gnss, rig modbus serve   harness/bench/
// A usage error (unknown command or option, missing or bad value) names the
// word at fault and exits 2; `rig --version` prints the version and commit.
#include <CLI/CLI.hpp>

#include <algorithm>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "harness/bench/bench_emulate.h"
#include "harness/bench/bench_hid.h"
#include "harness/bench/bench_modbus.h"
#include "harness/bench/bench_serial.h"
#include "harness/bench/nmea_decode_tool.h"
#include "harness/commands/bench_command.h"
#include "harness/commands/compare_command.h"
#include "harness/commands/dds_check_command.h"
#include "harness/commands/diff_command.h"
#include "harness/commands/falsify_command.h"
#include "harness/commands/history_command.h"
#include "harness/commands/judge_command.h"
#include "harness/commands/mcap_command.h"
#include "harness/commands/run_command.h"
#include "harness/report/build_info.h"
#include "rig/runtime/dds_security.h"

namespace {

// Edit distance, for "did you mean" on a mistyped command.
std::size_t edit_distance(const std::string& a, const std::string& b) {
    std::vector<std::size_t> row(b.size() + 1);
    for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
    for (std::size_t i = 1; i <= a.size(); ++i) {
        std::size_t diagonal = row[0];
        row[0] = i;
        for (std::size_t j = 1; j <= b.size(); ++j) {
            const std::size_t above = row[j];
            row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
            diagonal = above;
        }
    }
    return row[b.size()];
}

// A usage error as one line naming the word at fault, then exit status 2 (the
// shell convention for a command used wrongly; CLI11's own codes are 1xx).
// Help and --version are not errors: CLI11 prints them and they exit 0.
int usage_error(const CLI::App& app, const CLI::ParseError& error) {
    if (error.get_exit_code() == 0) return app.exit(error);
    // The command the error is in: the deepest subcommand that was reached.
    const CLI::App* command = &app;
    std::string path = "rig";
    for (bool deeper = true; deeper;) {
        deeper = false;
        for (const CLI::App* sub : command->get_subcommands([](const CLI::App*) { return true; })) {
            if (sub->parsed()) {
                command = sub;
                path += " " + sub->get_name();
                deeper = true;
                break;
            }
        }
    }
    std::vector<std::string> commands;
    for (const CLI::App* sub : command->get_subcommands([](const CLI::App*) { return true; })) {
        if (!sub->get_group().empty()) commands.push_back(sub->get_name());
    }
    std::vector<std::string> extras = app.remaining(/*recurse=*/true);
    std::string message;
    const bool needs_command = !commands.empty() && command->get_require_subcommand_min() > 0 &&
                               dynamic_cast<const CLI::RequiredError*>(&error) != nullptr;
    if (needs_command || dynamic_cast<const CLI::ExtrasError*>(&error) != nullptr) {
        const auto word = std::find_if(extras.begin(), extras.end(), [](const std::string& w) { return !w.empty(); });
        std::string list;
        for (const std::string& name : commands) list += (list.empty() ? "" : ", ") + name;
        if (word == extras.end()) {
            message = "missing command (commands: " + list + ")";
        } else if (word->front() == '-') {
            message = "unknown option '" + *word + "' (" + path + " --help lists the options)";
        } else if (needs_command) {
            std::string suggestion;
            for (const std::string& name : commands) {
                if (edit_distance(*word, name) <= 2) {
                    suggestion = "did you mean '" + name + "'? ";
                    break;
                }
            }
            message = "unknown command '" + *word + "' (" + suggestion + "commands: " + list + ")";
        } else {
            message = "unexpected argument '" + *word + "' (" + path + " --help says what it takes)";
        }
    } else {
        // CLI11's text names the option or argument: "--jobs: Value 99 not in
        // range 1 to 16", "--out: 1 required TEXT missing", "cases is required".
        message = std::string(error.what()) + " (" + path + " --help)";
    }
    std::cerr << path << ": " << message << "\n";
    return 2;
}

}  // namespace

int main(int argc, char** argv) {
    using namespace rig::harness;
    CLI::App app{"Sprayer HIL rig: runs timed cases against a controller under test and judges them from truth"};
    app.require_subcommand(1);
    app.set_version_flag("--version",
                         "rig " + std::string(rig_version()) + " (commit " + std::string(rig_commit()) + ")",
                         "print the rig's version and the commit it was built from, and exit");

    // The subcommands, in the order `rig --help` lists them.
    std::vector<std::unique_ptr<Subcommand>> commands;
    commands.push_back(std::make_unique<RunCommand>(app));
    commands.push_back(std::make_unique<JudgeCommand>(app));
    commands.push_back(std::make_unique<MergeCommand>(app));
    commands.push_back(std::make_unique<DiffCommand>(app));
    commands.push_back(std::make_unique<SweepCommand>(app));
    commands.push_back(std::make_unique<FalsifyCommand>(app));
    commands.push_back(std::make_unique<CompareCommand>(app));
    commands.push_back(std::make_unique<NmeaCommand>(app));
    commands.push_back(std::make_unique<PtyBenchCommand>(app));
    commands.push_back(std::make_unique<HidBenchCommand>(app));
    commands.push_back(std::make_unique<EmulateBenchCommand>(app));
    commands.push_back(std::make_unique<McapCommand>(app));
    commands.push_back(std::make_unique<HistoryCommand>(app));
    commands.push_back(std::make_unique<DdsCheckCommand>(app));
    commands.push_back(std::make_unique<SpeedBenchCommand>(app));
    commands.push_back(std::make_unique<ModbusCommand>(app));

    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& error) {
        return usage_error(app, error);
    }
    for (const std::unique_ptr<Subcommand>& command : commands) {
        if (!command->parsed()) continue;
        // Only --dds-security secures the rig's participants: RIG_DDS_SECURITY_DIR
        // is the controller's contract, read by the bench's second process alone.
        if (!command->security_from_environment()) rig::use_dds_security_identity(std::filesystem::path());
        return command->run();
    }
    return 2;
}
