// rig::DdsContext with a node that outlives it: a controller whose main()
// declares its node before its context destroys the context first. The
// node's readers and writers must then neither touch the freed context nor
// leak DDS entities (the SDK example and the boundary controller once did the
// former; ASan saw it). Runs under ASan in CI like every test.
//
// And a writer whose reader died with samples unacknowledged: deleting it must
// return. Fast DDS 2.9's StatefulWriter destructor frees the history's changes
// one by one while its periodic heartbeat may still walk that history; a freed
// change's sequence number sends add_gaps_for_holes_in_history_ counting towards
// 2^64 with the writer's mutex held, and the destructor waits on that mutex for
// ever (seen as a hung `rig run` after a controller crashed mid-case).
//
// And the start-up's waits and the reliability timers: matches and unmatches
// wake wait_for_matching_change on both sides; each context's endpoints get
// its ReliabilityTimers, and a camera frame's get prompt repair.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fcntl.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <future>
#include <memory>
#include <string>
#include <vector>

#include "idl/topics.h"
#include "rig/host/domain_lease.h"
#include "rig/runtime/dds_context.h"
#include "rig/runtime/realtime.h"
#include "run_support.h"

namespace {

TEST(DdsContext, EndpointsOutlivingTheirContextAreDetachedNotDangling) {
    const rig::DomainLease lease = rig::DomainLease::acquire();
    auto dds = std::make_unique<rig::DdsContext>(lease.domain_id(), "outlived");
    auto writer = std::make_unique<rig::Writer<rig::msg::NmeaSentence>>(*dds, rig::topics::kDdsCheckPing);
    auto reader = std::make_unique<rig::Reader<rig::msg::NmeaSentence>>(*dds, rig::topics::kDdsCheckPing);
    EXPECT_EQ(dds->writers().size(), 1u);
    EXPECT_EQ(dds->readers().size(), 1u);

    dds.reset();  // the context goes first

    rig::msg::NmeaSentence sample;
    sample.sentence("$GPGGA");
    // Writing through a detached writer is an error the caller sees, not a crash.
    EXPECT_THROW(writer->publish(sample), std::runtime_error);
    EXPECT_FALSE(writer->wait_delivered(std::chrono::milliseconds(1)));
    EXPECT_FALSE(reader->has_unread());
    EXPECT_TRUE(reader->take_all().empty());
    EXPECT_FALSE(reader->wait_for_data(std::chrono::milliseconds(1)));
    writer.reset();
    reader.reset();
}

// Start-up waits for matches on wait_for_matching_change (rig/runtime/lockstep.cpp):
// each match and unmatch of a writer or reader must wake it, in the context of
// the endpoint whose count changed. Without the wake-up every wait below runs
// out its 10 s and returns false, and no change is counted.
TEST(DdsContext, MatchingChangesWakeTheWaiterOnBothSides) {
    const rig::DomainLease lease = rig::DomainLease::acquire();
    rig::DdsContext writer_side(lease.domain_id(), "matching-writer");
    rig::DdsContext reader_side(lease.domain_id(), "matching-reader");
    rig::Writer<rig::msg::NmeaSentence> writer(writer_side, rig::topics::kDdsCheckPing);
    const std::uint64_t writer_seen = writer_side.matching_change_count();
    const std::uint64_t reader_seen = reader_side.matching_change_count();
    auto reader = std::make_unique<rig::Reader<rig::msg::NmeaSentence>>(reader_side, rig::topics::kDdsCheckPing);

    const auto wait_until = [](rig::DdsContext& dds, std::uint64_t seen, const std::function<bool()>& done) {
        while (!done()) {
            if (!dds.wait_for_matching_change(seen, std::chrono::seconds(10))) return false;
            seen = dds.matching_change_count();
        }
        return true;
    };
    EXPECT_TRUE(wait_until(reader_side, reader_seen, [&] { return reader->matched_writers() == 1; }));
    EXPECT_TRUE(wait_until(writer_side, writer_seen, [&] { return writer.matched_readers() == 1; }));
    // Counted even when the match came before the wait began.
    EXPECT_GT(reader_side.matching_change_count(), reader_seen);
    EXPECT_GT(writer_side.matching_change_count(), writer_seen);

    const std::uint64_t before_unmatch = writer_side.matching_change_count();
    reader.reset();
    EXPECT_TRUE(wait_until(writer_side, before_unmatch, [&] { return writer.matched_readers() == 0; }));
    EXPECT_GT(writer_side.matching_change_count(), before_unmatch);
}

// The reliability timers follow the context (rig/runtime/dds_context.h):
// lockstep's few wake-ups, real time's prompt repair, and prompt repair for a
// large type (a camera frame) whatever the context says.
TEST(DdsContext, ReliabilityTimersFollowTheContextAndLargeTypesRepairPromptly) {
    const rig::DomainLease lease = rig::DomainLease::acquire();
    rig::DdsContext lockstep(lease.domain_id(), "timers-lockstep");
    rig::DdsContext realtime(lease.domain_id(), "timers-realtime", /*watch_discovery=*/false,
                             rig::ReliabilityTimers::prompt_repair);
    EXPECT_EQ(lockstep.reliability_timers(), rig::ReliabilityTimers::few_wakeups);
    rig::Writer<rig::msg::NmeaSentence> lockstep_writer(lockstep, rig::topics::kDdsCheckPing);
    rig::Reader<rig::msg::NmeaSentence> lockstep_reader(lockstep, rig::topics::kDdsCheckPing);
    rig::Writer<rig::msg::CameraFrame> frame_writer(lockstep, rig::topics::kCameraLeftFrame);
    rig::Writer<rig::msg::NmeaSentence> realtime_writer(realtime, rig::topics::kDdsCheckPing);
    rig::Reader<rig::msg::NmeaSentence> realtime_reader(realtime, rig::topics::kDdsCheckPing);

    const auto writer_times = [](rig::DdsContext& dds, const std::string& topic) {
        std::vector<eprosima::fastdds::dds::DataWriter*> writers;
        dds.publisher().get_datawriters(writers);
        for (auto* writer : writers) {
            if (writer->get_topic()->get_name() == topic) return writer->get_qos().reliable_writer_qos().times;
        }
        ADD_FAILURE() << "no writer on " << topic;
        return eprosima::fastrtps::rtps::WriterTimes{};
    };
    const auto response_delay = [](rig::DdsContext& dds) {
        std::vector<eprosima::fastdds::dds::DataReader*> readers;
        dds.subscriber().get_datareaders(readers);
        EXPECT_EQ(readers.size(), 1u);
        return readers.empty() ? eprosima::fastrtps::Duration_t() :
                                 readers.front()->get_qos().reliable_reader_qos().times.heartbeatResponseDelay;
    };
    using eprosima::fastrtps::Duration_t;
    const auto few = writer_times(lockstep, rig::topics::kDdsCheckPing);
    EXPECT_EQ(few.heartbeatPeriod, Duration_t(0, 10'000'000));
    EXPECT_EQ(few.nackSupressionDuration, Duration_t(0, 5'000'000));
    EXPECT_EQ(response_delay(lockstep), Duration_t(0, 2'000'000));
    for (const auto& prompt : {writer_times(realtime, rig::topics::kDdsCheckPing),
                               writer_times(lockstep, rig::topics::kCameraLeftFrame)}) {
        EXPECT_EQ(prompt.heartbeatPeriod, Duration_t(0, 200'000));
        EXPECT_EQ(prompt.nackSupressionDuration, Duration_t(0, 0));
    }
    EXPECT_EQ(response_delay(realtime), Duration_t(0, 0));
}

TEST(DdsContext, EndpointsDestroyedFirstLeaveTheRegistry) {
    const rig::DomainLease lease = rig::DomainLease::acquire();
    rig::DdsContext dds(lease.domain_id(), "ordinary");
    {
        rig::Writer<rig::msg::NmeaSentence> writer(dds, rig::topics::kDdsCheckPing);
        rig::Reader<rig::msg::NmeaSentence> reader(dds, rig::topics::kDdsCheckPing);
        EXPECT_EQ(dds.writers().size(), 1u);
        EXPECT_EQ(dds.readers().size(), 1u);
    }
    EXPECT_TRUE(dds.writers().empty());
    EXPECT_TRUE(dds.readers().empty());
}

// The reference controller as a reader of the wheel encoder: it makes its
// participant and endpoints, then waits for a master that never comes.
pid_t spawn_encoder_reader(const std::filesystem::path& dir, int domain_id) {
    std::ofstream(dir / "controller.yaml") << "positioning: fusion\n";
    std::filesystem::create_directories(dir / "state");
    const std::string log_path = (dir / "controller.log").string();
    const std::string config_path = (dir / "controller.yaml").string();
    const std::string state_path = (dir / "state").string();
    const std::string domain = std::to_string(domain_id);
    const pid_t pid = ::fork();
    if (pid == 0) {
        const int log = ::open(log_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
        ::dup2(log, 1);
        ::dup2(log, 2);
        ::execl(RIG_BINARY_DIR "/bin/rig-controller", "rig-controller", "--domain", domain.c_str(), "--config",
                config_path.c_str(), "--state-dir", state_path.c_str(), nullptr);
        ::_exit(127);
    }
    return pid;
}

TEST(DdsContext, DeletingAWriterWhoseReaderDiedWithSamplesUnacknowledgedReturns) {
    const std::filesystem::path dir = rig::testing::fresh_dir("dds-context-dead-reader");
    const rig::DomainLease lease = rig::DomainLease::acquire();
    auto dds = std::make_unique<rig::DdsContext>(lease.domain_id(), "writer-of-a-dead-reader");
    const pid_t reader = spawn_encoder_reader(dir, lease.domain_id());
    ASSERT_GT(reader, 0);
    rig::RealtimeClock clock;
    // Several writers, each deleted with a full history: the race with the
    // heartbeat (every 0.2 ms while anything is unacknowledged) is lost on
    // almost every deletion without the fix.
    constexpr int kWriters = 8;
    std::vector<std::unique_ptr<rig::Writer<rig::msg::EncoderCount>>> writers;
    for (int i = 0; i < kWriters; ++i) {
        writers.push_back(std::make_unique<rig::Writer<rig::msg::EncoderCount>>(*dds, rig::topics::kWheelEncoder));
    }
    // Bounded by the controller's start-up, not a speed assertion.
    for (int i = 0; i < 6000; ++i) {
        bool all_matched = true;
        for (const auto& writer : writers) all_matched = all_matched && writer->matched_readers() >= 1;
        if (all_matched) break;
        clock.sleep_until_ns(clock.now_ns() + rig::seconds_to_ns(0.01));
    }
    for (const auto& writer : writers) {
        ASSERT_GE(writer->matched_readers(), 1) << rig::testing::read_all(dir / "controller.log");
    }
    ::kill(reader, SIGKILL);
    ::waitpid(reader, nullptr, 0);

    rig::msg::EncoderCount sample;
    for (auto& writer : writers) {
        for (int n = 0; n < 2000; ++n) {
            sample.count_pulses(static_cast<std::uint32_t>(n));
            writer->publish(sample);
        }
    }
    // The reader's participant is still matched (its lease has not run out), so
    // all of it stays unacknowledged in each writer's history. Half the writers
    // go by their own destructor, the other half with their context.
    auto deleted = std::async(std::launch::async, [&writers, &dds] {
        writers.resize(kWriters / 2);
        dds.reset();
        writers.clear();
    });
    if (deleted.wait_for(std::chrono::seconds(120)) != std::future_status::ready) {
        // The deleting thread is stuck inside Fast DDS and cannot be joined.
        std::fprintf(stderr, "deleting writers whose reader died did not return in 120 s\n");
        std::_Exit(1);
    }
}

}  // namespace
