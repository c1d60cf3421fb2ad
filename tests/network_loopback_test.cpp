// Hard rule: the rig never sends to anything but 127.0.0.1 (docs/design.md "DDS and the network").
// Two independent observers, each shown able to see a forbidden destination:
//  * the kernel's view: `strace -f` of `rig dds-check`, a two-process DDS
//    exchange through the loopback profile (discovery + user data);
//  * the libc boundary: tests/send_destination_recorder.cpp preloaded into a
//    whole case run (`rig run` + the controller process it spawns), which is
//    too slow to finish under ptrace.
#include <gtest/gtest.h>

#include "run_support.h"

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>
#include <string>

namespace {

namespace fs = std::filesystem;

fs::path fresh_dir(const std::string& name) { return rig::testing::fresh_dir("network-loopback-" + name); }

using rig::testing::read_all;
using rig::testing::strace_destinations;

// Destinations in a send_destination_recorder log: "<pid> <call> <family> <address> <port>".
std::set<std::string> recorder_destinations(const fs::path& recorder_log) {
    std::set<std::string> found;
    std::ifstream log(recorder_log);
    std::string pid, call, family, address, port;
    while (log >> pid >> call >> family >> address >> port) found.insert(address);
    return found;
}

std::string preload(const fs::path& recorder_log) {
    // Adds to ASAN_OPTIONS rather than replacing it: a sanitizer build's test
    // environment masks a mismatch inside Fast DDS there (cmake/RigHelpers.cmake).
    return "env ASAN_OPTIONS=\"${ASAN_OPTIONS:+$ASAN_OPTIONS:}verify_asan_link_order=0\" LD_PRELOAD='" RIG_SEND_RECORDER
           "' RIG_SEND_LOG='" + recorder_log.string() + "' ";
}

void expect_only_loopback(const std::set<std::string>& destinations, const fs::path& evidence) {
    ASSERT_TRUE(destinations.count("127.0.0.1")) << "no destination seen at all; is the observer working? " << evidence;
    for (const auto& destination : destinations) {
        EXPECT_EQ(destination, "127.0.0.1") << "traffic to " << destination << " (see " << evidence << ")";
    }
}

TEST(NetworkLoopbackOnly, KernelSeesOnlyLoopbackDuringDdsExchange) {
    const fs::path out = fresh_dir("strace");
    const fs::path strace_log = out / "strace.log";
    // `timeout` bounds the run even if DDS misbehaves under ptrace.
    const std::string command = "timeout -k 10 240 strace -f -qq -e trace=sendto,sendmsg,sendmmsg,connect -o '" +
                                strace_log.string() + "' '" RIG_BINARY_DIR "/bin/rig' dds-check --samples 10 --log-dir '" +
                                out.string() + "' > '" + (out / "rig.log").string() + "' 2>&1";
    const int status = std::system(command.c_str());
    ASSERT_EQ(status, 0) << "rig dds-check under strace failed:\n" << read_all(out / "rig.log");
    expect_only_loopback(strace_destinations(strace_log), strace_log);
}

TEST(NetworkLoopbackOnly, WholeCaseSendsOnlyTo127001) {
    const fs::path out = fresh_dir("whole-case");
    const fs::path recorder_log = out / "destinations.log";
    const std::string command = "timeout -k 10 240 " + preload(recorder_log) + "'" RIG_BINARY_DIR "/bin/rig' run '" +
                                RIG_SOURCE_DIR "/tests/data/short-fusion.yaml' --out '" + (out / "run").string() +
                                "' > '" + (out / "rig.log").string() + "' 2>&1";
    const int status = std::system(command.c_str());
    ASSERT_EQ(status, 0) << "rig run with the send recorder failed:\n" << read_all(out / "rig.log");
    // Both processes (harness and controller) must have been observed.
    std::set<std::string> pids;
    {
        std::ifstream log(recorder_log);
        std::string line;
        while (std::getline(log, line)) pids.insert(line.substr(0, line.find(' ')));
    }
    EXPECT_GE(pids.size(), 2u) << "expected the harness and the controller process in " << recorder_log;
    expect_only_loopback(recorder_destinations(recorder_log), recorder_log);
}

// The observers must be able to fail: the probe connects to 192.0.2.1 (no
// packet leaves: UDP connect only sets the peer) and sends one datagram to 127.0.0.1.
TEST(NetworkLoopbackOnly, RecorderSeesNonLoopbackDestination) {
    const fs::path out = fresh_dir("recorder-probe");
    const fs::path recorder_log = out / "destinations.log";
    ASSERT_EQ(std::system((preload(recorder_log) + "'" RIG_SEND_RECORDER_PROBE "'").c_str()), 0);
    const auto destinations = recorder_destinations(recorder_log);
    EXPECT_TRUE(destinations.count("127.0.0.1")) << read_all(recorder_log);
    EXPECT_TRUE(destinations.count("192.0.2.1")) << read_all(recorder_log);
}

TEST(NetworkLoopbackOnly, StraceSeesNonLoopbackDestination) {
    const fs::path out = fresh_dir("strace-probe");
    const fs::path strace_log = out / "strace.log";
    const std::string command = "strace -f -qq -e trace=sendto,connect -o '" + strace_log.string() + "' '" +
                                RIG_SEND_RECORDER_PROBE "'";
    ASSERT_EQ(std::system(command.c_str()), 0);
    const auto destinations = strace_destinations(strace_log);
    EXPECT_TRUE(destinations.count("127.0.0.1")) << read_all(strace_log);
    EXPECT_TRUE(destinations.count("192.0.2.1")) << read_all(strace_log);
}

TEST(NetworkLoopbackOnly, StraceParserReadsIpv6AndMulticast) {
    const fs::path log = fresh_dir("strace-sample") / "strace.log";
    std::ofstream(log) << "12 sendto(5, \"x\", 1, 0, {sa_family=AF_INET, sin_port=htons(7400), "
                          "sin_addr=inet_addr(\"239.255.0.1\")}, 16) = 1\n"
                          "12 sendmsg(6, {msg_name={sa_family=AF_INET6, sin6_port=htons(7410), "
                          "sin6_flowinfo=htonl(0), inet_pton(AF_INET6, \"fe80::1\", &sin6_addr)}}, 0) = 1\n";
    const auto destinations = strace_destinations(log);
    EXPECT_TRUE(destinations.count("239.255.0.1"));
    EXPECT_TRUE(destinations.count("fe80::1"));
}

}  // namespace
