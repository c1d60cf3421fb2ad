// The AD300 RTK receiver emulator (emulators/ad300_receiver.h): GPRMC at 10 Hz
// (seed 001 Sec. 4.2.2), read back with the controller's own NMEA parser.
#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <stdexcept>
#include <string>
#include <variant>
#include <vector>

#include "rig/nmea/nmea_parser.h"
#include "emulators/ad300_receiver.h"
#include "emulators/field2d/sprayer_kinematics.h"

namespace {

using namespace rig::field2d;
using rig::seconds_to_ns;
using rig::emulators::Ad300Params;
using rig::emulators::Ad300Receiver;
using rig::emulators::TimedLine;

constexpr double kWuzhiLat = 35.1;
constexpr double kWuzhiLon = 113.3;

// Straight north from the origin at `speed` (already moving at t = 0) for `seconds`.
SprayerKinematics north_at(double speed_m_s, double seconds) {
    const double run_m = speed_m_s * seconds;
    return SprayerKinematics(LocalFrame(kWuzhiLat, kWuzhiLon, 80.0),
                             Route2d({{0, 0}, 0.0, speed_m_s},
                                     {StraightSegment{run_m, speed_m_s, 0.5},
                                      StraightSegment{speed_m_s * speed_m_s, speed_m_s, 0.5, true}}),
                             SprayerMounting{}, BoomHeightProfile{});
}

rig::nmea::RmcData parse_rmc(const std::string& line) {
    const rig::nmea::ParseResult r = rig::nmea::parse_sentence(line);
    EXPECT_TRUE(r.ok()) << line;
    if (!r.ok()) return {};
    EXPECT_EQ(r.sentence->talker, "GP");
    EXPECT_EQ(r.sentence->type, "RMC");
    return std::get<rig::nmea::RmcData>(r.sentence->data);
}

TEST(Ad300Receiver, TenHertzWithLatencyAfterEachEpoch) {
    const SprayerKinematics k = north_at(1.0, 10.0);
    Ad300Params p;
    p.epoch_phase_s = 0.03;
    p.latency_s = 0.05;
    Ad300Receiver rx(k, p);
    // Epochs at 0.03 + 0.1 k; on the wire 50 ms later: by 1.0 s the epochs
    // 0.03 ... 0.93 (on the wire at 0.98), ten sentences.
    const std::vector<TimedLine> lines = rx.poll(seconds_to_ns(1.0));
    ASSERT_EQ(lines.size(), 10u);
    for (std::size_t i = 0; i < lines.size(); ++i) {
        EXPECT_EQ(lines[i].at_ns, seconds_to_ns(0.08) + static_cast<rig::TimeNs>(i) * 100'000'000);
    }
    EXPECT_EQ(rx.next_due_ns(), seconds_to_ns(1.08));
    EXPECT_TRUE(rx.poll(seconds_to_ns(1.0)).empty());
}

TEST(Ad300Receiver, EpochPhaseComesFromTheSeed) {
    const SprayerKinematics k = north_at(1.0, 10.0);
    std::set<double> phases;
    for (std::uint64_t seed = 1; seed <= 20; ++seed) {
        Ad300Params p;
        p.seed = seed;
        const Ad300Receiver a(k, p);
        const Ad300Receiver b(k, p);
        EXPECT_EQ(a.epoch_phase_s(), b.epoch_phase_s());
        EXPECT_GE(a.epoch_phase_s(), 0.0);
        EXPECT_LT(a.epoch_phase_s(), 0.1);
        phases.insert(a.epoch_phase_s());
    }
    EXPECT_EQ(phases.size(), 20u);
}

TEST(Ad300Receiver, PositionSpeedAndCourseReadBack) {
    // 1.5 m/s north; sigma = 1 cm + 1 ppm x 2 km = 1.2 cm per axis.
    const SprayerKinematics k = north_at(1.5, 30.0);
    Ad300Params p;
    p.seed = 7;
    Ad300Receiver rx(k, p);
    const std::vector<TimedLine> lines = rx.poll(seconds_to_ns(25.0));
    ASSERT_GE(lines.size(), 240u);
    double sum_e = 0.0;
    double sum_n = 0.0;
    double sum_e2 = 0.0;
    double sum_n2 = 0.0;
    double max_course_error = 0.0;
    for (std::size_t i = 0; i < lines.size(); ++i) {
        const rig::nmea::RmcData rmc = parse_rmc(lines[i].text);
        ASSERT_TRUE(rmc.position && rmc.speed_knots && rmc.course_true_deg);
        EXPECT_EQ(rmc.status, rig::nmea::DataStatus::valid);
        EXPECT_EQ(rmc.mode, 'R');  // RTK fixed
        const double epoch_s = rig::ns_to_seconds(rx.epoch_ns(static_cast<std::int64_t>(i)));
        const SprayerTruth truth = k.truth_at(epoch_s);
        const Vec2 measured = k.frame().to_local(rmc.position->lat_deg, rmc.position->lon_deg);
        const double de = measured.east_m - truth.antenna.east_m;
        const double dn = measured.north_m - truth.antenna.north_m;
        sum_e += de;
        sum_n += dn;
        sum_e2 += de * de;
        sum_n2 += dn * dn;
        // 1.5 m/s = 2.916 kn; velocity noise 2 cm/s per axis is 0.04 kn.
        EXPECT_NEAR(*rmc.speed_knots, 1.5 * 3600.0 / 1852.0, 0.25);
        const double course_error = std::remainder(*rmc.course_true_deg - 0.0, 360.0);
        max_course_error = std::max(max_course_error, std::abs(course_error));
    }
    const double n = static_cast<double>(lines.size());
    EXPECT_LT(std::abs(sum_e / n), 0.004);  // 3 sigma of the mean: 3 x 1.2 cm / sqrt(250)
    EXPECT_LT(std::abs(sum_n / n), 0.004);
    EXPECT_NEAR(std::sqrt(sum_e2 / n), 0.012, 0.003);
    EXPECT_NEAR(std::sqrt(sum_n2 / n), 0.012, 0.003);
    // Course noise at 1.5 m/s: about 0.02 / 1.5 rad = 0.76 deg (1 sigma).
    EXPECT_LT(max_course_error, 4.0);
    EXPECT_GT(max_course_error, 0.5);
}

double course_sd_deg(double speed_m_s) {
    const SprayerKinematics k = north_at(speed_m_s, 60.0);
    Ad300Params p;
    p.seed = 11;
    p.min_course_speed_m_s = 0.0;
    Ad300Receiver rx(k, p);
    double sum2 = 0.0;
    int n = 0;
    for (const TimedLine& line : rx.poll(seconds_to_ns(50.0))) {
        const rig::nmea::RmcData rmc = parse_rmc(line.text);
        if (!rmc.course_true_deg) continue;
        const double e = std::remainder(*rmc.course_true_deg, 360.0);
        sum2 += e * e;
        ++n;
    }
    return std::sqrt(sum2 / n);
}

TEST(Ad300Receiver, CourseNoiseGrowsAsTheSpeedFalls) {
    // sigma_course ~ sigma_v / v: 0.02 / 1.5 rad = 0.76 deg; 0.02 / 0.2 rad = 5.7 deg.
    const double fast = course_sd_deg(1.5);
    const double slow = course_sd_deg(0.2);
    EXPECT_NEAR(fast, 0.76, 0.2);
    EXPECT_NEAR(slow, 5.7, 1.2);
    EXPECT_GT(slow, 5.0 * fast);
}

TEST(Ad300Receiver, NoCourseWhenStandingStill) {
    const SprayerKinematics k(LocalFrame(kWuzhiLat, kWuzhiLon), Route2d({{0, 0}, 45.0}, {StandSegment{60.0}}),
                              SprayerMounting{}, BoomHeightProfile{});
    Ad300Receiver rx(k, Ad300Params{});
    // Standing: the reported speed is the velocity noise alone (about 2.5 cm/s),
    // below min_course_speed_m_s (10 cm/s): the course field stays empty.
    const std::vector<TimedLine> lines = rx.poll(seconds_to_ns(10.0));
    ASSERT_FALSE(lines.empty());
    for (const TimedLine& line : lines) {
        const rig::nmea::RmcData rmc = parse_rmc(line.text);
        EXPECT_FALSE(rmc.course_true_deg.has_value()) << line.text;
        ASSERT_TRUE(rmc.speed_m_s.has_value());
        EXPECT_LT(*rmc.speed_m_s, 0.1);
    }
}

TEST(Ad300Receiver, SameSeedSameSentencesHoweverPolled) {
    const SprayerKinematics k = north_at(1.0, 10.0);
    Ad300Params p;
    p.seed = 3;
    Ad300Receiver once(k, p);
    Ad300Receiver often(k, p);
    const std::vector<TimedLine> a = once.poll(seconds_to_ns(5.0));
    std::vector<TimedLine> b;
    for (int ms = 0; ms <= 5000; ms += 7) {
        for (TimedLine& line : often.poll(seconds_to_ns(ms / 1000.0))) b.push_back(std::move(line));
    }
    for (TimedLine& line : often.poll(seconds_to_ns(5.0))) b.push_back(std::move(line));
    ASSERT_EQ(a.size(), b.size());
    for (std::size_t i = 0; i < a.size(); ++i) {
        EXPECT_EQ(a[i].text, b[i].text);
        EXPECT_EQ(a[i].at_ns, b[i].at_ns);
    }
    p.seed = 4;
    Ad300Receiver other(k, p);
    EXPECT_NE(other.poll(seconds_to_ns(5.0)).front().text, a.front().text);
}

TEST(Ad300Receiver, BadParametersAreRejectedByName) {
    const SprayerKinematics k = north_at(1.0, 10.0);
    const auto expect_bad = [&](Ad300Params p, const std::string& key) {
        try {
            Ad300Receiver rx(k, p);
            ADD_FAILURE() << "no exception for " << key;
        } catch (const std::invalid_argument& e) {
            EXPECT_NE(std::string(e.what()).find(key), std::string::npos) << e.what();
        }
    };
    Ad300Params p;
    p.rate_hz = 0.0;
    expect_bad(p, "rate_hz");
    p = Ad300Params{};
    p.talker = "gps";
    expect_bad(p, "talker");
    p = Ad300Params{};
    p.epoch_phase_s = 0.1;  // must be < 1 / 10 Hz
    expect_bad(p, "epoch_phase_s");
    p = Ad300Params{};
    p.latency_s = -0.01;
    expect_bad(p, "latency_s");
}

// The whole text, as the case's load error shows it (emulators/param_check.h):
// the key, the bounds (an open upper one too) and the value, six decimals each.
TEST(Ad300Receiver, ARangeErrorSaysTheKeyTheBoundsAndTheValue) {
    const SprayerKinematics k = north_at(1.0, 10.0);
    Ad300Params p;
    p.utc_start_seconds_of_day = 86400.0;
    try {
        Ad300Receiver rx(k, p);
        ADD_FAILURE() << "86400 s of day was taken";
    } catch (const std::invalid_argument& e) {
        EXPECT_EQ(std::string(e.what()),
                  "ad300.utc_start_seconds_of_day: must be in [0.000000, 86400.000000), got 86400.000000");
    }
}

}  // namespace
