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

#include "run_support.h"  // read_all

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

// The trace digest of one run of `case_file` at `seed` (`rig run` into `out`),
// "" after a failed assertion (the run did not succeed, or gave no digest).
inline std::string run_digest(const std::filesystem::path& case_file, int seed, const std::filesystem::path& out,
                              int timeout_s = 600) {
    const std::filesystem::path log = out.string() + ".log";
    const int status = run_rig("run '" + case_file.string() + "' --seed " + std::to_string(seed) + " --out '" +
                                   out.string() + "'",
                               log, timeout_s);
    if (status != 0) {
        ADD_FAILURE() << "rig run exited " << status << ":\n" << read_all(log);
        return {};
    }
    const std::string digest = load_results(out).at("cases").at(0).at("trace_sha256").get<std::string>();
    EXPECT_FALSE(digest.empty()) << "no digest in " << out;
    return digest;
}

}  // namespace rig::testing
