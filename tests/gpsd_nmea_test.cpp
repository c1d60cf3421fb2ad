// A real NMEA client no one here wrote (Debian's gpsd) reads the stream the rig
// writes into a pty and reports the positions that were written.
//
// GGA + RMC epochs from rig/nmea/nmea_encoder.h, RTK fixed (quality 4), 5 Hz,
// along a short straight line near 40.18 N 116.44 E, go through
// NmeaSerialSink into a PtyPair whose slave gpsd reads (`gpsd -N -n -b`, on a
// free port on 127.0.0.1). A TCP client on 127.0.0.1 asks for JSON reports
// (?WATCH) and every TPV must carry the latitude and longitude (within 1e-7
// deg) and the time of an epoch that was written, in mode 2 or 3.
//
// The test waits for real time (it is not a rig node) but asserts nothing
// about timing: bounds are generous so a loaded 2-core machine cannot fail it.
#include <gtest/gtest.h>

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <signal.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <optional>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "rig/nmea/nmea_encoder.h"
#include "emulators/nmea_serial_sink.h"
#include "rig/host/child_process.h"
#include "rig/runtime/clock.h"
#include "rig/wire/pty_pair.h"
#include "tool_support.h"

namespace rig {
namespace {

namespace fs = std::filesystem;
using std::chrono::milliseconds;

constexpr int kEpochs = 25;
constexpr double kRateHz = 5.0;
constexpr double kSpeedMs = 6.0 / 3.6;  // 6 km/h, the paper's fastest run
constexpr double kHeadingDeg = 60.0;
constexpr double kStartLatDeg = 40.18;
constexpr double kStartLonDeg = 116.44;
constexpr double kMetresPerDegreeLat = 111'320.0;
constexpr double kStartSecondsOfDay = 2 * 3600.0;  // 02:00:00 UTC
constexpr double kPositionToleranceDeg = 1e-7;
constexpr auto kConnectTimeout = milliseconds(30'000);
constexpr auto kReportTimeout = milliseconds(30'000);  // after the last epoch

nmea::GnssFix epoch_fix(int index) {
    const double t = index / kRateHz;
    const double along_m = kSpeedMs * t;
    const double heading = kHeadingDeg * M_PI / 180.0;
    nmea::GnssFix fix;
    fix.year = 2023;
    fix.month = 7;
    fix.day = 15;
    fix.utc_seconds_of_day = kStartSecondsOfDay + t;
    fix.lat_deg = kStartLatDeg + along_m * std::cos(heading) / kMetresPerDegreeLat;
    fix.lon_deg = kStartLonDeg + along_m * std::sin(heading) /
                                     (kMetresPerDegreeLat * std::cos(kStartLatDeg * M_PI / 180.0));
    fix.altitude_msl_m = 48.5;
    fix.geoid_separation_m = -8.2;
    fix.fix_quality = 4;  // RTK fixed
    fix.satellites = 16;
    fix.hdop = 0.7;
    fix.speed_m_s = kSpeedMs;
    fix.course_deg = kHeadingDeg;
    fix.differential_age_s = 1.0;
    fix.station_id = 1;
    return fix;
}

// gpsd prints TPV time as ISO 8601 with milliseconds: 2023-07-15T02:00:00.200Z.
std::string iso_time(const nmea::GnssFix& fix) {
    const auto centiseconds = static_cast<long>(std::lround(fix.utc_seconds_of_day * 100.0));
    char text[80];
    std::snprintf(text, sizeof text, "%04d-%02d-%02dT%02ld:%02ld:%02ld.%03ldZ", fix.year, fix.month, fix.day,
                  centiseconds / 360000, centiseconds / 6000 % 60, centiseconds / 100 % 60, centiseconds % 100 * 10);
    return text;
}

int free_loopback_port() {
    const int probe = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
    sockaddr_in address{};
    address.sin_family = AF_INET;
    address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    address.sin_port = 0;
    socklen_t length = sizeof address;
    if (::bind(probe, reinterpret_cast<sockaddr*>(&address), sizeof address) != 0 ||
        ::getsockname(probe, reinterpret_cast<sockaddr*>(&address), &length) != 0) {
        ::close(probe);
        return -1;
    }
    ::close(probe);
    return ntohs(address.sin_port);
}

// Connects to 127.0.0.1:port, retrying while gpsd starts up.
int connect_loopback(int port) {
    const WallStopwatch waited;
    while (waited.elapsed() < kConnectTimeout) {
        const int fd = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
        sockaddr_in address{};
        address.sin_family = AF_INET;
        address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
        address.sin_port = htons(static_cast<std::uint16_t>(port));
        if (::connect(fd, reinterpret_cast<sockaddr*>(&address), sizeof address) == 0) return fd;
        ::close(fd);
        std::this_thread::sleep_for(milliseconds(100));
    }
    return -1;
}

// Line-oriented reading from gpsd's socket with a timeout.
class JsonLines {
public:
    explicit JsonLines(int fd) : fd_(fd) {}
    // Appends the complete lines that arrive within `timeout`.
    void poll_lines(milliseconds timeout, std::vector<nlohmann::json>& out) {
        pollfd watch{fd_, POLLIN, 0};
        if (::poll(&watch, 1, static_cast<int>(timeout.count())) <= 0) return;
        char buffer[8192];
        const ssize_t n = ::read(fd_, buffer, sizeof buffer);
        if (n <= 0) {
            closed_ = true;
            return;
        }
        pending_.append(buffer, static_cast<std::size_t>(n));
        for (auto newline = pending_.find('\n'); newline != std::string::npos; newline = pending_.find('\n')) {
            auto report = nlohmann::json::parse(pending_.substr(0, newline), nullptr, false);
            pending_.erase(0, newline + 1);
            if (!report.is_discarded()) out.push_back(std::move(report));
        }
    }
    bool closed() const { return closed_; }

private:
    int fd_;
    std::string pending_;
    bool closed_ = false;
};

std::string read_file(const fs::path& path) {
    std::ifstream in(path);
    std::stringstream text;
    text << in.rdbuf();
    return text.str();
}

TEST(GpsdReadsRigNmea, TpvReportsCarryTheWrittenPositionsAndTimes) {
    ASSERT_TRUE(rig::testing::tool_installed("gpsd", "gpsd"));
    const std::string gpsd_program = rig::testing::installed_program("gpsd");

    const fs::path dir = fs::path(::testing::TempDir()) / "gpsd-nmea";
    fs::remove_all(dir);
    fs::create_directories(dir);
    PtyPair pty(PtyOptions{SerialSettings{115200, 8, Parity::none, 1}, dir / "gnss0"});
    emulators::NmeaSerialSink sink(pty.master());

    const int port = free_loopback_port();
    ASSERT_GT(port, 0) << "no free TCP port on 127.0.0.1";
    const fs::path gpsd_log = dir / "gpsd.log";
    ChildProcess gpsd({gpsd_program, "-N", "-n", "-b", "-S", std::to_string(port), "-F",
                       (dir / "gpsd.sock").string(), pty.public_path()},
                      gpsd_log);

    const int client = connect_loopback(port);
    ASSERT_GE(client, 0) << "gpsd did not listen on 127.0.0.1:" << port << "; log:\n" << read_file(gpsd_log);
    const std::string watch = "?WATCH={\"enable\":true,\"json\":true}\n";
    ASSERT_EQ(::write(client, watch.data(), watch.size()), static_cast<ssize_t>(watch.size()));

    // Start the stream once gpsd has answered the WATCH (reports are not kept
    // for clients that are not watching yet).
    std::vector<nlohmann::json> reports;
    JsonLines lines(client);
    const WallStopwatch handshake;
    const auto watching = [&] {
        for (const auto& report : reports) {
            if (report.value("class", "") == "WATCH") return true;
        }
        return false;
    };
    while (!watching() && !lines.closed() && handshake.elapsed() < kConnectTimeout) {
        lines.poll_lines(milliseconds(200), reports);
    }
    ASSERT_TRUE(watching()) << "gpsd never answered ?WATCH; log:\n" << read_file(gpsd_log);

    // The receiver's 5 Hz: an absolute-deadline loop, as the rig's real-time loop paces the sink.
    std::map<std::string, nmea::GnssFix> written_by_time;
    const RealtimeClock clock;
    const TimeNs period_ns = seconds_to_ns(1.0 / kRateHz);
    for (int index = 0; index < kEpochs; ++index) {
        const nmea::GnssFix fix = epoch_fix(index);
        const std::vector<std::string> epoch{nmea::encode_gga("GP", fix), nmea::encode_rmc("GP", fix)};
        sink.write_epoch(epoch);
        written_by_time[iso_time(fix)] = fix;
        const TimeNs next_ns = (index + 1) * period_ns;
        while (clock.now_ns() < next_ns) {
            lines.poll_lines(milliseconds(std::max<TimeNs>(1, (next_ns - clock.now_ns()) / 1'000'000)), reports);
        }
    }

    // Collect until every written epoch has been reported, or gpsd has been
    // quiet for a while (it may report an epoch only when the next cycle
    // begins, so the last one can stay unsaid), within a generous bound.
    std::map<std::string, nlohmann::json> tpv_by_time;
    const auto collect = [&] {
        for (const auto& report : reports) {
            if (report.value("class", "") == "TPV" && report.contains("time")) {
                tpv_by_time[report["time"].get<std::string>()] = report;
            }
        }
    };
    const WallStopwatch draining;
    std::optional<WallStopwatch> quiet(std::in_place);
    collect();
    while (tpv_by_time.size() < written_by_time.size() && !lines.closed() && draining.elapsed() < kReportTimeout &&
           quiet->elapsed() < milliseconds(3000)) {
        const std::size_t before = reports.size();
        lines.poll_lines(milliseconds(500), reports);
        if (reports.size() != before) quiet.emplace();
        collect();
    }
    ::close(client);
    ::kill(gpsd.pid(), SIGTERM);
    gpsd.stop(milliseconds(5000));

    // Every TPV with a time belongs to an epoch that was written, with its position.
    int matched = 0;
    for (const auto& [time, tpv] : tpv_by_time) {
        const auto written = written_by_time.find(time);
        ASSERT_NE(written, written_by_time.end()) << "gpsd reported a time that was never written: " << tpv.dump();
        ASSERT_TRUE(tpv.contains("lat") && tpv.contains("lon")) << tpv.dump();
        EXPECT_NEAR(tpv["lat"].get<double>(), written->second.lat_deg, kPositionToleranceDeg) << tpv.dump();
        EXPECT_NEAR(tpv["lon"].get<double>(), written->second.lon_deg, kPositionToleranceDeg) << tpv.dump();
        const int mode = tpv.value("mode", 0);
        EXPECT_TRUE(mode == 2 || mode == 3) << tpv.dump();
        ++matched;
    }
    std::cout << "gpsd reported " << matched << " of " << kEpochs << " epochs written\n";
    // gpsd may spend the first epochs recognising the stream and report the
    // last one only when another cycle begins; the rest must all be there.
    EXPECT_GE(matched, kEpochs - 6) << "only " << matched << " of " << kEpochs
                                    << " epochs reported; gpsd log:\n"
                                    << read_file(gpsd_log);
    EXPECT_EQ(sink.sentences_written(), 2u * kEpochs);
}

}  // namespace
}  // namespace rig
