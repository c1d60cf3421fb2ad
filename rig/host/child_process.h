#pragma once
// A node in its own process (the controller under test): started by the harness
// from the command the case names, its output captured to a log file, stopped at
// the end, killed if it does not stop.
#include <chrono>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <sys/types.h>

namespace rig {

class ChildProcess {
public:
    // Starts argv[0] (searched in PATH if it has no '/'), stdout+stderr to log_path,
    // with this process's environment and `environment` ("NAME=value" each, set
    // over it: the controller's DDS-Security identity). Throws std::runtime_error
    // naming the command when it cannot be started.
    ChildProcess(const std::vector<std::string>& argv, const std::filesystem::path& log_path,
                 const std::vector<std::string>& environment = {});
    // The same with stdout+stderr to `output_fd` (a pipe's write end: the
    // caller closes its own copy after the start).
    ChildProcess(const std::vector<std::string>& argv, int output_fd, const std::vector<std::string>& environment = {});
    ~ChildProcess();  // terminates if still running
    ChildProcess(const ChildProcess&) = delete;
    ChildProcess& operator=(const ChildProcess&) = delete;

    pid_t pid() const { return pid_; }
    // Non-blocking: nullopt while running, else a description of how it ended.
    std::optional<std::string> exit_description();
    // Waits up to `grace` for it to end by itself, then SIGTERM and up to `grace`
    // again, then SIGKILL. Returns how it ended.
    std::string stop(std::chrono::milliseconds grace = std::chrono::milliseconds(3000));
    const std::string& command_line() const { return command_line_; }

private:
    void start(const std::vector<std::string>& argv, const std::filesystem::path* log_path, int output_fd,
               const std::vector<std::string>& environment);
    static std::string describe_status(int status);
    pid_t pid_ = -1;
    std::optional<std::string> ended_;
    std::string command_line_;
};

// What a short command printed and how it ended.
struct CommandResult {
    std::string ended;   // "process exited with status 0", "... killed by signal 9 (Killed) after SIGKILL"
    std::string output;  // its stdout and stderr, interleaved as written (at most max_output bytes)
    bool succeeded() const { return ended == "process exited with status 0"; }
};
// Runs argv to its end, its output captured through a pipe (no file is
// written), stopped (SIGTERM, then SIGKILL) when it runs past `time_limit`.
// Throws std::runtime_error naming the command when it cannot be started.
CommandResult run_command(const std::vector<std::string>& argv, std::chrono::milliseconds time_limit,
                          std::size_t max_output = 64 * 1024);

}  // namespace rig
