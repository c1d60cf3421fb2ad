// Wire format of the GNSS receiver emulator: turns one epoch of a receiver's
// solution (GnssFix) into NMEA 0183 sentences.  The solution is kept apart from
// the wire format (as ArduPilot SITL does) so that one simulated receiver can be
// written as GGA, RMC or anything else a case asks for.
//
// This file does not use the controller's parser: the emulator stands for a real
// receiver, and the round-trip tests check the two independent sides against
// each other.
#pragma once

#include <string>
#include <string_view>

namespace rig::nmea {

struct GnssFix {                          // one epoch of a receiver's solution
    int year = 1980, month = 1, day = 6;  // UTC date
    double utc_seconds_of_day = 0.0;
    double lat_deg = 0.0, lon_deg = 0.0;  // WGS84
    double altitude_msl_m = 0.0, geoid_separation_m = 0.0;
    int fix_quality = 0;  // GGA: 0 none, 1 GPS, 2 DGPS, 4 RTK fixed, 5 RTK float
    int satellites = 0;
    double hdop = 0.0;
    double speed_m_s = 0.0, course_deg = 0.0;  // over ground, course true north clockwise
    double differential_age_s = 0.0;
    int station_id = 0;
};

// Minutes of latitude/longitude are written with this many decimals, as RTK
// receivers do (Trimble in nmea-rtk.log): 1e-8 minute is about 2e-5 m.
inline constexpr int kMinuteDecimals = 8;

// Full sentences, "$" to "*HH\r\n".  Time is hhmmss.ss; a time that rounds up to
// 24:00:00.00 is written as 00:00:00.00 of the next day (RMC's date moves too).
// fix_quality 0 means no solution: position, altitude, geoid separation and the
// differential fields (GGA), speed and course (RMC) are left empty; RMC status
// is V and mode N.  The differential age and station id are only written for
// fix qualities 2, 4 and 5.  A day past the end of the month rolls over into the
// next month.
// A value that is not finite, or a position outside +-90 / +-180 degrees, is also
// written as an empty field: a receiver never prints "nan".
std::string encode_gga(std::string_view talker, const GnssFix& fix);
std::string encode_rmc(std::string_view talker, const GnssFix& fix);

// body is the text between '$' and '*'; returns "$body*HH\r\n" with the
// checksum in upper-case hex.
std::string with_checksum(std::string_view body);

}  // namespace rig::nmea
