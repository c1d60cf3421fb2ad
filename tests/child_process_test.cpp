// rig::ChildProcess: the controller under test runs in its own process group,
// and nothing of it outlives the run — not a wrapper script's child, not after
// the rig itself is killed. A controller left running would sit in a DDS
// domain the next run leases and talk to it.
#include "rig/host/child_process.h"
#include "rig/runtime/clock.h"

#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fcntl.h>

#include <algorithm>
#include <chrono>
#include <fstream>
#include <vector>
#include <string>

namespace {

using namespace std::chrono_literals;

std::string temp_path(const std::string& name) {
    return ::testing::TempDir() + "/child-process-" + std::to_string(::getpid()) + "-" + name;
}

// True when the process is gone or a zombie (killed, not yet reaped by init).
bool process_ended(pid_t pid) {
    std::ifstream stat("/proc/" + std::to_string(pid) + "/stat");
    if (!stat) return true;
    std::string line;
    std::getline(stat, line);
    const auto close_paren = line.rfind(')');
    return close_paren != std::string::npos && close_paren + 2 < line.size() && line[close_paren + 2] == 'Z';
}

// Generous bounds: these wait for the kernel, not for a timing property.
bool eventually_ended(pid_t pid) {
    for (int i = 0; i < 2000; ++i) {
        if (process_ended(pid)) return true;
        rig::pause_between_polls(5ms);
    }
    return false;
}

pid_t read_pid_file(const std::string& path) {
    for (int i = 0; i < 2000; ++i) {
        std::ifstream in(path);
        pid_t pid = 0;
        if (in >> pid && pid > 0) return pid;
        rig::pause_between_polls(5ms);
    }
    return -1;
}

TEST(ChildProcess, StoppingAWrapperScriptAlsoStopsWhatItStarted) {
    const std::string pid_file = temp_path("grandchild-a");
    std::remove(pid_file.c_str());
    rig::ChildProcess wrapper({"/bin/sh", "-c", "sleep 600 & echo $! > " + pid_file + "; wait"},
                              temp_path("wrapper-a.log"));
    const pid_t grandchild = read_pid_file(pid_file);
    ASSERT_GT(grandchild, 0);
    const std::string how = wrapper.stop(200ms);
    EXPECT_NE(how.find("signal"), std::string::npos) << how;
    EXPECT_TRUE(eventually_ended(grandchild)) << "the wrapper's child survived the stop";
}

TEST(ChildProcess, ALeaderThatExitsLeavesNoChildBehind) {
    const std::string pid_file = temp_path("grandchild-b");
    std::remove(pid_file.c_str());
    rig::ChildProcess wrapper({"/bin/sh", "-c", "sleep 600 & echo $! > " + pid_file + "; exit 3"},
                              temp_path("wrapper-b.log"));
    const pid_t grandchild = read_pid_file(pid_file);
    ASSERT_GT(grandchild, 0);
    std::optional<std::string> ended;
    for (int i = 0; i < 2000 && !ended; ++i) {
        ended = wrapper.exit_description();
        if (!ended) rig::pause_between_polls(5ms);
    }
    ASSERT_TRUE(ended.has_value());
    EXPECT_EQ(*ended, "process exited with status 3");
    EXPECT_TRUE(eventually_ended(grandchild));
}

TEST(ChildProcess, ItIsInItsOwnProcessGroup) {
    rig::ChildProcess sleeper({"sleep", "600"}, temp_path("sleeper.log"));
    EXPECT_EQ(::getpgid(sleeper.pid()), sleeper.pid());
    EXPECT_NE(::getpgid(sleeper.pid()), ::getpgrp());
    sleeper.stop(100ms);
}

TEST(ChildProcess, ACommandThatCannotStartIsNamed) {
    try {
        rig::ChildProcess missing({"/nonexistent/controller-binary", "--flag"}, temp_path("missing.log"));
        FAIL() << "started a command that does not exist";
    } catch (const std::runtime_error& error) {
        const std::string what = error.what();
        EXPECT_NE(what.find("/nonexistent/controller-binary --flag"), std::string::npos) << what;
        EXPECT_NE(what.find("No such file"), std::string::npos) << what;
    }
}

// A program that exists, with a log that cannot be opened (its directory is
// missing): the error names the log, not the program, as what is missing.
TEST(ChildProcess, ALogThatCannotBeOpenedIsNamedNotTheProgram) {
    const std::string log = temp_path("no-such-directory") + "/child.log";
    try {
        rig::ChildProcess child({"/bin/true"}, log);
        FAIL() << "started with a log in a directory that does not exist";
    } catch (const std::runtime_error& error) {
        const std::string what = error.what();
        EXPECT_EQ(what, "cannot start '/bin/true': cannot open its log '" + log + "': No such file or directory");
    }
}

TEST(ChildProcess, TheLogFileGetsStdoutAndStderr) {
    const std::string log = temp_path("both.log");
    rig::ChildProcess talker({"/bin/sh", "-c", "echo out; echo err >&2"}, log);
    for (int i = 0; i < 2000 && !talker.exit_description(); ++i) rig::pause_between_polls(5ms);
    std::ifstream in(log);
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    EXPECT_EQ(text, "out\nerr\n");
}

TEST(ChildProcess, GetsTheRigsEnvironmentWithItsOwnVariablesSetOverIt) {
    // How the controller gets its DDS-Security identity (RIG_DDS_SECURITY_DIR).
    ::setenv("RIG_CHILD_TEST_KEPT", "from the rig", 1);
    ::setenv("RIG_CHILD_TEST_SET", "the rig's value", 1);
    const std::string log = temp_path("environment.log");
    rig::ChildProcess printer({"/bin/sh", "-c", "echo \"$RIG_CHILD_TEST_KEPT|$RIG_CHILD_TEST_SET|$RIG_CHILD_TEST_NEW\""}, log,
                              {"RIG_CHILD_TEST_SET=the child's", "RIG_CHILD_TEST_NEW=new=with equals"});
    for (int i = 0; i < 2000 && !printer.exit_description(); ++i) rig::pause_between_polls(5ms);
    std::ifstream in(log);
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    EXPECT_EQ(text, "from the rig|the child's|new=with equals\n");
    ::unsetenv("RIG_CHILD_TEST_KEPT");
    ::unsetenv("RIG_CHILD_TEST_SET");
}

TEST(ChildProcess, InheritsNoDescriptorButItsStandardOnes) {
    // An fd of the rig's without close-on-exec (as Fast DDS's sockets are):
    // the controller must not get it.
    const std::string marker = temp_path("inherited.txt");
    std::ofstream(marker) << "rig's file\n";
    const int fd = ::open(marker.c_str(), O_RDONLY);
    ASSERT_GE(fd, 3);
    const std::string log = temp_path("fds.log");
    rig::ChildProcess lister({"/bin/sh", "-c", "ls /proc/$$/fd"}, log);
    for (int i = 0; i < 2000 && !lister.exit_description(); ++i) rig::pause_between_polls(5ms);
    ::close(fd);
    std::ifstream in(log);
    std::vector<std::string> fds;
    for (std::string line; std::getline(in, line);) fds.push_back(line);
    EXPECT_NE(std::find(fds.begin(), fds.end(), "1"), fds.end()) << "the listing did not run";
    EXPECT_EQ(std::find(fds.begin(), fds.end(), std::to_string(fd)), fds.end()) << "fd " << fd << " was inherited";
}

TEST(ChildProcess, ItDiesWithTheRig) {
    // A stand-in for the rig that is killed without stopping its controller.
    int pipe_fds[2];
    ASSERT_EQ(::pipe(pipe_fds), 0);
    const pid_t rig = ::fork();
    ASSERT_GE(rig, 0);
    if (rig == 0) {
        ::close(pipe_fds[0]);
        auto* child = new rig::ChildProcess({"sleep", "600"}, temp_path("orphan.log"));  // never stopped
        const pid_t pid = child->pid();
        [[maybe_unused]] auto n = ::write(pipe_fds[1], &pid, sizeof pid);
        ::raise(SIGKILL);
    }
    ::close(pipe_fds[1]);
    pid_t controller = -1;
    ASSERT_EQ(::read(pipe_fds[0], &controller, sizeof controller), static_cast<ssize_t>(sizeof controller));
    ::close(pipe_fds[0]);
    int status = 0;
    ::waitpid(rig, &status, 0);
    ASSERT_TRUE(WIFSIGNALED(status));
    EXPECT_TRUE(eventually_ended(controller)) << "the controller outlived the rig that started it";
}

}  // namespace
