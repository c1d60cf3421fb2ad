// Hard rule: the rig never sends to anything but 127.0.0.1. Runs a whole case
// (harness + controller process) under `strace -f -e trace=sendto,sendmsg,connect`
// and fails on any IPv4/IPv6 destination other than 127.0.0.1.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <set>
#include <string>

namespace {

std::set<std::string> destinations_in(const std::filesystem::path& strace_log) {
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

TEST(NetworkLoopbackOnly, WholeCaseSendsOnlyTo127001) {
    const std::filesystem::path out = std::filesystem::path(::testing::TempDir()) / "network-loopback";
    std::filesystem::remove_all(out);
    std::filesystem::create_directories(out);
    const std::filesystem::path strace_log = out / "strace.log";
    const std::string command = "strace -f -qq -e trace=sendto,sendmsg,connect -o '" + strace_log.string() + "' '" +
                                RIG_BINARY_DIR + "/bin/rig' run '" + RIG_SOURCE_DIR +
                                "/tests/data/short-fusion.yaml' --out '" + (out / "run").string() + "' > '" +
                                (out / "rig.log").string() + "' 2>&1";
    const int status = std::system(command.c_str());
    ASSERT_EQ(status, 0) << "rig run under strace failed; see " << (out / "rig.log");

    const auto destinations = destinations_in(strace_log);
    // The run talked over UDP loopback at least once, so strace did see traffic.
    ASSERT_TRUE(destinations.count("127.0.0.1")) << "no destination seen at all: is strace capturing?";
    for (const auto& destination : destinations) {
        EXPECT_EQ(destination, "127.0.0.1") << "traffic to " << destination << " (see " << strace_log << ")";
    }
}

TEST(NetworkLoopbackOnly, ParserSeesNonLoopbackDestinations) {
    // The check above must be able to fail: feed it lines as strace prints them.
    const std::filesystem::path log = std::filesystem::path(::testing::TempDir()) / "strace-sample.log";
    std::ofstream(log) << "12 sendto(5, \"x\", 1, 0, {sa_family=AF_INET, sin_port=htons(7400), "
                          "sin_addr=inet_addr(\"239.255.0.1\")}, 16) = 1\n"
                          "12 sendmsg(6, {msg_name={sa_family=AF_INET6, sin6_port=htons(7410), "
                          "sin6_flowinfo=htonl(0), inet_pton(AF_INET6, \"fe80::1\", &sin6_addr)}}, 0) = 1\n";
    const auto destinations = destinations_in(log);
    EXPECT_TRUE(destinations.count("239.255.0.1"));
    EXPECT_TRUE(destinations.count("fe80::1"));
}

}  // namespace
