#include "rig/host/child_process.h"

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <stdexcept>

#include "rig/runtime/clock.h"

extern char** environ;

namespace rig {

ChildProcess::ChildProcess(const std::vector<std::string>& argv, const std::filesystem::path& log_path) {
    if (argv.empty()) throw std::runtime_error("empty command for a node process");
    for (const auto& arg : argv) command_line_ += (command_line_.empty() ? "" : " ") + arg;

    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
    posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, log_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);

    // Its own process group: a Ctrl-C at the terminal reaches the rig alone, which
    // then ends the run and stops this process itself (and records why).
    posix_spawnattr_t attributes;
    posix_spawnattr_init(&attributes);
    posix_spawnattr_setflags(&attributes, POSIX_SPAWN_SETPGROUP);
    posix_spawnattr_setpgroup(&attributes, 0);

    std::vector<char*> raw_argv;
    for (const auto& arg : argv) raw_argv.push_back(const_cast<char*>(arg.c_str()));
    raw_argv.push_back(nullptr);
    const int rc = posix_spawnp(&pid_, raw_argv[0], &actions, &attributes, raw_argv.data(), environ);
    posix_spawn_file_actions_destroy(&actions);
    posix_spawnattr_destroy(&attributes);
    if (rc != 0) {
        throw std::runtime_error("cannot start '" + command_line_ + "': " + std::strerror(rc));
    }
}

ChildProcess::~ChildProcess() {
    if (pid_ > 0 && !ended_) stop(std::chrono::milliseconds(1000));
}

std::string ChildProcess::describe_status(int status) {
    if (WIFEXITED(status)) return "process exited with status " + std::to_string(WEXITSTATUS(status));
    if (WIFSIGNALED(status)) {
        const int sig = WTERMSIG(status);
        return std::string("process killed by signal ") + std::to_string(sig) + " (" + strsignal(sig) + ")";
    }
    return "process ended (status " + std::to_string(status) + ")";
}

std::optional<std::string> ChildProcess::exit_description() {
    if (ended_) return ended_;
    int status = 0;
    const pid_t rc = ::waitpid(pid_, &status, WNOHANG);
    if (rc == pid_) ended_ = describe_status(status);
    return ended_;
}

std::string ChildProcess::stop(std::chrono::milliseconds grace) {
    // First let it finish on its own (a follower exits after the shutdown tick),
    // then ask with SIGTERM, then insist.
    for (int signal_to_send : {0, SIGTERM}) {
        if (signal_to_send != 0) ::kill(pid_, signal_to_send);
        const WallStopwatch waited;
        while (waited.elapsed() < grace) {
            if (exit_description()) return *ended_;
            timespec pause{0, 5'000'000};
            nanosleep(&pause, nullptr);
        }
    }
    ::kill(pid_, SIGKILL);
    int status = 0;
    ::waitpid(pid_, &status, 0);
    ended_ = describe_status(status) + " after SIGKILL";
    return *ended_;
}

}  // namespace rig
