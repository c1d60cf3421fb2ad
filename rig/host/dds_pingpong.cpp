#include "rig/host/dds_pingpong.h"

#include <algorithm>
#include <chrono>
#include <iostream>
#include <numeric>
#include <stdexcept>
#include <vector>

#include "idl/topics.h"
#include "rig/host/child_process.h"
#include "rig/host/domain_lease.h"
#include "rig/runtime/clock.h"
#include "rig/runtime/dds_context.h"

namespace rig {
namespace {

constexpr auto kMatchTimeout = std::chrono::milliseconds(15'000);
constexpr auto kAnswerTimeout = std::chrono::milliseconds(5'000);
// The second process's wait for its last answers to be acknowledged before it
// exits (reliable delivery can take a heartbeat period or two on a loaded
// machine), and the first process's patience with that exit: longer than the
// wait, so that a slow acknowledgement is never a killed second process.
constexpr auto kPongDeliveryWait = std::chrono::milliseconds(5'000);
constexpr auto kPongExitGrace = 3 * kPongDeliveryWait;
// The first ping is sent again at this period until answered: matched from the
// writer's side is not yet matched from the reader's (as the lockstep hello is
// repeated, docs/controller-contract.md section 7), and a slow second process
// (a sanitizer build on a loaded machine) may take seconds to get there.
constexpr auto kFirstPingRepeat = std::chrono::milliseconds(200);

double percentile(std::vector<double> values, double fraction) {
    if (values.empty()) return 0.0;
    std::sort(values.begin(), values.end());
    const auto index = static_cast<std::size_t>(fraction * static_cast<double>(values.size() - 1) + 0.5);
    return values[std::min(index, values.size() - 1)];
}

}  // namespace

PingPongResult run_dds_pingpong(const PingPongOptions& options) {
    const DomainLease lease = DomainLease::acquire();
    DdsContext dds(lease.domain_id(), "bench-ping");
    // As the lockstep master's clock endpoints: writers that are not output.
    Writer<msg::ClockTick> ping(dds, topics::kBenchPing, /*counts_as_output=*/false);
    Reader<msg::ClockAck> pong(dds, topics::kBenchPong);

    std::filesystem::create_directories(options.log_dir);
    const std::uint32_t total = options.warmup_rounds + options.rounds;
    ChildProcess echo({options.pong_executable.string(), "bench", "--pong", "--domain", std::to_string(lease.domain_id()),
                       "--pingpong-rounds", std::to_string(total)},
                      options.log_dir / "bench-pong.log", options.pong_environment);
    auto fail = [&](const std::string& what) -> PingPongResult {
        const std::string ended = echo.stop(std::chrono::milliseconds(500));
        throw std::runtime_error("DDS ping-pong: " + what + " (second process: " + ended + ")");
    };

    PingPongResult result;
    const WallStopwatch since_start;
    for (;;) {
        const std::uint64_t seen = dds.matching_change_count();
        if (ping.matched_readers() >= 1 && pong.matched_writers() >= 1) break;
        if (since_start.elapsed() > kMatchTimeout) return fail("the second process was not matched within 15 s");
        if (auto gone = echo.exit_description()) return fail("it ended before matching");
        dds.wait_for_matching_change(seen, std::chrono::milliseconds(50));
    }
    result.matched_after_s = since_start.elapsed_s();

    msg::ClockTick tick;
    tick.reader_counts().clear();
    for (std::uint32_t i = 0; i < options.topics_in_tick; ++i) {
        msg::TopicCount count;
        count.topic("device/bench/topic_" + std::to_string(i));
        count.samples(i);
        tick.published_counts().push_back(count);
    }
    std::vector<double> round_trips_us;
    round_trips_us.reserve(options.rounds);
    for (std::uint32_t seq = 1; seq <= total; ++seq) {
        tick.seq(seq);
        tick.time_ns(static_cast<TimeNs>(seq) * 10'000'000);
        const WallStopwatch round_trip;
        ping.publish(tick);
        bool answered = false;
        const WallStopwatch waiting;
        while (!answered) {
            if (seq == 1) {
                if (waiting.elapsed() > kMatchTimeout) return fail("no answer to the first ping within 15 s");
                if (!pong.wait_for_data(kFirstPingRepeat)) {
                    ping.publish(tick);
                    continue;
                }
            } else if (!pong.wait_for_data(kAnswerTimeout)) {
                return fail("no answer to ping " + std::to_string(seq) + " within 5 s");
            }
            for (const msg::ClockAck& ack : pong.take_all()) answered |= ack.seq() == seq;
        }
        if (seq > options.warmup_rounds) round_trips_us.push_back(round_trip.elapsed_s() * 1e6);
    }
    const std::string ended = echo.stop(kPongExitGrace);
    if (ended != "process exited with status 0") throw std::runtime_error("DDS ping-pong: the second process " + ended);
    result.rounds = options.rounds;
    result.mean_us = std::accumulate(round_trips_us.begin(), round_trips_us.end(), 0.0) /
                     static_cast<double>(std::max<std::size_t>(1, round_trips_us.size()));
    result.p50_us = percentile(round_trips_us, 0.50);
    result.p99_us = percentile(round_trips_us, 0.99);
    return result;
}

int run_dds_pong(std::uint32_t domain_id, std::uint32_t rounds) {
    DdsContext dds(domain_id, "bench-pong");
    Reader<msg::ClockTick> ping(dds, topics::kBenchPing);
    Writer<msg::ClockAck> pong(dds, topics::kBenchPong, /*counts_as_output=*/false);
    msg::ClockAck ack;
    ack.node_name("bench-pong");
    // Every ping is answered, a repeated first one too; the rounds count by sequence number.
    std::uint64_t last_seq = 0;
    while (last_seq < rounds) {
        if (!ping.wait_for_data(kMatchTimeout)) {
            std::cerr << "bench pong: no ping for 15 s after ping " << last_seq << "; giving up\n";
            return 1;
        }
        for (const msg::ClockTick& tick : ping.take_all()) {
            ack.seq(tick.seq());
            ack.next_wake_ns(tick.time_ns() + 10'000'000);
            pong.publish(ack);
            last_seq = std::max<std::uint64_t>(last_seq, tick.seq());
        }
    }
    const auto undelivered = dds.wait_all_delivered(kPongDeliveryWait);
    return undelivered.empty() ? 0 : 1;
}

}  // namespace rig
