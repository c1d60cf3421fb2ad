// The L4 laser boom-height sensor (emulators/l4_laser_sensor.h) and the
// controller's reader of its lines (controller/boundary/l4_laser_parser.h):
// the two sides are written independently and checked against each other.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "controller/boundary/l4_laser_parser.h"
#include "emulators/l4_laser_sensor.h"

namespace {

using namespace rig::field2d;
using rig::seconds_to_ns;
using rig::controller::boundary::L4Reading;
using rig::controller::boundary::parse_l4_line;
using rig::emulators::L4LaserParams;
using rig::emulators::L4LaserSensor;
using rig::emulators::TimedLine;

SprayerKinematics standing(BoomHeightProfile height) {
    return SprayerKinematics(LocalFrame(35.1, 113.3), Route2d({{0, 0}, 0.0}, {StandSegment{100.0}}), SprayerMounting{},
                             std::move(height));
}

TEST(L4Laser, WireFormat) {
    EXPECT_EQ(rig::emulators::format_l4_distance(0.5), "D=0.500m\r\n");
    EXPECT_EQ(rig::emulators::format_l4_distance(0.5034), "D=0.503m\r\n");
    EXPECT_EQ(rig::emulators::format_l4_distance(12.3456, 4), "D=12.3456m\r\n");
    EXPECT_EQ(rig::emulators::format_l4_distance(0.0), "D=0.000m\r\n");
    EXPECT_EQ(rig::emulators::format_l4_error(1), "E=1\r\n");
    EXPECT_THROW(rig::emulators::format_l4_distance(-0.1), std::invalid_argument);
    EXPECT_THROW(rig::emulators::format_l4_distance(0.5, 2), std::invalid_argument);
}

TEST(L4Laser, ReadingsStayWithinTheDatasheetAccuracy) {
    // Table 1: +-(1 mm + 0.0005 D): at D = 0.5 m, +-1.25 mm, then rounded to the
    // 1 mm resolution (+-0.5 mm): every reading within 1.75 mm of 0.5 m.
    const SprayerKinematics k = standing(BoomHeightProfile{});
    L4LaserParams p;
    p.phase_s = 0.0;
    L4LaserSensor laser(k, p);
    const std::vector<TimedLine> lines = laser.poll(seconds_to_ns(10.0));
    // 10 Hz from t = 0, 20 ms latency: samples 0 ... 9.9 s, 100 lines.
    ASSERT_EQ(lines.size(), 100u);
    double lo = 1e9;
    double hi = -1e9;
    for (std::size_t i = 0; i < lines.size(); ++i) {
        EXPECT_EQ(lines[i].at_ns, seconds_to_ns(0.02) + static_cast<rig::TimeNs>(i) * 100'000'000);
        const L4Reading r = parse_l4_line(lines[i].text);
        ASSERT_TRUE(r.ok()) << lines[i].text;
        EXPECT_LE(std::abs(*r.distance_m - 0.5), 0.00175 + 1e-12);
        lo = std::min(lo, *r.distance_m);
        hi = std::max(hi, *r.distance_m);
    }
    // The noise is there: readings 0.499, 0.500 and 0.501 m all occur.
    EXPECT_NEAR(lo, 0.499, 1e-12);
    EXPECT_NEAR(hi, 0.501, 1e-12);
}

TEST(L4Laser, FollowsAMovingBoomAndReportsOutOfRange) {
    const SprayerKinematics k = standing(BoomHeightProfile({{0.0, 0.4}, {10.0, 0.6}}));
    L4LaserParams p;
    p.phase_s = 0.05;
    p.latency_s = 0.0;
    L4LaserSensor laser(k, p);
    for (const TimedLine& line : laser.poll(seconds_to_ns(12.0))) {
        const double h = k.boom_height_at(rig::ns_to_seconds(line.at_ns));
        const L4Reading r = parse_l4_line(line.text);
        ASSERT_TRUE(r.ok());
        EXPECT_LE(std::abs(*r.distance_m - h), 0.001 + 0.0005 * h + 0.0005 + 1e-12);
    }
    p.min_range_m = 1.0;  // the boom is below the module's range
    L4LaserSensor blind(k, p);
    const std::vector<TimedLine> lines = blind.poll(seconds_to_ns(1.0));
    ASSERT_FALSE(lines.empty());
    EXPECT_EQ(lines.front().text, "E=1\r\n");
    EXPECT_EQ(parse_l4_line(lines.front().text).device_error, 1);
}

TEST(L4Laser, SameSeedSameLines) {
    const SprayerKinematics k = standing(BoomHeightProfile{});
    L4LaserParams p;
    p.seed = 9;
    L4LaserSensor a(k, p);
    L4LaserSensor b(k, p);
    std::vector<TimedLine> lb;
    for (int ms = 0; ms <= 3000; ms += 13) {
        for (TimedLine& l : b.poll(seconds_to_ns(ms / 1000.0))) lb.push_back(std::move(l));
    }
    for (TimedLine& l : b.poll(seconds_to_ns(3.0))) lb.push_back(std::move(l));
    const std::vector<TimedLine> la = a.poll(seconds_to_ns(3.0));
    ASSERT_EQ(la.size(), lb.size());
    for (std::size_t i = 0; i < la.size(); ++i) EXPECT_EQ(la[i].text, lb[i].text);
    EXPECT_LT(a.phase_s(), 0.1);
}

TEST(L4Laser, BadParametersAreRejectedByName) {
    const SprayerKinematics k = standing(BoomHeightProfile{});
    L4LaserParams p;
    p.rate_hz = 50.0;
    EXPECT_THROW(L4LaserSensor(k, p), std::invalid_argument);
    p = L4LaserParams{};
    p.decimals = 2;
    try {
        L4LaserSensor laser(k, p);
        ADD_FAILURE();
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("decimals"), std::string::npos);
    }
    p = L4LaserParams{};
    p.max_range_m = 0.01;
    EXPECT_THROW(L4LaserSensor(k, p), std::invalid_argument);
}

// The whole text, as the case's load error shows it (emulators/param_check.h).
TEST(L4Laser, ARangeErrorSaysTheKeyTheBoundsAndTheValue) {
    const SprayerKinematics k = standing(BoomHeightProfile{});
    L4LaserParams p;
    p.mount_offset_m = -1.25;
    try {
        L4LaserSensor laser(k, p);
        ADD_FAILURE() << "a mount offset of -1.25 m was taken";
    } catch (const std::invalid_argument& e) {
        EXPECT_EQ(std::string(e.what()), "l4_laser.mount_offset_m: must be in [-1.000000, 2.000000], got -1.250000");
    }
}

TEST(L4LaserParser, HostileLinesGiveErrorsNotCrashes) {
    EXPECT_DOUBLE_EQ(*parse_l4_line("D=0.503m\r\n").distance_m, 0.503);
    EXPECT_DOUBLE_EQ(*parse_l4_line("D=0.503m").distance_m, 0.503);
    EXPECT_DOUBLE_EQ(*parse_l4_line("D=12.3456m\n").distance_m, 12.3456);
    const struct {
        const char* line;
        const char* fragment;
    } bad[] = {
        {"", "empty line at column 1"},
        {"\r\n", "empty line"},
        {"D=0.503", "expected unit 'm' at column 8"},
        {"D=.5m", "start with a digit at column 3"},
        {"D=0.m", "digits after '.'"},
        {"D=0,503m", "expected '.'"},
        {"D=0.503mm", "after the unit"},
        {"X=1", "expected 'D=' or 'E='"},
        {"E=abc", "digits"},
        {"D=0.50\x01m", "non-printable byte at column 7"},
        {"D=0.5000000000000000000000000000000m", "longer than 32"},
        {"D=9999999.0m", "too large"},
    };
    for (const auto& b : bad) {
        const L4Reading r = parse_l4_line(b.line);
        EXPECT_FALSE(r.ok()) << b.line;
        ASSERT_TRUE(r.error.has_value()) << b.line;
        EXPECT_NE(r.error->find(b.fragment), std::string::npos) << b.line << " -> " << *r.error;
    }
    // Any bytes at all: never throws, always one answer.
    std::string junk;
    for (int i = 0; i < 2000; ++i) {
        junk.push_back(static_cast<char>((i * 37 + 11) % 256));
        const L4Reading r = parse_l4_line(junk.substr(junk.size() > 20 ? junk.size() - 20 : 0));
        EXPECT_TRUE(r.ok() || r.device_error || r.error);
    }
}

}  // namespace
