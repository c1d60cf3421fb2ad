// `rig nmea decode`: exact JSON lines and exit codes for small streams.
// Positions and speeds are chosen to be exact in binary (48 deg 7.5 min =
// 48.125 deg; 3.6 kn = 1.852 m/s) so the expected JSON can be written by hand.
#include <gtest/gtest.h>

#include <sstream>
#include <string>

#include "harness/bench/nmea_decode_tool.h"

namespace rig::nmea {
namespace {

using namespace std::string_literals;

struct Decoded {
    int exit_code;
    std::string output;
};

Decoded decode(const std::string& input) {
    std::istringstream in(input);
    std::ostringstream out;
    const int exit_code = decode_stream(in, out);
    return {exit_code, out.str()};
}

TEST(NmeaDecodeTool, GoodBadAndCommentLines) {
    const std::string input =
        "# gpsd-style comment\n"                                                 // 1
        "\n"                                                                     // 2
        "$GPGGA,123519,4807.500,N,01115.000,E,1,08,0.9,545.4,M,46.9,M,,*4F\n"    // 3
        "$GNRMC,235960.25,A,4807.500,S,01115.000,W,3.6,270.5,290220,,,R*54\r\n"  // 4
        "$GPHDT,274.07,T*04\n"                                                   // 5
        "   # indented comment\n"                                                // 6
        "$GPGSV,1,1,01,08,75,303,44*42\n"                                        // 7
        "\x01\xFF garbage\n"                                                     // 8
        "$GPGGA,123519,4807.500,N,01115.000,E,9,08,0.9,545.4,M,46.9,M,,*47\n"    // 9
        "$GPZDA,201530.00,04,07,2002,00,00*60";                                  // 10, no final newline
    const Decoded decoded = decode(input);
    EXPECT_EQ(decoded.exit_code, 1);
    EXPECT_EQ(
        decoded.output,
        R"json({"talker":"GP","type":"GGA","decoded":true,"utc_time":"12:35:19.000","lat_deg":48.125,"lon_deg":11.25,"fix_quality":1,"satellites":8,"hdop":0.9,"altitude_msl_m":545.4,"geoid_separation_m":46.9}
{"talker":"GN","type":"RMC","decoded":true,"utc_time":"23:59:60.250","date":"2020-02-29","status":"A","lat_deg":-48.125,"lon_deg":-11.25,"speed_knots":3.6,"speed_m_s":1.852,"course_deg":270.5,"mode":"R"}
{"error":"checksum mismatch: sentence says 0x04, computed 0x03","code":"checksum_mismatch","line":5}
{"talker":"GP","type":"GSV","decoded":false,"fields":["1","1","01","08","75","303","44"]}
{"error":"sentence must start with '$', starts with '\\x01' at column 1","code":"missing_start_delimiter","line":8}
{"error":"GGA field 6 (fix quality): '9' is outside 0..8","code":"field_out_of_range","line":9}
{"talker":"GP","type":"ZDA","decoded":true,"utc_time":"20:15:30.000","date":"2002-07-04","local_zone_hours":0,"local_zone_minutes":0}
)json");
}

TEST(NmeaDecodeTool, AllGoodIsExitZero) {
    const Decoded decoded = decode(
        "# only good lines\r\n"
        "$GPHDT,274.07,T*03\r\n"
        "\r\n"
        "$PSRF151,3,1833,28692,0x7EFFFFFF*15\r\n");
    EXPECT_EQ(decoded.exit_code, 0);
    EXPECT_EQ(decoded.output,
              R"json({"talker":"GP","type":"HDT","decoded":true,"heading_deg":274.07}
{"talker":"P","type":"SRF151","decoded":false,"fields":["3","1833","28692","0x7EFFFFFF"]}
)json");
}

TEST(NmeaDecodeTool, EmptyInputIsExitZero) {
    const Decoded decoded = decode("");
    EXPECT_EQ(decoded.exit_code, 0);
    EXPECT_EQ(decoded.output, "");
}

TEST(NmeaDecodeTool, HugeLinesAndBinaryGarbage) {
    std::string garbage;
    for (int i = 0; i < 4096; ++i) garbage += static_cast<char>(i * 7 % 256 == '\n' ? 0 : i * 7 % 256);
    const Decoded decoded = decode(std::string(1 << 20, '$') + "\n" + std::string(200, 'A') + "\n" + garbage);
    EXPECT_EQ(decoded.exit_code, 1);
    EXPECT_EQ(
        decoded.output,
        R"json({"error":"line is 1048576 bytes long, far beyond any sentence; not parsed","code":"line_too_long","line":1}
{"error":"sentence is 202 characters including CR LF; the limit is 120 (NMEA 0183 says 82)","code":"line_too_long","line":2}
{"error":"sentence is 4098 characters including CR LF; the limit is 120 (NMEA 0183 says 82)","code":"line_too_long","line":3}
)json");
}

}  // namespace
}  // namespace rig::nmea
