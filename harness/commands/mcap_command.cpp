#include "harness/commands/mcap_command.h"

#include <CLI/CLI.hpp>

#include <algorithm>
#include <filesystem>
#include <iostream>
#include <stdexcept>
#include <system_error>

#include "harness/trace/trace_mcap.h"

namespace rig::harness {

namespace {

namespace fs = std::filesystem;

// The trace files under a run's --out (cases/*/trace.sqlite), or the file itself.
std::vector<fs::path> traces_named_by(const std::string& argument) {
    const fs::path path(argument);
    if (!fs::is_directory(path)) return {path};
    std::vector<fs::path> found;
    const fs::path cases = path / "cases";
    if (fs::is_directory(cases)) {
        for (const fs::directory_entry& entry : fs::directory_iterator(cases)) {
            if (fs::is_regular_file(entry.path() / "trace.sqlite")) found.push_back(entry.path() / "trace.sqlite");
        }
    }
    if (found.empty()) throw std::runtime_error(argument + ": no cases/*/trace.sqlite in it (a rig run --out directory?)");
    std::sort(found.begin(), found.end());
    return found;
}

}  // namespace

McapCommand::McapCommand(CLI::App& app) {
    command_ = app.add_subcommand(
        "mcap", "write traces as MCAP for Foxglove or PlotJuggler: trace.mcap beside each trace.sqlite");
    command_->add_option("runs_or_traces", inputs_, "rig run --out directories or trace.sqlite files")->required();
    command_->add_option("--out", out_file_, "the MCAP file, when one trace is given (default: beside it)");
}

bool McapCommand::parsed() const { return command_->parsed(); }

int McapCommand::run() {
    std::vector<fs::path> traces;
    try {
        for (const std::string& input : inputs_) {
            for (fs::path& trace : traces_named_by(input)) traces.push_back(std::move(trace));
        }
    } catch (const std::exception& error) {
        std::cerr << "rig mcap: " << error.what() << "\n";
        return 2;
    }
    if (!out_file_.empty() && traces.size() != 1) {
        std::cerr << "rig mcap: --out names one file, but " << traces.size() << " traces were given\n";
        return 2;
    }
    int status = 0;
    for (const fs::path& trace : traces) {
        const fs::path mcap = out_file_.empty() ? trace.parent_path() / "trace.mcap" : fs::path(out_file_);
        // Written beside, then renamed: never a half-written file under the name, nor one replaced by it.
        const fs::path partial = mcap.string() + ".partial";
        try {
            const TraceMcapSummary summary = write_trace_mcap(trace, partial);
            fs::rename(partial, mcap);
            std::cout << mcap.string() << ": " << summary.messages << " messages on " << summary.channels
                      << " channels\n";
        } catch (const std::exception& error) {
            std::cerr << "rig mcap: " << error.what() << "\n";
            std::error_code ignored;
            fs::remove(partial, ignored);
            status = 1;
        }
    }
    return status;
}

}  // namespace rig::harness
