// In-process delivery (issue 32, rig/runtime/dds_context.h LocalBus): when
// every node lives in one process, a sample goes from writer to readers by
// hand-off. The readers get what DDS gives them, in the same order, with the
// same writer; a reader outside the bus (an observer on the domain) still gets
// every sample over DDS, and the bus's readers get each sample once; a writer
// outside the bus (a forger) still reaches them. And the lockstep's rounds
// (rig/runtime/lockstep.h): a round only where a node steps, the same rounds
// and samples with and without the bus.
#include <gtest/gtest.h>

#include <chrono>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "idl/topics.h"
#include "rig/host/domain_lease.h"
#include "rig/runtime/dds_context.h"
#include "rig/runtime/lockstep.h"

namespace {

using rig::DdsContext;
using rig::LocalBus;
using rig::msg::NmeaSentence;

constexpr std::chrono::milliseconds kBound{10'000};

// Until `ready` holds, woken by every match change of `dds` (false when the bound passes).
template <class Ready>
bool wait_matching(DdsContext& dds, Ready ready) {
    const auto deadline = std::chrono::steady_clock::now() + kBound;
    for (;;) {
        const std::uint64_t seen = dds.matching_change_count();
        if (ready()) return true;
        if (std::chrono::steady_clock::now() > deadline) return false;
        dds.wait_for_matching_change(seen, std::chrono::milliseconds(50));
    }
}

NmeaSentence sentence(const std::string& text) {
    NmeaSentence sample;
    sample.sentence(text);
    return sample;
}

std::vector<std::string> texts(const std::vector<std::pair<NmeaSentence, std::string>>& samples,
                               std::vector<std::string>* writers = nullptr) {
    std::vector<std::string> out;
    for (const auto& [sample, writer] : samples) {
        out.push_back(sample.sentence().to_string());
        if (writers != nullptr) writers->push_back(writer);
    }
    return out;
}

// A harness's context and a controller's on one domain, on one bus or not.
struct TwoContexts {
    explicit TwoContexts(bool bus)
        : harness(lease.domain_id(), "harness"), controller(lease.domain_id(), "controller") {
        if (bus) {
            harness.join_local_bus(std::make_shared<LocalBus>());
            controller.join_local_bus(harness.local_bus());
        }
    }
    rig::DomainLease lease = rig::DomainLease::acquire();
    DdsContext harness;
    DdsContext controller;
};

// Two writers (one a context each) on one topic, read in both contexts:
// what each reader holds once every sample counted has arrived.
std::vector<std::vector<std::string>> exchange(bool bus) {
    TwoContexts contexts(bus);
    rig::Writer<NmeaSentence> device(contexts.harness, "test/sentences");
    rig::Writer<NmeaSentence> controller(contexts.controller, "test/sentences");
    rig::Reader<NmeaSentence> in_controller(contexts.controller, "test/sentences");
    rig::Reader<NmeaSentence> in_harness(contexts.harness, "test/sentences");
    EXPECT_TRUE(wait_matching(contexts.harness, [&] {
        return device.matched_readers() >= 2 && controller.matched_readers() >= 2 && in_harness.matched_writers() >= 2 &&
               in_controller.matched_writers() >= 2;
    }));
    std::vector<std::vector<std::string>> seen(2);
    std::uint64_t written = 0;
    for (int round = 0; round < 3; ++round) {
        device.publish(sentence("device " + std::to_string(round) + " a"));
        device.publish(sentence("device " + std::to_string(round) + " b"));
        controller.publish(sentence("controller " + std::to_string(round)));
        written += 3;
        // Counted delivery, as the lockstep waits for it.
        EXPECT_TRUE(contexts.harness.wait_received({{"test/sentences", written}}, kBound).empty());
        EXPECT_TRUE(contexts.controller.wait_received({{"test/sentences", written}}, kBound).empty());
        for (const auto& sample : in_controller.take_all()) seen[0].push_back(sample.sentence().to_string());
        for (const auto& sample : in_harness.take_all()) seen[1].push_back(sample.sentence().to_string());
    }
    return seen;
}

TEST(LocalBus, ReadersGetWhatDdsGivesThemInTheSameOrder) {
    const auto over_dds = exchange(false);
    const auto by_hand_off = exchange(true);
    ASSERT_EQ(over_dds[0].size(), 9u);
    EXPECT_EQ(over_dds[0].front(), "device 0 a");
    EXPECT_EQ(by_hand_off, over_dds);
}

TEST(LocalBus, ASampleIsInItsReadersWhenPublishReturnsAndNamesItsWriter) {
    TwoContexts contexts(true);
    rig::Writer<NmeaSentence> writer(contexts.harness, "test/sentences");
    rig::Reader<NmeaSentence> reader(contexts.controller, "test/sentences");
    EXPECT_TRUE(reader.on_local_bus());
    EXPECT_TRUE(reader.reached_on_local_bus());
    EXPECT_FALSE(reader.has_unread());
    // No wait for discovery or delivery: the hand-off is the delivery.
    for (int i = 0; i < 3; ++i) {
        writer.publish(sentence("$GPGGA," + std::to_string(i)));
        EXPECT_TRUE(reader.has_unread());
        EXPECT_EQ(reader.received_count(), static_cast<std::uint64_t>(i + 1));
    }
    std::vector<std::string> writers;
    EXPECT_EQ(texts(reader.take_all_with_writer(), &writers),
              (std::vector<std::string>{"$GPGGA,0", "$GPGGA,1", "$GPGGA,2"}));
    EXPECT_EQ(writers, std::vector<std::string>(3, contexts.harness.guid_prefix()));
    EXPECT_FALSE(reader.has_unread());
    // The queue's slots serve the next round's samples.
    writer.publish(sentence("$GPGGA,3"));
    EXPECT_EQ(texts(reader.take_all_with_writer()), std::vector<std::string>{"$GPGGA,3"});
    EXPECT_TRUE(contexts.harness.all_readers_on_local_bus());
    EXPECT_TRUE(contexts.controller.all_readers_on_local_bus());
}

TEST(LocalBus, AnObserverOffTheBusGetsEverySampleAndTheBusReadersEachOnce) {
    TwoContexts contexts(true);
    DdsContext observer_side(contexts.lease.domain_id(), "observer");  // another process's, as far as the bus knows
    rig::Writer<NmeaSentence> writer(contexts.harness, "test/sentences");
    rig::Reader<NmeaSentence> on_bus(contexts.controller, "test/sentences");
    rig::Reader<NmeaSentence> observer(observer_side, "test/sentences");
    ASSERT_TRUE(wait_matching(contexts.harness, [&] { return writer.matched_readers() >= 2; }));
    ASSERT_TRUE(wait_matching(observer_side, [&] { return observer.matched_writers() >= 1; }));
    for (int i = 0; i < 4; ++i) writer.publish(sentence("sample " + std::to_string(i)));
    ASSERT_TRUE(observer_side.wait_received({{"test/sentences", 4}}, kBound).empty());
    std::vector<std::string> expected{"sample 0", "sample 1", "sample 2", "sample 3"};
    std::vector<std::string> writers;
    EXPECT_EQ(texts(observer.take_all_with_writer(), &writers), expected);
    EXPECT_EQ(writers, std::vector<std::string>(4, contexts.harness.guid_prefix()));
    // The DDS copies that reached the bus's reader too are dropped: each sample once.
    EXPECT_EQ(texts(on_bus.take_all_with_writer()), expected);
    EXPECT_TRUE(on_bus.take_all().empty());
    EXPECT_EQ(on_bus.received_count(), 4u);
}

TEST(LocalBus, AWriterOffTheBusStillReachesTheBusReadersWithoutMakingThemDue) {
    TwoContexts contexts(true);
    DdsContext forger_side(contexts.lease.domain_id(), "forger");
    rig::Reader<NmeaSentence> on_bus(contexts.harness, "test/sentences");
    rig::Writer<NmeaSentence> forger(forger_side, "test/sentences");
    ASSERT_TRUE(wait_matching(forger_side, [&] { return forger.matched_readers() >= 1; }));
    forger.publish(sentence("forged"));
    ASSERT_TRUE(on_bus.wait_for_data(kBound));
    // What the lockstep counts and steps nodes for is the bus's samples.
    EXPECT_FALSE(on_bus.has_unread());
    std::vector<std::string> writers;
    EXPECT_EQ(texts(on_bus.take_all_with_writer(), &writers), std::vector<std::string>{"forged"});
    EXPECT_EQ(writers, std::vector<std::string>{forger_side.guid_prefix()});
}

TEST(LocalBus, ARawReaderOnTheBusContextGetsTheSamplesOverDds) {
    // A controller's own topic the rig has no type for is recorded raw: its
    // reader is not on the bus, so the topic's writers still write over DDS.
    TwoContexts contexts(true);
    rig::Writer<NmeaSentence> writer(contexts.controller, "test/own-topic");
    rig::RawReader raw(contexts.harness, "test/own-topic", "rig::msg::NmeaSentence");
    EXPECT_FALSE(raw.on_local_bus());
    EXPECT_FALSE(contexts.harness.all_readers_on_local_bus());
    ASSERT_TRUE(wait_matching(contexts.controller, [&] { return writer.matched_readers() >= 1; }));
    writer.publish(sentence("diagnostic"));
    ASSERT_TRUE(contexts.harness.wait_received({{"test/own-topic", 1}}, kBound).empty());
    const auto samples = raw.take_all_with_writer();
    ASSERT_EQ(samples.size(), 1u);
    EXPECT_EQ(samples[0].second, contexts.controller.guid_prefix());
    EXPECT_FALSE(samples[0].first.bytes.empty());
}

TEST(LocalBus, JoiningABusAfterEndpointsWereMadeIsRefused) {
    const rig::DomainLease lease = rig::DomainLease::acquire();
    DdsContext dds(lease.domain_id(), "late");
    rig::Writer<NmeaSentence> writer(dds, "test/sentences");
    EXPECT_THROW(dds.join_local_bus(std::make_shared<LocalBus>()), std::logic_error);
}

// --- Rounds ---------------------------------------------------------------

// Publishes "sensor T" every 10 ms of simulated time.
class Sensor final : public rig::Node {
public:
    const std::string& name() const override { return name_; }
    void configure(DdsContext& dds) override { writer_ = std::make_unique<rig::Writer<NmeaSentence>>(dds, "test/sensor"); }
    rig::TimeNs step(rig::TimeNs now_ns) override {
        writer_->publish(sentence("sensor " + std::to_string(now_ns)));
        return now_ns + 10'000'000;
    }

private:
    std::string name_ = "sensor";
    std::unique_ptr<rig::Writer<NmeaSentence>> writer_;
};

// The controller: answers each sensor sample with a command; only reacts.
class Controller final : public rig::Node {
public:
    const std::string& name() const override { return name_; }
    void configure(DdsContext& dds) override {
        reader_ = std::make_unique<rig::Reader<NmeaSentence>>(dds, "test/sensor");
        writer_ = std::make_unique<rig::Writer<NmeaSentence>>(dds, "test/command");
    }
    rig::TimeNs step(rig::TimeNs) override {
        for (const auto& sample : reader_->take_all()) writer_->publish(sentence("command for " + sample.sentence().to_string()));
        return rig::kNever;
    }
    bool has_unread_input() const override { return reader_->has_unread(); }

private:
    std::string name_ = "controller";
    std::unique_ptr<rig::Reader<NmeaSentence>> reader_;
    std::unique_ptr<rig::Writer<NmeaSentence>> writer_;
};

// A local node that takes the commands (the spray circuit's part); logs them.
class Actuator final : public rig::Node {
public:
    explicit Actuator(std::vector<std::string>& log) : log_(log) {}
    const std::string& name() const override { return name_; }
    void configure(DdsContext& dds) override { reader_ = std::make_unique<rig::Reader<NmeaSentence>>(dds, "test/command"); }
    rig::TimeNs step(rig::TimeNs now_ns) override {
        for (const auto& sample : reader_->take_all()) {
            log_.push_back("actuator at " + std::to_string(now_ns) + ": " + sample.sentence().to_string());
        }
        return rig::kNever;
    }
    bool has_unread_input() const override { return reader_->has_unread(); }

private:
    std::string name_ = "actuator";
    std::vector<std::string>& log_;
    std::unique_ptr<rig::Reader<NmeaSentence>> reader_;
};

struct RoundsRun {
    std::vector<std::string> log;  // every round, and what the recorder and the actuator took
    std::uint64_t rounds = 0;
    std::uint64_t instants = 0;
};

// The sensor and (optionally) the actuator in the master, the controller in
// process on its own context, a recorder's reader of the commands drained
// after every round; on one bus or over DDS.
RoundsRun run_rounds(bool bus, bool with_actuator) {
    RoundsRun run;
    TwoContexts contexts(bus);
    Sensor sensor;
    Controller controller;
    Actuator actuator(run.log);
    rig::Reader<NmeaSentence> recorder(contexts.harness, "test/command");
    rig::LockstepMaster master(contexts.harness, rig::LockstepTimeouts{});
    master.add_local_node(sensor);
    if (with_actuator) master.add_local_node(actuator);
    master.add_in_process_node(controller, contexts.controller);
    master.set_after_round([&](rig::TimeNs t, int round) {
        ++run.rounds;
        run.log.push_back("round " + std::to_string(round) + " at " + std::to_string(t));
        for (const auto& sample : recorder.take_all()) run.log.push_back("recorded " + sample.sentence().to_string());
    });
    master.start();
    while (master.advance(50'000'000)) ++run.instants;
    master.shutdown();
    return run;
}

TEST(LockstepRounds, AnInstantWhoseAnswersNoLocalNodeReadsIsOneRound) {
    for (const bool bus : {false, true}) {
        const RoundsRun run = run_rounds(bus, /*with_actuator=*/false);
        EXPECT_EQ(run.instants, 6u) << "bus " << bus;  // 0, 10, ..., 50 ms
        // The controller's commands reach the recorder in round 0; no node
        // has anything left to do at that instant, so there is no round 1.
        EXPECT_EQ(run.rounds, run.instants) << "bus " << bus;
        ASSERT_GE(run.log.size(), 2u);
        EXPECT_EQ(run.log[0], "round 0 at 0");
        EXPECT_EQ(run.log[1], "recorded command for sensor 0");
    }
}

TEST(LockstepRounds, ALocalNodeWithInputGetsAnotherRoundAtTheSameInstant) {
    const RoundsRun over_dds = run_rounds(false, /*with_actuator=*/true);
    const RoundsRun by_hand_off = run_rounds(true, /*with_actuator=*/true);
    EXPECT_EQ(over_dds.instants, 6u);
    // Round 0: the sensor, the controller's answer; round 1: the actuator takes it. No round 2.
    EXPECT_EQ(over_dds.rounds, 2 * over_dds.instants);
    const std::vector<std::string> first_instant{"round 0 at 0", "recorded command for sensor 0",
                                                 "actuator at 0: command for sensor 0", "round 1 at 0"};
    ASSERT_GE(over_dds.log.size(), first_instant.size());
    EXPECT_EQ(std::vector<std::string>(over_dds.log.begin(), over_dds.log.begin() + 4), first_instant);
    // The same rounds, the same samples in the same order, with and without the bus.
    EXPECT_EQ(by_hand_off.log, over_dds.log);
    EXPECT_EQ(by_hand_off.rounds, over_dds.rounds);
}

}  // namespace
