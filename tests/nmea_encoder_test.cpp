// GNSS emulator wire format: one hand-worked fix checked character for
// character, rounding/carry edge cases, and a randomised round trip through the
// controller's parser (an independent implementation of the other side).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <iostream>
#include <random>
#include <string>
#include <vector>

#include "rig/nmea/nmea_parser.h"
#include "rig/nmea/nmea_encoder.h"

namespace rig::nmea {
namespace {

// 1e-8 minute (the last printed digit) in degrees, and metres per degree of
// latitude (an upper bound for longitude as well).
constexpr double kMinuteQuantumDeg = 1e-8 / 60.0;
constexpr double kMetresPerDegree = 111320.0;

GnssFix hand_worked_fix() {
    GnssFix fix;
    fix.year = 2020;
    fix.month = 3;
    fix.day = 18;
    fix.utc_seconds_of_day = 48500.6;  // 13 h 28 min 20.60 s
    fix.lat_deg = 41.574970205;        // 0.574970205 deg * 60 = 34.4982123 min
    fix.lon_deg = -93.750558641;       // 0.750558641 deg * 60 = 45.03351846 min
    fix.altitude_msl_m = 278.02;
    fix.geoid_separation_m = -31.442;
    fix.fix_quality = 2;
    fix.satellites = 9;
    fix.hdop = 1.0;
    fix.speed_m_s = 1.673;  // * 3600 / 1852 = 3.25205 kn
    fix.course_deg = 92.308;
    fix.differential_age_s = 7.6;
    fix.station_id = 133;
    return fix;
}

// Checksums worked out separately with
//   python3 -c 'import functools;print("%02X"%functools.reduce(lambda a,c:a^ord(c),BODY,0))'
TEST(NmeaEncoder, HandWorkedGga) {
    EXPECT_EQ(encode_gga("GP", hand_worked_fix()),
              "$GPGGA,132820.60,4134.49821230,N,09345.03351846,W,2,09,1.0,278.020,M,-31.442,M,7.6,"
              "0133*75\r\n");
}

TEST(NmeaEncoder, HandWorkedRmc) {
    EXPECT_EQ(encode_rmc("GP", hand_worked_fix()),
              "$GPRMC,132820.60,A,4134.49821230,N,09345.03351846,W,3.252,92.308,180320,,,D*7B\r\n");
}

TEST(NmeaEncoder, NoFixLeavesPositionEmptyAndRmcVoid) {
    GnssFix fix = hand_worked_fix();
    fix.fix_quality = 0;
    fix.satellites = 0;
    fix.hdop = 99.9;
    fix.year = 2019;
    fix.month = 12;
    fix.day = 31;
    fix.utc_seconds_of_day = 86399.996;  // rounds to 24:00:00.00: next day, next year
    EXPECT_EQ(encode_gga("GN", fix), "$GNGGA,000000.00,,,,,0,00,99.9,,M,,M,,*41\r\n");
    EXPECT_EQ(encode_rmc("GN", fix), "$GNRMC,000000.00,V,,,,,,,010120,,,N*61\r\n");

    const ParseResult gga = parse_sentence(encode_gga("GN", fix));
    ASSERT_TRUE(gga.ok()) << gga.error->message;
    EXPECT_FALSE(std::get<GgaData>(gga.sentence->data).position);
    const ParseResult rmc = parse_sentence(encode_rmc("GN", fix));
    ASSERT_TRUE(rmc.ok()) << rmc.error->message;
    EXPECT_EQ(std::get<RmcData>(rmc.sentence->data).status, DataStatus::invalid);
}

TEST(NmeaEncoder, WithChecksum) {
    EXPECT_EQ(with_checksum("GPHDT,,T"), "$GPHDT,,T*1B\r\n");  // hemi.log
    EXPECT_EQ(with_checksum(""), "$*00\r\n");
}

// Field 2..5 of GGA ("ddmm.mmmmmmmm,N,dddmm.mmmmmmmm,E") for a position.
std::string position_fields(double lat_deg, double lon_deg) {
    GnssFix fix = hand_worked_fix();
    fix.lat_deg = lat_deg;
    fix.lon_deg = lon_deg;
    const std::string gga = encode_gga("GP", fix);
    const std::size_t begin = gga.find(',', gga.find(',') + 1) + 1;  // after the time
    std::size_t end = begin;
    for (int comma = 0; comma < 4; ++comma) end = gga.find(',', end) + 1;
    return gga.substr(begin, end - 1 - begin);
}

TEST(NmeaEncoder, MinutesThatRoundTo60CarryIntoDegrees) {
    struct Row {
        double lat_deg, lon_deg;
        std::string expected;
        std::string legend;
    };
    const std::vector<Row> rows{
        {10.0 + 59.999999996 / 60.0, 9.0 + 59.999999996 / 60.0, "1100.00000000,N,01000.00000000,E",
         "59.999999996 min rounds to 60: carry"},
        {-(10.0 + 59.999999996 / 60.0), -(9.0 + 59.999999996 / 60.0), "1100.00000000,S,01000.00000000,W",
         "same, south and west"},
        {10.0 + 59.999999994 / 60.0, 9.0, "1059.99999999,N,00900.00000000,E", "59.999999994 min stays below 60"},
        {89.99999999999, 179.99999999999, "9000.00000000,N,18000.00000000,E", "the limits"},
        {90.0, -180.0, "9000.00000000,N,18000.00000000,W", "exactly the limits"},
        {0.0, -0.0, "0000.00000000,N,00000.00000000,E", "zero and negative zero"},
        {-1e-12, -1e-12, "0000.00000000,N,00000.00000000,E",
         "rounds to zero: printed hemisphere follows the printed value"},
        {-0.5, 0.25, "0030.00000000,S,00015.00000000,E", "half a degree south"},
        {91.0, 0.0, ",,,", "latitude out of range: empty fields"},
        {0.0, 180.5, ",,,", "longitude out of range: empty fields"},
        {std::nan(""), 0.0, ",,,", "not a number: empty fields"},
    };
    for (const Row& row : rows) {
        EXPECT_EQ(position_fields(row.lat_deg, row.lon_deg), row.expected) << row.legend;
    }
}

TEST(NmeaEncoder, TimeAndDateRounding) {
    struct Row {
        double seconds_of_day;
        int year, month, day;
        std::string time, date, legend;
    };
    const std::vector<Row> rows{
        {59.996, 2020, 3, 18, "000100.00", "180320", "59.996 s rounds to the next minute"},
        {3599.996, 2020, 3, 18, "010000.00", "180320", "carry into the hour"},
        {86399.994, 2020, 3, 18, "235959.99", "180320", "last centisecond of the day"},
        {86399.996, 2020, 2, 28, "000000.00", "290220", "carry into 29 February of a leap year"},
        {86399.996, 2019, 2, 28, "000000.00", "010319", "carry into 1 March"},
        {86399.996, 2019, 12, 31, "000000.00", "010120", "carry into the next year"},
        {86400.0, 2020, 3, 18, "000000.00", "190320", "86400 s is the next day"},
        {-0.004, 2020, 3, 18, "000000.00", "180320", "-0.004 s rounds to 0"},
        {-1.0, 2020, 3, 1, "235959.00", "290220", "negative: the day before"},
        {43200.0, 2020, 3, 32, "120000.00", "010420", "day 32 of March is 1 April"},
    };
    for (const Row& row : rows) {
        GnssFix fix = hand_worked_fix();
        fix.utc_seconds_of_day = row.seconds_of_day;
        fix.year = row.year;
        fix.month = row.month;
        fix.day = row.day;
        const std::string rmc = encode_rmc("GP", fix);
        EXPECT_EQ(rmc.substr(7, 9), row.time) << row.legend << ": " << rmc;
        EXPECT_NE(rmc.find("," + row.date + ","), std::string::npos) << row.legend << ": " << rmc;
        EXPECT_TRUE(parse_sentence(rmc).ok()) << row.legend << ": " << rmc;
    }
}

TEST(NmeaEncoder, ImpossibleDateIsAnEmptyField) {
    GnssFix fix = hand_worked_fix();
    fix.month = 13;
    EXPECT_NE(encode_rmc("GP", fix).find(",92.308,,,,D*"), std::string::npos) << encode_rmc("GP", fix);
    fix.month = 3;
    fix.day = 0;
    EXPECT_NE(encode_rmc("GP", fix).find(",92.308,,,,D*"), std::string::npos) << encode_rmc("GP", fix);
}

TEST(NmeaEncoder, CourseAndSignRounding) {
    GnssFix fix = hand_worked_fix();
    fix.course_deg = 359.9996;
    EXPECT_NE(encode_rmc("GP", fix).find(",0.000,180320,"), std::string::npos) << "wraps to 0";
    fix.course_deg = -90.0;
    EXPECT_NE(encode_rmc("GP", fix).find(",270.000,180320,"), std::string::npos);
    fix.course_deg = 720.5;
    EXPECT_NE(encode_rmc("GP", fix).find(",0.500,180320,"), std::string::npos);

    fix.altitude_msl_m = -0.0001;
    EXPECT_NE(encode_gga("GP", fix).find(",0.000,M,"), std::string::npos) << "no -0.000";
    fix.altitude_msl_m = std::nan("");
    EXPECT_NE(encode_gga("GP", fix).find(",1.0,,M,"), std::string::npos) << "NaN: empty";
}

// Randomised round trip.  The wire has 1e-8 minute resolution (1.9e-5 m), so a
// fix cannot come back to better than half of that; what must hold is
//  - the parser reads the printed digits to better than 1e-6 m,
//  - the decoded position is the input within half a quantum,
//  - re-encoding the decoded fix gives the identical sentence.
TEST(NmeaEncoder, RandomisedRoundTripThroughTheParser) {
    std::mt19937_64 random(0x5EED);
    std::uniform_real_distribution<double> latitude(-90.0, 90.0);
    std::uniform_real_distribution<double> longitude(-180.0, 180.0);
    std::uniform_real_distribution<double> seconds_of_day(0.0, 86400.0);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    std::uniform_int_distribution<int> whole_degrees_lat(0, 89);
    std::uniform_int_distribution<int> whole_degrees_lon(0, 179);
    const std::vector<int> qualities{1, 2, 4, 5};

    // An angle whose minutes are within 1e-8 of 60: the carry case.
    auto near_minute_carry = [&](int degrees) {
        const double sign = unit(random) < 0.5 ? -1.0 : 1.0;
        return sign * (degrees + (60.0 - 1e-8 * unit(random)) / 60.0);
    };
    // Exact wire value: the angle rounded to whole quanta (what the digits say).
    auto wire_value = [](double angle_deg) {
        const double quanta = std::round(std::fabs(angle_deg) / kMinuteQuantumDeg);
        return std::copysign(quanta * kMinuteQuantumDeg, angle_deg);
    };

    constexpr int kSamples = 20000;
    double worst_parse_error_m = 0.0;
    for (int i = 0; i < kSamples; ++i) {
        GnssFix fix = hand_worked_fix();
        const bool edge = i % 4 == 0;
        fix.lat_deg = edge ? near_minute_carry(whole_degrees_lat(random)) : latitude(random);
        fix.lon_deg = edge ? near_minute_carry(whole_degrees_lon(random)) : longitude(random);
        fix.utc_seconds_of_day = seconds_of_day(random);
        fix.fix_quality = qualities[static_cast<std::size_t>(i) % qualities.size()];
        fix.speed_m_s = 10.0 * unit(random);
        fix.course_deg = 360.0 * unit(random);
        fix.altitude_msl_m = -100.0 + 5000.0 * unit(random);

        const std::string gga_text = encode_gga("GN", fix);
        const ParseResult gga_result = parse_sentence(gga_text);
        ASSERT_TRUE(gga_result.ok()) << gga_text << gga_result.error->message;
        const GgaData gga = std::get<GgaData>(gga_result.sentence->data);
        ASSERT_TRUE(gga.position && gga.utc_time) << gga_text;

        for (const auto& [decoded, input] :
             {std::pair{gga.position->lat_deg, fix.lat_deg}, std::pair{gga.position->lon_deg, fix.lon_deg}}) {
            const double parse_error_m = std::fabs(decoded - wire_value(input)) * kMetresPerDegree;
            worst_parse_error_m = std::max(worst_parse_error_m, parse_error_m);
            ASSERT_LT(parse_error_m, 1e-6) << gga_text;
            ASSERT_LE(std::fabs(decoded - input), 0.5 * kMinuteQuantumDeg + 1e-12) << gga_text;
        }
        const double expected_time =
            static_cast<double>(std::llround(fix.utc_seconds_of_day * 100.0) % 8640000) / 100.0;
        ASSERT_NEAR(gga.utc_time->seconds_of_day(), expected_time, 1e-9) << gga_text;
        ASSERT_EQ(gga.fix_quality, fix.fix_quality);

        GnssFix decoded_fix = fix;
        decoded_fix.lat_deg = gga.position->lat_deg;
        decoded_fix.lon_deg = gga.position->lon_deg;
        decoded_fix.utc_seconds_of_day = gga.utc_time->seconds_of_day();
        ASSERT_EQ(encode_gga("GN", decoded_fix), gga_text);

        const std::string rmc_text = encode_rmc("GN", fix);
        const ParseResult rmc_result = parse_sentence(rmc_text);
        ASSERT_TRUE(rmc_result.ok()) << rmc_text << rmc_result.error->message;
        const RmcData rmc = std::get<RmcData>(rmc_result.sentence->data);
        ASSERT_TRUE(rmc.position && rmc.speed_m_s && rmc.course_true_deg) << rmc_text;
        ASSERT_EQ(rmc.position, gga.position);
        ASSERT_EQ(rmc.status, DataStatus::valid);
        // Speed is printed to 0.001 kn, course to 0.001 deg.
        ASSERT_NEAR(*rmc.speed_m_s, fix.speed_m_s, 0.0005 * 1852.0 / 3600.0 + 1e-12) << rmc_text;
        const double course_error = std::fabs(*rmc.course_true_deg - fix.course_deg);
        ASSERT_LE(std::min(course_error, 360.0 - course_error), 0.0005 + 1e-9) << rmc_text;
        ASSERT_LE(gga_text.size(), kDefaultMaxSentenceLength);
        ASSERT_LE(rmc_text.size(), kDefaultMaxSentenceLength);
    }
    RecordProperty("worst_parse_error_m", std::to_string(worst_parse_error_m));
    std::cout << "worst position error added by the parser: " << worst_parse_error_m << " m\n";
}

}  // namespace
}  // namespace rig::nmea
