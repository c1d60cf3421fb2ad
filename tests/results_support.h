#pragma once
// Helpers for the tests that run `rig run` / `rig judge` as a user would and
// read the verdicts back from results.json.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>
#include <stdexcept>
#include <string>

#include <nlohmann/json.hpp>

namespace rig::testing {

// `rig ARGS` with its output in `log`, bounded by `timeout_s` (a hung run fails
// the test instead of stalling the suite); the exit status, -1 if killed.
inline int run_rig(const std::string& args, const std::filesystem::path& log, int timeout_s = 600) {
    const std::string command = "timeout -k 10 " + std::to_string(timeout_s) + " '" RIG_BINARY_DIR "/bin/rig' " + args +
                                " > '" + log.string() + "' 2>&1";
    const int status = std::system(command.c_str());
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

inline nlohmann::json load_results(const std::filesystem::path& out) {
    std::ifstream in(out / "results.json");
    if (!in) {
        ADD_FAILURE() << "no results.json in " << out;
        return nlohmann::json::object();
    }
    return nlohmann::json::parse(in);
}

// The case run named `name` (throws if the results have none).
inline const nlohmann::json& find_case(const nlohmann::json& results, const std::string& name) {
    for (const auto& c : results.at("cases")) {
        if (c.at("name") == name) return c;
    }
    throw std::runtime_error("no case " + name + " in the results");
}

// The metrics named by a case's failures ("metric value > limit ...").
inline std::set<std::string> failing_metrics(const nlohmann::json& one_case) {
    std::set<std::string> metrics;
    for (const auto& failure : one_case.at("failures")) {
        const std::string line = failure.get<std::string>();
        metrics.insert(line.substr(0, line.find(' ')));
    }
    return metrics;
}

}  // namespace rig::testing
