// Lockstep master/follower over real DDS (loopback profile) with a remote echo
// node in its own process (tests/lockstep_test_node.cpp).
#include <gtest/gtest.h>

#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "rig/host/child_process.h"
#include "rig/runtime/dds_context.h"
#include "rig/host/domain_lease.h"
#include "rig/runtime/follower.h"
#include "rig/runtime/lockstep.h"
#include "idl/topics.h"

namespace {

// Publishes "ping" every 10 ms of simulated time.
class Pinger final : public rig::Node {
public:
    const std::string& name() const override { return name_; }
    void configure(rig::DdsContext& dds) override {
        writer_ = std::make_unique<rig::Writer<rig::msg::NmeaSentence>>(dds, "test/ping");
    }
    rig::TimeNs step(rig::TimeNs now_ns) override {
        rig::msg::NmeaSentence ping;
        ping.sentence("ping " + std::to_string(now_ns));
        writer_->publish(ping);
        return now_ns + 10'000'000;
    }

private:
    std::string name_ = "pinger";
    std::unique_ptr<rig::Writer<rig::msg::NmeaSentence>> writer_;
};

struct RemoteEcho {
    rig::DomainLease lease = rig::DomainLease::acquire();
    std::unique_ptr<rig::ChildProcess> process;
    explicit RemoteEcho(const std::string& extra_flag = "", const std::string& extra_value = "") {
        std::vector<std::string> argv{RIG_LOCKSTEP_TEST_NODE, "--domain", std::to_string(lease.domain_id()),
                                      "--node-name", "echo"};
        if (!extra_flag.empty()) {
            argv.push_back(extra_flag);
            argv.push_back(extra_value);
        }
        process = std::make_unique<rig::ChildProcess>(argv, ::testing::TempDir() + "/echo-node.log");
    }
};

std::map<rig::TimeNs, std::string> run_echo_case(rig::TimeNs end_ns) {
    RemoteEcho echo;
    rig::DdsContext dds(echo.lease.domain_id(), "harness");
    Pinger pinger;
    rig::Reader<rig::msg::NmeaSentence> pongs(dds, "test/pong");
    std::map<rig::TimeNs, std::string> seen;
    rig::LockstepMaster master(dds, rig::LockstepTimeouts{});
    master.add_local_node(pinger);
    master.add_remote_node("echo", [&] { return echo.process->exit_description(); });
    master.set_after_round([&](rig::TimeNs t, int) {
        for (const auto& pong : pongs.take_all()) seen[t] += pong.sentence().to_string() + ";";
    });
    master.start();
    while (master.advance(end_ns)) {
    }
    master.shutdown();
    EXPECT_EQ(echo.process->stop(), "process exited with status 0");
    return seen;
}

// A plant whose time only the master moves: it logs every advance.
class LoggingTruth final : public rig::TruthModel {
public:
    void advance_to(rig::TimeNs now_ns) override { log.push_back("advance " + std::to_string(now_ns)); }
    std::vector<std::string> log;
};

// A sensor that samples the plant every `period`: it logs the instant it steps
// at, into the same log, so the order of advance and sample is visible.
class LoggingSensor final : public rig::Node {
public:
    LoggingSensor(std::string name, rig::TimeNs period, std::vector<std::string>& log)
        : name_(std::move(name)), period_(period), log_(log) {}
    const std::string& name() const override { return name_; }
    void configure(rig::DdsContext&) override {}
    rig::TimeNs step(rig::TimeNs now_ns) override {
        log_.push_back(name_ + " " + std::to_string(now_ns));
        return now_ns + period_;
    }

private:
    std::string name_;
    rig::TimeNs period_;
    std::vector<std::string>& log_;
};

// The plant is advanced once per instant, before any local node steps at it,
// whichever nodes are due; a device never advances it (rig/runtime/node.h).
TEST(Lockstep, TheTruthModelIsAdvancedOncePerInstantBeforeTheNodesStep) {
    rig::DomainLease lease = rig::DomainLease::acquire();
    rig::DdsContext dds(lease.domain_id(), "harness");
    LoggingTruth truth;
    LoggingSensor fast("fast", 20'000'000, truth.log);
    LoggingSensor slow("slow", 50'000'000, truth.log);
    rig::LockstepMaster master(dds, rig::LockstepTimeouts{});
    master.add_truth_model(truth);
    master.add_local_node(fast);
    master.add_local_node(slow);
    master.start();
    while (master.advance(100'000'000)) {
    }
    master.shutdown();
    const std::vector<std::string> expected{
        "advance 0",         "fast 0",         "slow 0",           //
        "advance 20000000",  "fast 20000000",                      //
        "advance 40000000",  "fast 40000000",                      //
        "advance 50000000",  "slow 50000000",                      //
        "advance 60000000",  "fast 60000000",                      //
        "advance 80000000",  "fast 80000000",                      //
        "advance 100000000", "fast 100000000", "slow 100000000"};
    EXPECT_EQ(truth.log, expected);
}

TEST(Lockstep, SamplePublishedAtTIsSeenAtTAndRunsAreIdentical) {
    const auto first = run_echo_case(500'000'000);
    ASSERT_EQ(first.size(), 51u);  // pings at 0, 10, ..., 500 ms
    for (const auto& [t, text] : first) {
        // The echo of the ping sent at t came back at the same simulated t.
        EXPECT_NE(text.find("ping " + std::to_string(t) + " #"), std::string::npos) << text;
        EXPECT_NE(text.find("@" + std::to_string(t) + ";"), std::string::npos) << text;
    }
    const auto second = run_echo_case(500'000'000);
    EXPECT_EQ(first, second);
}

TEST(Lockstep, NodeThatStopsAnsweringFailsByNameInBoundedTime) {
    RemoteEcho echo("--stall-at-ms", "200");
    rig::DdsContext dds(echo.lease.domain_id(), "harness");
    Pinger pinger;
    rig::Reader<rig::msg::NmeaSentence> pongs(dds, "test/pong");
    rig::LockstepTimeouts timeouts;
    timeouts.ack = std::chrono::milliseconds(1500);
    rig::LockstepMaster master(dds, timeouts);
    master.add_local_node(pinger);
    master.add_remote_node("echo", [&] { return echo.process->exit_description(); });
    master.start();
    const rig::WallStopwatch wall;
    try {
        while (master.advance(10'000'000'000)) {
        }
        FAIL() << "the stalled node was not detected";
    } catch (const rig::NodeFailure& failure) {
        EXPECT_EQ(failure.node_name(), "echo");
        EXPECT_NE(std::string(failure.what()).find("did not acknowledge tick"), std::string::npos) << failure.what();
        EXPECT_NE(std::string(failure.what()).find("t=0.200 s"), std::string::npos) << failure.what();
    }
    EXPECT_LT(wall.elapsed_s(), 30.0);
    echo.process->stop(std::chrono::milliseconds(500));
}

TEST(Lockstep, NodeProcessThatDiesFailsByName) {
    RemoteEcho echo;
    rig::DdsContext dds(echo.lease.domain_id(), "harness");
    Pinger pinger;
    rig::Reader<rig::msg::NmeaSentence> pongs(dds, "test/pong");
    rig::LockstepMaster master(dds, rig::LockstepTimeouts{});
    master.add_local_node(pinger);
    master.add_remote_node("echo", [&] { return echo.process->exit_description(); });
    master.start();
    ASSERT_TRUE(master.advance(1'000'000'000));
    ::kill(echo.process->pid(), SIGKILL);
    try {
        while (master.advance(10'000'000'000)) {
        }
        FAIL() << "the dead node was not detected";
    } catch (const rig::NodeFailure& failure) {
        EXPECT_EQ(failure.node_name(), "echo");
        EXPECT_NE(std::string(failure.what()).find("signal 9"), std::string::npos) << failure.what();
    }
}

// A node whose tick reader missed the hello, as a Cyclone DDS reader that
// matched the tick writer after the hello was written does (its volatile
// reader starts after the writer's first heartbeat): the master sends the
// hello again until every node answered (docs/controller-contract.md,
// "Conformance findings"). The node here drops the first copy on purpose.
TEST(Lockstep, TheHelloIsSentAgainUntilEveryNodeAnswered) {
    const rig::DomainLease lease = rig::DomainLease::acquire();
    rig::DdsContext harness(lease.domain_id(), "harness");
    rig::DdsContext node(lease.domain_id(), "late-reader");
    rig::Reader<rig::msg::ClockTick> ticks(node, rig::topics::kClockTick);
    rig::Writer<rig::msg::ClockAck> acks(node, rig::topics::kClockAck, false);
    rig::LockstepTimeouts timeouts;
    timeouts.startup = std::chrono::milliseconds(10'000);
    rig::LockstepMaster master(harness, timeouts);
    master.add_remote_node("late-reader", {});
    int hellos_seen = 0;
    std::thread late_reader([&] {
        const rig::WallStopwatch waited;
        while (waited.elapsed() < timeouts.startup) {
            ticks.wait_for_data(std::chrono::milliseconds(50));
            for (const rig::msg::ClockTick& tick : ticks.take_all()) {
                if (tick.seq() != 0 || ++hellos_seen == 1) continue;
                rig::msg::ClockAck ack;
                ack.node_name("late-reader");
                ack.seq(0);
                acks.publish(ack);
                return;
            }
        }
    });
    EXPECT_NO_THROW(master.start());
    late_reader.join();
    EXPECT_GE(hellos_seen, 2);
    master.shutdown(true);  // the node is gone: do not wait for its last answer
}

// A node that only reads, and says when it was configured and destroyed.
class LonelyReader final : public rig::Node {
public:
    LonelyReader(bool& configured, bool& destroyed) : configured_(configured), destroyed_(destroyed) {}
    ~LonelyReader() override { destroyed_ = true; }
    const std::string& name() const override { return name_; }
    void configure(rig::DdsContext& dds) override {
        reader_ = std::make_unique<rig::Reader<rig::msg::NmeaSentence>>(dds, "test/lonely");
        configured_ = true;
    }
    rig::TimeNs step(rig::TimeNs) override { return rig::kNever; }

private:
    std::string name_ = "lonely";
    bool& configured_;
    bool& destroyed_;
    std::unique_ptr<rig::Reader<rig::msg::NmeaSentence>> reader_;
};

rig::FollowerStartup lonely_startup(const rig::DomainLease& lease) {
    rig::FollowerStartup startup;
    startup.domain_id = lease.domain_id();
    startup.options.node_name = "lonely";
    startup.options.startup_timeout = std::chrono::milliseconds(300);
    return startup;
}

// run_follower (rig/runtime/follower.h) with no rig on the domain: the node it
// made is configured on the follower's context, the start-up gives up after
// its bound with status 3 (no counterpart) naming what was unmatched, and the
// node is gone when the call returns.
TEST(Follower, WithoutARigTheStartUpGivesUpWithStatus3) {
    const rig::DomainLease lease = rig::DomainLease::acquire();
    bool configured = false;
    bool destroyed = false;
    ::testing::internal::CaptureStderr();
    const int status =
        rig::run_follower(lonely_startup(lease), [&] { return std::make_unique<LonelyReader>(configured, destroyed); });
    const std::string said = ::testing::internal::GetCapturedStderr();
    EXPECT_EQ(status, 3);
    EXPECT_TRUE(configured);
    EXPECT_TRUE(destroyed);
    EXPECT_NE(said.find("lonely: no DDS counterpart within 300 ms for: "), std::string::npos) << said;
    EXPECT_NE(said.find("reads test/lonely"), std::string::npos) << said;
}

// What the factory throws (a bad configuration) reaches the program's own
// handler, which says it with the node's name; a factory that makes nothing is
// a programming error.
TEST(Follower, WhatTheFactoryThrowsComesOutOfRunFollower) {
    const rig::DomainLease lease = rig::DomainLease::acquire();
    EXPECT_THROW(rig::run_follower(lonely_startup(lease),
                                   []() -> std::unique_ptr<rig::Node> { throw std::runtime_error("bad config"); }),
                 std::runtime_error);
    EXPECT_THROW(rig::run_follower(lonely_startup(lease), [] { return std::unique_ptr<rig::Node>(); }), std::logic_error);
}

}  // namespace
