#pragma once
#include <sys/wait.h>
// Small helpers for the tests that run the `rig` executables as a user would
// (whole runs, the network check, the negative cases).
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>
#include <string>

namespace rig::testing {

// An empty scratch folder under GoogleTest's temp dir, named for the test.
inline std::filesystem::path fresh_dir(const std::string& name) {
    const std::filesystem::path dir = std::filesystem::path(::testing::TempDir()) / name;
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    return dir;
}

// A path as one word of a shell command line (single-quoted).
inline std::string shell_word(const std::filesystem::path& path) { return "'" + path.string() + "'"; }

// A whole file as text ("" when it cannot be read: the caller's assertion says what was expected).
inline std::string read_all(const std::filesystem::path& path) {
    std::ifstream in(path);
    std::stringstream text;
    text << in.rdbuf();
    return text.str();
}

// What a shell command prints on its standard output ("" if it cannot run).
inline std::string read_all_command(const std::string& command) {
    std::string output;
    if (FILE* pipe = ::popen(command.c_str(), "r")) {
        char buffer[4096];
        while (std::fgets(buffer, sizeof buffer, pipe) != nullptr) output += buffer;
        ::pclose(pipe);
    }
    return output;
}

// A shell command's exit status and everything it printed on stdout (add
// `2>&1` to the command for stderr too); exit_code -1 when it did not exit.
struct ShellResult {
    int exit_code = -1;
    std::string output;
};
inline ShellResult run_shell(const std::string& command) {
    ShellResult result;
    if (FILE* pipe = ::popen(command.c_str(), "r")) {
        char buffer[4096];
        while (std::fgets(buffer, sizeof buffer, pipe) != nullptr) result.output += buffer;
        const int status = ::pclose(pipe);
        result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    }
    return result;
}

// Destinations in an strace log (sendto/sendmsg/connect lines as strace 6 prints them).
inline std::set<std::string> strace_destinations(const std::filesystem::path& strace_log) {
    std::set<std::string> found;
    std::ifstream log(strace_log);
    const std::regex ipv4(R"re(sin_addr=inet_addr\("([^"]+)"\))re");
    const std::regex ipv6(R"re(inet_pton\(AF_INET6, "([^"]+)")re");
    std::string line;
    while (std::getline(log, line)) {
        for (const auto* pattern : {&ipv4, &ipv6}) {
            for (auto it = std::sregex_iterator(line.begin(), line.end(), *pattern); it != std::sregex_iterator();
                 ++it) {
                found.insert((*it)[1]);
            }
        }
    }
    return found;
}

}  // namespace rig::testing
