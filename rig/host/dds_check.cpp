#include "rig/host/dds_check.h"

#include <algorithm>
#include <chrono>
#include <ostream>
#include <string>

#include "idl/topics.h"
#include "rig/host/child_process.h"
#include "rig/runtime/clock.h"
#include "rig/runtime/dds_context.h"
#include "rig/host/domain_lease.h"

namespace rig {
namespace {

constexpr auto kMatchTimeout = std::chrono::milliseconds(15'000);
constexpr auto kSampleTimeout = std::chrono::milliseconds(5'000);

std::string ping_text(std::uint32_t index) { return "ping " + std::to_string(index); }

// Polls (in bounded wall time) until `ready` holds; false on timeout.
template <class Ready>
bool wait_until(Ready ready, ReaderBase& reader, std::chrono::milliseconds timeout) {
    const WallStopwatch stopwatch;
    while (!ready()) {
        if (stopwatch.elapsed_s() * 1000.0 > static_cast<double>(timeout.count())) return false;
        reader.wait_for_data(std::chrono::milliseconds(20));
    }
    return true;
}

}  // namespace

int run_dds_check(const DdsCheckOptions& options, std::ostream& out) {
    const DomainLease lease = DomainLease::acquire();
    DdsContext dds(lease.domain_id(), "dds-check");
    Writer<msg::NmeaSentence> ping(dds, topics::kDdsCheckPing);
    Reader<msg::NmeaSentence> pong(dds, topics::kDdsCheckPong);

    std::filesystem::create_directories(options.log_dir);
    const auto echo_log = options.log_dir / "dds-check-echo.log";
    ChildProcess echo({options.echo_executable.string(), "dds-check", "--echo", "--domain",
                       std::to_string(lease.domain_id()), "--samples", std::to_string(options.samples)},
                      echo_log);
    out << "dds-check: domain " << lease.domain_id() << ", echo process " << echo.pid() << " (log " << echo_log.string()
        << ")\n";

    const WallStopwatch total;
    if (!wait_until([&] { return ping.matched_readers() > 0 && pong.matched_writers() > 0; }, pong, kMatchTimeout)) {
        out << "dds-check: FAILED: the echo process was not discovered within " << kMatchTimeout.count()
            << " ms (" << echo.exit_description().value_or("still running") << ")\n";
        echo.stop(std::chrono::milliseconds(500));
        return 1;
    }
    out << "dds-check: matched after " << static_cast<int>(total.elapsed_s() * 1000.0) << " ms\n";

    double worst_round_trip_ms = 0.0;
    for (std::uint32_t index = 0; index < options.samples; ++index) {
        msg::NmeaSentence sample;
        sample.sentence(ping_text(index));
        const WallStopwatch round_trip;
        ping.publish(sample);
        std::vector<msg::NmeaSentence> answers;
        if (!wait_until(
                [&] {
                    for (auto& answer : pong.take_all()) answers.push_back(answer);
                    return !answers.empty();
                },
                pong, kSampleTimeout)) {
            out << "dds-check: FAILED: no answer to \"" << ping_text(index) << "\" within " << kSampleTimeout.count()
                << " ms\n";
            echo.stop(std::chrono::milliseconds(500));
            return 1;
        }
        const std::string expected = "pong " + std::to_string(index);
        if (answers.size() != 1 || answers.front().sentence().to_string() != expected) {
            out << "dds-check: FAILED: expected \"" << expected << "\", got \""
                << answers.front().sentence().to_string() << "\" (" << answers.size() << " samples)\n";
            echo.stop(std::chrono::milliseconds(500));
            return 1;
        }
        worst_round_trip_ms = std::max(worst_round_trip_ms, round_trip.elapsed_s() * 1000.0);
    }
    const std::string ended = echo.stop();
    out << "dds-check: " << options.samples << "/" << options.samples << " round trips, worst "
        << worst_round_trip_ms << " ms; echo " << ended << "\n";
    return ended == "process exited with status 0" ? 0 : 1;
}

int run_dds_echo(std::uint32_t domain_id, std::uint32_t samples, std::ostream& out) {
    DdsContext dds(domain_id, "dds-check-echo");
    Reader<msg::NmeaSentence> ping(dds, topics::kDdsCheckPing);
    Writer<msg::NmeaSentence> pong(dds, topics::kDdsCheckPong);
    std::uint32_t answered = 0;
    while (answered < samples) {
        std::vector<msg::NmeaSentence> pings;
        if (!wait_until(
                [&] {
                    pings = ping.take_all();
                    return !pings.empty();
                },
                ping, kMatchTimeout)) {
            out << "dds-check echo: no ping for " << kMatchTimeout.count() << " ms after " << answered
                << " answers; giving up\n";
            return 1;
        }
        for (const auto& sample : pings) {
            const std::string text = sample.sentence().to_string();
            msg::NmeaSentence answer;
            answer.sentence("pong " + text.substr(text.find(' ') + 1));
            pong.publish(answer);
            ++answered;
        }
    }
    // Let the last answer be acknowledged before the participant goes away.
    const auto undelivered = dds.wait_all_delivered(std::chrono::milliseconds(5'000));
    out << "dds-check echo: answered " << answered << " pings" << (undelivered.empty() ? "" : " (last not acknowledged)")
        << "\n";
    return undelivered.empty() ? 0 : 1;
}

}  // namespace rig
