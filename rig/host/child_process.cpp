#include "rig/host/child_process.h"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <optional>
#include <cerrno>
#include <cstring>
#include <stdexcept>
#include <string_view>

#include "rig/runtime/clock.h"

namespace rig {
namespace {

// Where starting a child failed, reported from the child to the parent.
enum class StartStep : int { exec = 0, null_input = 1, log = 2, descriptors = 3 };

// Async-signal-safe (between fork and exec): FD_CLOEXEC on every fd from 3 up.
bool mark_close_on_exec(int max_fd) {
    for (int fd = 3; fd < max_fd; ++fd) {
        const int flags = ::fcntl(fd, F_GETFD);
        if (flags >= 0 && ::fcntl(fd, F_SETFD, flags | FD_CLOEXEC) != 0) return false;
    }
    return true;
}

}  // namespace

ChildProcess::ChildProcess(const std::vector<std::string>& argv, const std::filesystem::path& log_path,
                           const std::vector<std::string>& environment) {
    start(argv, &log_path, -1, environment);
}

ChildProcess::ChildProcess(const std::vector<std::string>& argv, int output_fd,
                           const std::vector<std::string>& environment) {
    start(argv, nullptr, output_fd, environment);
}

void ChildProcess::start(const std::vector<std::string>& argv, const std::filesystem::path* log_path, int output_fd,
                         const std::vector<std::string>& environment) {
    if (argv.empty()) throw std::runtime_error("empty command for a node process");
    for (const auto& arg : argv) command_line_ += (command_line_.empty() ? "" : " ") + arg;

    // Everything the child needs is prepared before fork: between fork and exec a
    // multithreaded parent (DDS threads) allows only async-signal-safe calls.
    std::vector<char*> raw_argv;
    for (const auto& arg : argv) raw_argv.push_back(const_cast<char*>(arg.c_str()));
    raw_argv.push_back(nullptr);
    // The child's environment: ours, with `environment` set over it.
    std::vector<std::string> child_environment(environment);
    for (char** variable = environ; *variable != nullptr; ++variable) {
        const std::string_view entry(*variable);
        const std::string_view name = entry.substr(0, entry.find('='));
        const bool overridden = std::any_of(environment.begin(), environment.end(), [&](const std::string& set) {
            return set.size() > name.size() && set.compare(0, name.size(), name) == 0 && set[name.size()] == '=';
        });
        if (!overridden) child_environment.emplace_back(entry);
    }
    std::vector<char*> raw_environment;
    for (const auto& entry : child_environment) raw_environment.push_back(const_cast<char*>(entry.c_str()));
    raw_environment.push_back(nullptr);
    const std::string log = log_path != nullptr ? log_path->string() : std::string();
    const pid_t parent = ::getpid();
    // For kernels without close_range (before 5.11): the fds to mark one by one.
    const long open_max = ::sysconf(_SC_OPEN_MAX);
    const int max_fd = static_cast<int>(open_max > 0 && open_max < 65536 ? open_max : 65536);

    // exec failure travels back over a close-on-exec pipe: EOF means exec succeeded.
    int report[2];
    if (::pipe2(report, O_CLOEXEC) != 0) {
        throw std::runtime_error("cannot start '" + command_line_ + "': pipe: " + std::strerror(errno));
    }
    pid_ = ::fork();
    if (pid_ < 0) {
        const int err = errno;
        ::close(report[0]);
        ::close(report[1]);
        throw std::runtime_error("cannot start '" + command_line_ + "': fork: " + std::strerror(err));
    }
    if (pid_ == 0) {
        // Its own process group: a Ctrl-C at the terminal reaches the rig alone,
        // which then ends the run and stops the group itself (and records why).
        ::setpgid(0, 0);
        // If the rig dies without stopping it (SIGKILL, a crash), the controller
        // dies too rather than living on in a DDS domain the next run will lease.
        ::prctl(PR_SET_PDEATHSIG, SIGKILL);
        if (::getppid() != parent) ::_exit(127);  // the parent died before prctl
        // What failed, and its errno: a log that cannot be opened is not a
        // missing program, and the error must say which it was.
        int failure[2] = {static_cast<int>(StartStep::exec), 0};
        const int in = ::open("/dev/null", O_RDONLY);
        const int out = in < 0 ? -1 : log_path == nullptr ? output_fd : ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
        if (in < 0) {
            failure[0] = static_cast<int>(StartStep::null_input);
            failure[1] = errno;
        } else if (out < 0) {
            failure[0] = static_cast<int>(StartStep::log);
            failure[1] = errno;
        } else if (::dup2(in, STDIN_FILENO) < 0 || ::dup2(out, STDOUT_FILENO) < 0 || ::dup2(out, STDERR_FILENO) < 0 ||
                   (::close_range(3, ~0U, CLOSE_RANGE_CLOEXEC) != 0 && !mark_close_on_exec(max_fd))) {
            failure[0] = static_cast<int>(StartStep::descriptors);
            failure[1] = errno;
        } else {
            // Nothing but stdin/out/err crosses exec: not the rig's DDS sockets
            // (a controller holding them would keep the rig's ports bound after
            // the rig is gone), not its trace files, not its ptys' masters.
            ::execvpe(raw_argv[0], raw_argv.data(), raw_environment.data());
            failure[1] = errno;
        }
        [[maybe_unused]] const auto written = ::write(report[1], failure, sizeof failure);
        ::_exit(127);
    }
    ::close(report[1]);
    int failure[2] = {0, 0};
    ssize_t got;
    do got = ::read(report[0], failure, sizeof failure);
    while (got < 0 && errno == EINTR);
    ::close(report[0]);
    if (got == static_cast<ssize_t>(sizeof failure)) {
        int status = 0;
        ::waitpid(pid_, &status, 0);
        pid_ = -1;
        const std::string reason = std::strerror(failure[1]);
        switch (static_cast<StartStep>(failure[0])) {
            case StartStep::null_input:
                throw std::runtime_error("cannot start '" + command_line_ + "': /dev/null: " + reason);
            case StartStep::log:
                throw std::runtime_error("cannot start '" + command_line_ + "': cannot open its log '" + log +
                                         "': " + reason);
            case StartStep::descriptors:
                throw std::runtime_error("cannot start '" + command_line_ + "': setting up its file descriptors: " +
                                         reason);
            case StartStep::exec:
                break;
        }
        throw std::runtime_error("cannot start '" + command_line_ + "': " + reason);
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
    // Look without reaping: while the leader is a zombie its pid (= the group id)
    // cannot be reused, so what is left of its group (a wrapper script's child)
    // can be killed safely before the leader is reaped.
    siginfo_t info{};
    if (::waitid(P_PID, static_cast<id_t>(pid_), &info, WEXITED | WNOHANG | WNOWAIT) != 0 || info.si_pid != pid_) {
        return ended_;
    }
    ::kill(-pid_, SIGKILL);
    int status = 0;
    ::waitpid(pid_, &status, 0);
    ended_ = describe_status(status);
    return ended_;
}

std::string ChildProcess::stop(std::chrono::milliseconds grace) {
    // First let it finish on its own (a follower exits after the shutdown tick),
    // then ask with SIGTERM, then insist.
    for (int signal_to_send : {0, SIGTERM}) {
        if (signal_to_send != 0) ::kill(-pid_, signal_to_send);  // the whole group: wrappers' children too
        const WallStopwatch waited;
        while (waited.elapsed() < grace) {
            if (exit_description()) return *ended_;
            timespec pause{0, 5'000'000};
            nanosleep(&pause, nullptr);
        }
    }
    ::kill(-pid_, SIGKILL);
    int status = 0;
    ::waitpid(pid_, &status, 0);
    ended_ = describe_status(status) + " after SIGKILL";
    return *ended_;
}

CommandResult run_command(const std::vector<std::string>& argv, std::chrono::milliseconds time_limit,
                          std::size_t max_output) {
    int pipe_fds[2];
    if (::pipe2(pipe_fds, O_CLOEXEC) != 0) {
        throw std::runtime_error("cannot run '" + (argv.empty() ? std::string() : argv.front()) +
                                 "': pipe: " + std::strerror(errno));
    }
    CommandResult result;
    std::optional<ChildProcess> child;
    try {
        child.emplace(argv, pipe_fds[1]);
    } catch (...) {
        ::close(pipe_fds[0]);
        ::close(pipe_fds[1]);
        throw;
    }
    ::close(pipe_fds[1]);
    // Read until the child (and anything it started) closes the pipe, or the time is up.
    const WallStopwatch waited;
    char buffer[4096];
    for (;;) {
        const auto left = time_limit - std::chrono::duration_cast<std::chrono::milliseconds>(waited.elapsed());
        if (left.count() <= 0) break;
        pollfd readable{pipe_fds[0], POLLIN, 0};
        const int ready = ::poll(&readable, 1, static_cast<int>(std::min<long long>(left.count(), 1000)));
        if (ready < 0 && errno == EINTR) continue;
        if (ready <= 0) continue;
        const ssize_t got = ::read(pipe_fds[0], buffer, sizeof buffer);
        if (got < 0 && errno == EINTR) continue;
        if (got <= 0) break;
        const std::size_t room = max_output - std::min(max_output, result.output.size());
        result.output.append(buffer, std::min<std::size_t>(room, static_cast<std::size_t>(got)));
    }
    ::close(pipe_fds[0]);
    result.ended = child->stop(std::chrono::milliseconds(500));
    return result;
}

}  // namespace rig
