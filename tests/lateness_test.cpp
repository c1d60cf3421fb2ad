// The rig's own lateness in real-time runs (rig/runtime/lateness.h, issue 14
// item 5): the account fed by hand with deadlines and emission instants (no
// clock, no load: every figure is exact), and the RealtimeMaster's injected
// stall, whose lateness has a floor no machine load can lower.
#include <gtest/gtest.h>

#include "rig/host/domain_lease.h"
#include "rig/runtime/dds_context.h"
#include "rig/runtime/lateness.h"
#include "rig/runtime/realtime.h"

namespace {

constexpr rig::TimeNs kMs = 1'000'000;

// A 100 Hz device that emitted every deadline from 10 ms on `late_ms` late.
void feed_device(rig::LatenessAccount& account, const std::string& device, int emissions, double late_ms) {
    for (int k = 1; k <= emissions; ++k) {
        const rig::TimeNs deadline = k * 10 * kMs;
        account.record(device, deadline, deadline + static_cast<rig::TimeNs>(late_ms * 1e6));
    }
}

TEST(LatenessAccount, AnOnTimeRunIsWithinTheBound) {
    rig::LatenessAccount account;
    feed_device(account, "wheel_encoder", 1000, 0.05);
    feed_device(account, "gnss_g970", 50, 0.2);
    const rig::LatenessVerdict verdict = account.verdict();
    EXPECT_EQ(verdict.emissions, 1050u);
    EXPECT_EQ(verdict.late, 0u);
    EXPECT_DOUBLE_EQ(verdict.late_pct, 0.0);
    EXPECT_NEAR(verdict.max_ms, 0.2, 1e-9);
    EXPECT_EQ(verdict.worst_device, "gnss_g970");
    EXPECT_TRUE(verdict.first_late_device.empty());
    EXPECT_EQ(verdict.overloaded, "");
}

TEST(LatenessAccount, NoEmissionsIsNoOverload) {
    const rig::LatenessVerdict verdict = rig::LatenessAccount().verdict();
    EXPECT_EQ(verdict.emissions, 0u);
    EXPECT_EQ(verdict.overloaded, "");
}

TEST(LatenessAccount, OneEmissionPastTheLongestLatenessMakesTheRunInvalidNamingDeviceAndTime) {
    rig::LatenessAccount account;
    feed_device(account, "wheel_encoder", 500, 0.05);
    // One GNSS epoch, due at 3.4 s, left 153.2 ms late (a stalled machine).
    account.record("gnss_g970", 3400 * kMs, 3400 * kMs + static_cast<rig::TimeNs>(153.2 * 1e6));
    const rig::LatenessVerdict verdict = account.verdict();
    EXPECT_EQ(verdict.late, 1u);
    EXPECT_EQ(verdict.worst_device, "gnss_g970");
    EXPECT_EQ(verdict.worst_deadline_ns, 3400 * kMs);
    EXPECT_NEAR(verdict.max_ms, 153.2, 1e-6);
    EXPECT_EQ(verdict.first_late_device, "gnss_g970");
    EXPECT_EQ(verdict.overloaded,
              "gnss_g970 emitted 153.2 ms after its deadline at t = 3.400 s (bound realtime.max_lateness_ms: 100 ms)");
    EXPECT_EQ(verdict.devices.at("gnss_g970").late, 1u);
    EXPECT_EQ(verdict.devices.at("wheel_encoder").late, 0u);
}

TEST(LatenessAccount, TheBoundItselfIsWithinIt) {
    rig::LatenessBound bound;
    bound.max_lateness_ms = 50.0;
    rig::LatenessAccount account(bound);
    feed_device(account, "board_io", 1000, 0.0);
    account.record("board_io", 20 * kMs, 70 * kMs);  // exactly 50 ms late: late, not past the bound
    EXPECT_EQ(account.verdict().overloaded, "");
    account.record("board_io", 30 * kMs, 80 * kMs + 1);  // 1 ns more
    EXPECT_NE(account.verdict().overloaded.find("board_io emitted 50.0 ms after its deadline at t = 0.030 s"),
              std::string::npos)
        << account.verdict().overloaded;
}

TEST(LatenessAccount, TooManyLateEmissionsMakeTheRunInvalidEvenIfNoneIsVeryLate) {
    rig::LatenessAccount account;  // late after 10 ms, at most 1 % late, none over 100 ms
    feed_device(account, "wheel_encoder", 980, 0.1);
    // 20 of 1000 (2 %) emissions 30 ms late: a machine that does not keep time.
    for (int k = 0; k < 20; ++k) account.record("main_flow_meter", (5000 + 10 * k) * kMs, (5030 + 10 * k) * kMs);
    const rig::LatenessVerdict verdict = account.verdict();
    EXPECT_EQ(verdict.emissions, 1000u);
    EXPECT_EQ(verdict.late, 20u);
    EXPECT_DOUBLE_EQ(verdict.late_pct, 2.0);
    EXPECT_EQ(verdict.first_late_device, "main_flow_meter");
    EXPECT_EQ(verdict.first_late_deadline_ns, 5000 * kMs);
    EXPECT_EQ(verdict.overloaded,
              "20 of 1000 emissions (2.00 %) left more than 10 ms late, the first from main_flow_meter at t = 5.000 s "
              "(bound realtime.max_late_pct: 1 %)");
}

TEST(LatenessAccount, AFewLateEmissionsWithinTheShareAreNoOverload) {
    rig::LatenessAccount account;
    feed_device(account, "wheel_encoder", 990, 0.1);
    // 10 of 1000 (1 %, the bound) 30 ms late; an emission exactly late_after_ms late is not late.
    for (int k = 0; k < 10; ++k) account.record("main_flow_meter", (5000 + 10 * k) * kMs, (5030 + 10 * k) * kMs);
    account.record("main_flow_meter", 7000 * kMs, 7010 * kMs);
    EXPECT_EQ(account.verdict().late, 10u);
    EXPECT_EQ(account.verdict().overloaded, "");
}

TEST(LatenessAccount, AnEarlyEmissionIsOnTime) {
    rig::LatenessAccount account;
    account.record("plant", 50 * kMs, 40 * kMs);
    EXPECT_DOUBLE_EQ(account.verdict().max_ms, 0.0);
    EXPECT_EQ(account.verdict().late, 0u);
}

TEST(LatenessAccount, BothReasonsAreGivenWhenBothHold) {
    rig::LatenessBound bound;
    bound.max_late_pct = 0.0;
    rig::LatenessAccount account(bound);
    account.record("plant", 50 * kMs, 250 * kMs);
    const std::string overloaded = account.verdict().overloaded;
    EXPECT_NE(overloaded.find("plant emitted 200.0 ms"), std::string::npos) << overloaded;
    EXPECT_NE(overloaded.find("; 1 of 1 emissions (100.00 %)"), std::string::npos) << overloaded;
}

// A 100 Hz node with no endpoints: the master's only local node.
class Ticker final : public rig::Node {
public:
    const std::string& name() const override { return name_; }
    void configure(rig::DdsContext&) override {}
    rig::TimeNs step(rig::TimeNs now_ns) override { return rig::next_period_boundary(now_ns, 10 * kMs); }

private:
    std::string name_ = "ticker";
};

// The self-test fault (a case's rig_faults): the master stops stepping for
// 300 ms at (the first pass from) t = 50 ms. The ticker's next deadline is at
// most 10 ms after the stall began, and it cannot run before the stall ends,
// so it is at least 290 ms late on any machine (load only adds to it): the run
// is overloaded, deterministically.
TEST(RealtimeMaster, AnInjectedStallIsSeenAsTheRigsOwnLateness) {
    const rig::DomainLease lease = rig::DomainLease::acquire();
    rig::DdsContext dds(lease.domain_id(), "harness");
    Ticker ticker;
    rig::RealtimeMaster master(dds, rig::LockstepTimeouts{});
    master.add_local_node(ticker);
    master.inject_stall(50 * kMs, 300 * kMs);
    master.start();
    master.run_until(500 * kMs);
    master.shutdown();
    const rig::LatenessVerdict verdict = master.lateness();
    EXPECT_GE(verdict.max_ms, 290.0);
    EXPECT_EQ(verdict.worst_device, "ticker");
    EXPECT_GE(verdict.late, 1u);
    EXPECT_NE(verdict.overloaded.find("ticker emitted"), std::string::npos) << verdict.overloaded;
    // The same figures feed the jitter table.
    EXPECT_GE(master.emission_jitter().at("ticker").max_ms, 290.0);
}

}  // namespace
