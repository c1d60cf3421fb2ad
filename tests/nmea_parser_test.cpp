// NMEA parser: a gpsd-style table of hostile inputs (each row says what is wrong
// with it and which error code it must get), hand-worked good sentences, and a
// mutation run that throws damaged sentences at the parser to show it never
// crashes (run this under -fsanitize=address,undefined).
#include <gtest/gtest.h>

#include <cstdint>
#include <ostream>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "rig/nmea/nmea_parser.h"

namespace rig::nmea {
namespace {

using namespace std::string_literals;
using Code = ParseErrorCode;

// "$body*HH" with the checksum computed here, independently of nmea_checksum(),
// for rows whose fault lies behind a correct checksum.
std::string sentence(std::string_view body) {
    unsigned checksum = 0;
    for (char c : body) checksum ^= static_cast<unsigned char>(c);
    constexpr std::string_view kHex = "0123456789ABCDEF";
    return "$"s + std::string(body) + "*" + kHex[checksum >> 4] + kHex[checksum & 0xF];
}

// A well-formed TXT sentence whose length, counting CR LF, is exactly `length`.
std::string sentence_of_length(std::size_t length) {
    const std::string head = "GPTXT,01,01,02,";
    constexpr std::size_t kFraming = 1 + 3 + 2;  // '$', "*HH", CR LF
    return sentence(head + std::string(length - kFraming - head.size(), 'X'));
}

// Base sentences (classic NMEA documentation examples) with one field replaced.
std::string gga_with(std::size_t field_number, std::string_view value) {
    std::vector<std::string> fields{"GPGGA", "123519", "4807.038", "N",    "01131.000", "E", "1", "08",
                                    "0.9",   "545.4",  "M",        "46.9", "M",         "",  ""};
    fields.at(field_number) = value;
    std::string body;
    for (const std::string& field : fields) body += (body.empty() ? "" : ",") + field;
    return sentence(body);
}

std::string rmc_with(std::size_t field_number, std::string_view value) {
    std::vector<std::string> fields{"GPRMC", "123519", "A",      "4807.038", "N", "01131.000", "E",
                                    "022.4", "084.4",  "230394", "003.1",    "W", "A"};
    fields.at(field_number) = value;
    std::string body;
    for (const std::string& field : fields) body += (body.empty() ? "" : ",") + field;
    return sentence(body);
}

struct HostileRow {
    std::string input;
    ParseErrorCode code;
    std::string legend;              // what is wrong with the input
    std::string message_contains{};  // optional: part of the message that must appear
};

void PrintTo(const HostileRow& row, std::ostream* out) { *out << row.legend; }

std::vector<HostileRow> hostile_rows() {
    return {
        // --- framing ---
        {"", Code::empty_line, "empty line"},
        {"\r\n", Code::empty_line, "nothing but CR LF"},
        {"  \t \r\n", Code::empty_line, "only blanks"},
        {"GPHDT,274.07,T*03", Code::missing_start_delimiter, "no '$'"},
        {"!AIVDM,1,1,,A,13aEOK?P00PD2wVMdLDRhgvL289?,0*26", Code::missing_start_delimiter,
         "AIS '!' sentence on the GNSS port"},
        {",,,,,,,,,,,,,*1E", Code::missing_start_delimiter,
         "tail of a sentence whose head was lost (gp-320fw line 58)"},
        {"$", Code::missing_checksum, "'$' alone"},
        {"$GPHDT,274.07,T", Code::missing_checksum,
         "no checksum (gpsd accepts that; NMEA 0183 makes it optional, we do not)"},
        {"$GPHDT,274.07,T*", Code::malformed_checksum, "'*' with no hex digits"},
        {"$GPHDT,274.07,T*0", Code::malformed_checksum, "'*' with one hex digit", "column 16"},
        {"$GPHDT,274.07,T*0G", Code::malformed_checksum, "non-hex checksum"},
        {"$GPHDT,274.07,T*030", Code::malformed_checksum, "three checksum digits"},
        {"$GPHDT,274.07,T*03 ", Code::malformed_checksum, "blank after the checksum"},
        {"$GPGSA,A,1,,,,,,,,,,,,,,,*1E*43", Code::malformed_checksum, "two '*' (gp-320fw line 42)"},
        {"$GPHDT,274.07,T*04", Code::checksum_mismatch, "checksum off by one", "says 0x04, computed 0x03"},
        {"$GPHDT,274.08,T*03", Code::checksum_mismatch, "one payload digit changed"},
        {"$GPRMC,000344.03,A,4808.9992,N,4,02.3*05", Code::checksum_mismatch,
         "RMC cut mid-line, ending in another sentence's checksum (gp-320fw line 22)"},
        {sentence_of_length(121), Code::line_too_long, "121 characters incl. CR LF, one over the default limit",
         "121 characters"},
        {std::string(10240, 'A'), Code::line_too_long, "10 kB of garbage"},
        {"$GPGGA," + std::string(10000, ',') + "*00", Code::line_too_long, "10 kB of commas"},
        {"$GPHDT,27\0.07,T*03"s, Code::non_printable_character, "embedded NUL", "byte 0x00 at column 10"},
        {"$GPHDT,274.07\xB0,T*03", Code::non_printable_character, "Latin-1 degree sign"},
        {"$GPHDT,274.07\xC2\xB0,T*03", Code::non_printable_character, "UTF-8 degree sign"},
        {"$GPHDT,\t274.07,T*03", Code::non_printable_character, "tab inside the sentence"},
        {"$GPHDT,274.07,T*03\r\r\x7F", Code::non_printable_character, "stray CR and DEL after the checksum"},
        {"$GPRMC,000346.03,A,4808\0\0\0\0\0\0\0\0\0\0\0\0                  \r"s, Code::non_printable_character,
         "line padded with NULs (gp-320fw line 31)"},
        {"$GPGGA,030130$GPGLL,2638.1728,N,08011.3893,W,030131.000,A,A*41", Code::embedded_start_delimiter,
         "two sentences run together (triton400.log line 19)", "column 14"},
        {"$GPGSA,A,1,,$GPRMC,000425.00,V,0000.0000,N,00000.0000,E,,,220899,,,N*4D", Code::embedded_start_delimiter,
         "GSA cut short, RMC follows (gp-320fw line 74)"},
        {"$GPHDT,274.07,T!AI*03", Code::embedded_start_delimiter, "'!' inside a sentence"},
        // --- address ---
        {"$*00", Code::malformed_address, "empty address"},
        {sentence("gpgga,123519"), Code::malformed_address, "lower-case address"},
        {sentence("GPN,00000.0000,E,0,00,0.0,,M,,M,,"), Code::malformed_address,
         "3-letter address (gp-320fw line 34, checksum repaired)"},
        {sentence("GPGGA1,123519"), Code::malformed_address, "6-character address"},
        {sentence("GPGG4,123519"), Code::malformed_address, "digit in the sentence type"},
        {sentence("P,1,2"), Code::malformed_address, "proprietary 'P' with no manufacturer"},
        {sentence("Psrf,1"), Code::malformed_address, "proprietary address in lower case"},
        {sentence("XXGGA,123519,,,,,0,00,,,M,,M,,"), Code::unknown_talker, "talker XX", "talker 'XX' is not accepted"},
        {sentence("GIGGA,123519,,,,,0,00,,,M,,M,,"), Code::unknown_talker,
         "NavIC talker GI is not on the accepted list"},
        {sentence("GPXYZ,1,2"), Code::unknown_sentence_type, "sentence type XYZ", "'XYZ' is unknown"},
        // --- field counts ---
        {sentence("GPGGA,123519,4807.038,N"), Code::too_few_fields, "GGA with 3 fields",
         "GGA has 3 fields, needs at least 14"},
        {sentence("GPRMC,000344.03,A,4808.9992,N,4,02.3"), Code::too_few_fields,
         "truncated RMC behind a correct checksum"},
        {sentence("GPZDA,201530.00,04,07,2002"), Code::too_few_fields, "ZDA without the zone"},
        {sentence("GPGGA,235955.00,0000.0000,N,00000.0000,E,0,00,0.0,,M,,,,,,,,,,,"), Code::too_many_fields,
         "GGA with 21 fields (gp-320fw line 47, checksum repaired)"},
        {sentence("GPHDT,274.07,T,1"), Code::too_many_fields, "HDT with a third field"},
        // --- GGA fields ---
        {gga_with(2, "4860.000"), Code::field_out_of_range, "latitude minutes = 60",
         "GGA field 2 (latitude): minutes '60.000' must be below 60"},
        {gga_with(2, "4899.999"), Code::field_out_of_range, "latitude minutes 99.999"},
        {gga_with(2, "9100.000"), Code::field_out_of_range, "latitude 91 degrees", "beyond 90 degrees"},
        {gga_with(2, "9000.001"), Code::field_out_of_range, "latitude just over 90"},
        {gga_with(4, "18000.001"), Code::field_out_of_range, "longitude just over 180"},
        {gga_with(4, "01160.000"), Code::field_out_of_range, "longitude minutes = 60"},
        {gga_with(2, "480.7038"), Code::bad_field_syntax, "latitude with 3 digits before '.'"},
        {gga_with(4, "1131.000"), Code::bad_field_syntax, "longitude with 2 degree digits"},
        {gga_with(2, "-4807.038"), Code::bad_field_syntax, "signed latitude"},
        {gga_with(2, "4807."), Code::bad_field_syntax, "latitude ending in '.'"},
        {gga_with(2, "48O7.038"), Code::bad_field_syntax, "letter O for zero in latitude"},
        {gga_with(3, "X"), Code::bad_field_syntax, "N/S field 'X'", "GGA field 3 (N/S): 'X' is not N/S"},
        {gga_with(5, "N"), Code::bad_field_syntax, "E/W field 'N'"},
        {gga_with(3, ""), Code::bad_field_syntax, "latitude without N/S"},
        {gga_with(4, ""), Code::bad_field_syntax, "latitude without longitude",
         "field 4 (longitude): empty but latitude is given"},
        {gga_with(1, "250000"), Code::field_out_of_range, "time 25:00:00", "GGA field 1 (UTC time): '250000'"},
        {gga_with(1, "126019"), Code::field_out_of_range, "time 12:60:19"},
        {gga_with(1, "123561.5"), Code::field_out_of_range, "second 61.5"},
        {gga_with(1, "12:35:19"), Code::bad_field_syntax, "time with colons"},
        {gga_with(1, "1235"), Code::bad_field_syntax, "time hhmm"},
        {gga_with(1, "123519."), Code::bad_field_syntax, "time ending in '.'"},
        {gga_with(6, "x"), Code::bad_field_syntax, "fix quality 'x'",
         "GGA field 6 (fix quality): 'x' is not an integer"},
        {gga_with(6, "9"), Code::field_out_of_range, "fix quality 9", "'9' is outside 0..8"},
        {gga_with(6, "1.0"), Code::bad_field_syntax, "fix quality with decimals"},
        {gga_with(7, "-1"), Code::bad_field_syntax, "negative satellite count"},
        {gga_with(7, "99999999999"), Code::field_out_of_range, "satellite count overflows int"},
        {gga_with(8, "1e3"), Code::bad_field_syntax, "HDOP with exponent"},
        {gga_with(8, "nan"), Code::bad_field_syntax, "HDOP 'nan'"},
        {gga_with(8, "inf"), Code::bad_field_syntax, "HDOP 'inf'"},
        {gga_with(8, "1.2.3"), Code::bad_field_syntax, "HDOP with two points"},
        {gga_with(8, "+0.9"), Code::bad_field_syntax, "HDOP with '+'"},
        {gga_with(8, "."), Code::bad_field_syntax, "HDOP '.' alone"},
        {gga_with(8, "-0.9"), Code::field_out_of_range, "negative HDOP", "'-0.9' is below 0"},
        {gga_with(10, "F"), Code::bad_field_syntax, "altitude in feet", "is not 'M'"},
        {gga_with(13, "-1.0"), Code::field_out_of_range, "negative differential age"},
        {gga_with(14, "1024"), Code::field_out_of_range, "station id over 1023"},
        // --- RMC fields ---
        {rmc_with(9, "321394"), Code::field_out_of_range, "date 32/13",
         "RMC field 9 (date): '321394' is not a calendar date (day 32, month 13)"},
        {rmc_with(9, "310494"), Code::field_out_of_range, "31 April"},
        {rmc_with(9, "290221"), Code::field_out_of_range, "29 February 2021 (not a leap year)"},
        {rmc_with(9, "000194"), Code::field_out_of_range, "day 0"},
        {rmc_with(9, "2303"), Code::bad_field_syntax, "date ddmm"},
        {rmc_with(9, "23-3-94"), Code::bad_field_syntax, "date with dashes"},
        {rmc_with(2, "X"), Code::bad_field_syntax, "status 'X'"},
        {rmc_with(2, "AV"), Code::bad_field_syntax, "status 'AV'"},
        {rmc_with(7, "-1.0"), Code::field_out_of_range, "negative speed"},
        {rmc_with(8, "400.0"), Code::field_out_of_range, "course 400 degrees",
         "RMC field 8 (course over ground): '400.0' is above 360"},
        {rmc_with(11, "X"), Code::bad_field_syntax, "magnetic variation direction 'X'"},
        {rmc_with(12, "Z"), Code::bad_field_syntax, "mode indicator 'Z'"},
        // --- other types ---
        {sentence("GPZDA,201530.00,04,13,2002,00,00"), Code::field_out_of_range, "ZDA month 13"},
        {sentence("GPZDA,201530.00,,07,2002,00,00"), Code::bad_field_syntax, "ZDA date without day",
         "all present or all empty"},
        {sentence("GPZDA,201530.00,04,07,2002,14,00"), Code::field_out_of_range, "ZDA zone +14 h"},
        {sentence("GPVTG,054.7,X,034.4,M,005.5,N,010.2,K"), Code::bad_field_syntax, "VTG reference 'X' instead of 'T'"},
        {sentence("GPVTG,054.7,T,034.4,M,fast,N,010.2,K"), Code::bad_field_syntax, "VTG speed 'fast'"},
        {sentence("GPHDT,abc,T"), Code::bad_field_syntax, "HDT heading 'abc'"},
        {sentence("GPHDT,361.0,T"), Code::field_out_of_range, "HDT heading 361"},
        {sentence("GPGLL,4916.45,N,12311.12,W,225444,X,"), Code::bad_field_syntax, "GLL status 'X'"},
        {sentence("GPGLL,4916.45,N,12311.12,W,225444"), Code::too_few_fields, "GLL without status"},
    };
}

class HostileInput : public ::testing::TestWithParam<HostileRow> {};

TEST_P(HostileInput, IsRejectedWithItsOwnCode) {
    const HostileRow& row = GetParam();
    const ParseResult result = parse_sentence(row.input);
    ASSERT_FALSE(result.ok()) << row.legend;
    ASSERT_TRUE(result.error.has_value());
    EXPECT_FALSE(result.sentence.has_value());
    EXPECT_EQ(to_string(result.error->code), to_string(row.code))
        << row.legend << "\n  message: " << result.error->message;
    EXPECT_NE(result.error->message.find(row.message_contains), std::string::npos)
        << row.legend << "\n  message: " << result.error->message
        << "\n  expected to contain: " << row.message_contains;
}

INSTANTIATE_TEST_SUITE_P(Table, HostileInput, ::testing::ValuesIn(hostile_rows()));

// Every error code is covered by at least one row of the table.
TEST(HostileInputTable, CoversEveryErrorCode) {
    std::set<std::string_view> covered;
    for (const HostileRow& row : hostile_rows()) covered.insert(to_string(row.code));
    for (int code = 0; code <= static_cast<int>(Code::field_out_of_range); ++code) {
        EXPECT_TRUE(covered.count(to_string(static_cast<Code>(code)))) << to_string(static_cast<Code>(code));
    }
}

TEST(ParseErrorCode, NamesAreDistinctSnakeCase) {
    std::set<std::string_view> names;
    for (int code = 0; code <= static_cast<int>(Code::field_out_of_range); ++code) {
        const std::string_view name = to_string(static_cast<Code>(code));
        EXPECT_EQ(name.find_first_not_of("abcdefghijklmnopqrstuvwxyz_"), std::string_view::npos);
        names.insert(name);
    }
    EXPECT_EQ(names.size(), static_cast<std::size_t>(Code::field_out_of_range) + 1);
}

// ---------------------------------------------------------------------------
// Good sentences, values worked out by hand.

// The decoded data by value (so that it may outlive the ParseResult), or an
// empty T and a test failure.
template <class T>
T decoded_as(const ParseResult& result) {
    if (!result.ok()) {
        ADD_FAILURE() << "rejected: " << result.error->message;
        return T{};
    }
    const T* data = std::get_if<T>(&result.sentence->data);
    if (data == nullptr) {
        ADD_FAILURE() << "decoded as another type: " << result.sentence->type;
        return T{};
    }
    return *data;
}

TEST(GoodSentence, GgaDocumentationExample) {
    const ParseResult result = parse_sentence("$GPGGA,123519,4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,*47");
    const auto gga = decoded_as<GgaData>(result);
    ASSERT_TRUE(result.ok());
    EXPECT_EQ(result.sentence->talker, "GP");
    EXPECT_EQ(result.sentence->type, "GGA");
    EXPECT_EQ(gga.utc_time, (UtcTime{12, 35, 19.0}));
    ASSERT_TRUE(gga.position);
    EXPECT_DOUBLE_EQ(gga.position->lat_deg, 48.1173);             // 48 + 7.038/60
    EXPECT_DOUBLE_EQ(gga.position->lon_deg, 11.516666666666667);  // 11 + 31/60
    EXPECT_EQ(gga.fix_quality, 1);
    EXPECT_EQ(gga.satellites_used, 8);
    EXPECT_EQ(gga.hdop, 0.9);
    EXPECT_EQ(gga.altitude_msl_m, 545.4);
    EXPECT_EQ(gga.geoid_separation_m, 46.9);
    EXPECT_FALSE(gga.differential_age_s);
    EXPECT_FALSE(gga.differential_station_id);
}

TEST(GoodSentence, RtkGgaWithEightDecimalMinutesIsLongerThan82) {
    // nmea-fuzzy-cases.log: Trimble, RTK fixed, 93 characters with CR LF.
    const std::string line =
        "$GNGGA,133900.00,4134.50180323,N,09345.03586581,W,4,19,0.7,280.827,M,-31.442,M,6.0,0002*61"
        "\r\n";
    const ParseResult result = parse_sentence(line);
    const auto gga = decoded_as<GgaData>(result);
    ASSERT_TRUE(gga.position);
    EXPECT_DOUBLE_EQ(gga.position->lat_deg, 41.575030053833333);  // 41 + 34.50180323/60
    EXPECT_DOUBLE_EQ(gga.position->lon_deg, -93.7505977635);      // -(93 + 45.03586581/60)
    EXPECT_EQ(gga.utc_time, (UtcTime{13, 39, 0.0}));
    EXPECT_EQ(gga.fix_quality, 4);
    EXPECT_EQ(gga.satellites_used, 19);
    EXPECT_EQ(gga.altitude_msl_m, 280.827);
    EXPECT_EQ(gga.geoid_separation_m, -31.442);
    EXPECT_EQ(gga.differential_age_s, 6.0);
    EXPECT_EQ(gga.differential_station_id, 2);

    // The same sentence under strict NMEA 0183 length rules.
    const ParseResult strict = parse_sentence(line, ParseOptions{kNmeaMaxSentenceLength});
    ASSERT_FALSE(strict.ok());
    EXPECT_EQ(strict.error->code, Code::line_too_long);
}

TEST(GoodSentence, LengthLimitIsInclusive) {
    EXPECT_TRUE(parse_sentence(sentence_of_length(kDefaultMaxSentenceLength)).ok());
    EXPECT_TRUE(parse_sentence(sentence_of_length(82), ParseOptions{82}).ok());
    EXPECT_FALSE(parse_sentence(sentence_of_length(83), ParseOptions{82}).ok());
}

TEST(GoodSentence, GgaWithoutFixHasNoPosition) {
    // hemi.log: everything empty but the quality and the units.
    const ParseResult empty = parse_sentence("$GPGGA,,,,,,0,,,,M,,M,,*66");
    const auto hemi = decoded_as<GgaData>(empty);
    EXPECT_EQ(hemi.fix_quality, 0);
    EXPECT_FALSE(hemi.utc_time);
    EXPECT_FALSE(hemi.position);
    EXPECT_FALSE(hemi.altitude_msl_m);

    // beidou-bd.log: SiRF's 15-field GGA (one more than NMEA) before the first fix.
    const ParseResult sirf = parse_sentence("$GNGGA,074150.799,,,,,0,00,,,M,0.0,M,,0000,*64");
    const auto gga = decoded_as<GgaData>(sirf);
    EXPECT_EQ(gga.utc_time, (UtcTime{7, 41, 50.799}));
    EXPECT_FALSE(gga.position);
    EXPECT_EQ(gga.satellites_used, 0);
    EXPECT_EQ(gga.geoid_separation_m, 0.0);
    EXPECT_EQ(gga.differential_station_id, 0);
}

TEST(GoodSentence, ExtraTrailingGgaFieldIsTolerated) {
    const ParseResult result =
        parse_sentence("$GNGGA,074155.799,3114.8770,N,12135.2463,E,1,05,1.3,156.9,M,8.3,M,,0000,4.9*77");
    const auto gga = decoded_as<GgaData>(result);
    ASSERT_TRUE(gga.position);
    EXPECT_DOUBLE_EQ(gga.position->lat_deg, 31.24795);            // 31 + 14.877/60
    EXPECT_DOUBLE_EQ(gga.position->lon_deg, 121.58743833333333);  // 121 + 35.2463/60
}

TEST(GoodSentence, RmcDocumentationExample) {
    const ParseResult result =
        parse_sentence("$GPRMC,123519,A,4807.038,N,01131.000,E,022.4,084.4,230394,003.1,W*6A\r\n");
    const auto rmc = decoded_as<RmcData>(result);
    EXPECT_EQ(rmc.utc_time, (UtcTime{12, 35, 19.0}));
    EXPECT_EQ(rmc.status, DataStatus::valid);
    ASSERT_TRUE(rmc.position);
    EXPECT_DOUBLE_EQ(rmc.position->lat_deg, 48.1173);
    EXPECT_DOUBLE_EQ(rmc.position->lon_deg, 11.516666666666667);
    EXPECT_EQ(rmc.speed_knots, 22.4);
    ASSERT_TRUE(rmc.speed_m_s);
    EXPECT_DOUBLE_EQ(*rmc.speed_m_s, 11.523555555555555);  // 22.4 * 1852 / 3600
    EXPECT_EQ(rmc.course_true_deg, 84.4);
    EXPECT_EQ(rmc.date, (Date{1994, 3, 23}));
    EXPECT_EQ(rmc.magnetic_variation_deg, -3.1);  // 3.1 W
    EXPECT_FALSE(rmc.mode);                       // NMEA 2.0: 11 fields, no mode
}

TEST(GoodSentence, RmcWithLeadingBlankAndCrLf) {
    // beidou-bd.log line 78 starts with a space.
    const ParseResult result =
        parse_sentence(" $GNRMC,074157.799,A,3114.8902,N,12135.2443,E,0.32,4.94,250215,,,A*7F\r\n");
    const auto rmc = decoded_as<RmcData>(result);
    EXPECT_EQ(result.sentence->talker, "GN");
    EXPECT_EQ(rmc.utc_time, (UtcTime{7, 41, 57.799}));
    EXPECT_EQ(rmc.date, (Date{2015, 2, 25}));
    EXPECT_EQ(rmc.mode, 'A');
    EXPECT_FALSE(rmc.magnetic_variation_deg);
}

TEST(GoodSentence, LowerCaseChecksumAndVoidRmc) {
    // magellan-ec10.log: lower-case hex, status V, NMEA 4.1 navigational status V.
    const ParseResult result = parse_sentence("$GPRMC,205150.00,V,,,,,,,,,,,V*4a");
    const auto rmc = decoded_as<RmcData>(result);
    EXPECT_EQ(rmc.status, DataStatus::invalid);
    EXPECT_FALSE(rmc.position);
    EXPECT_FALSE(rmc.date);
    EXPECT_FALSE(rmc.mode);
    EXPECT_EQ(rmc.navigational_status, 'V');
}

TEST(GoodSentence, RmcTwoDigitYearWindow) {
    EXPECT_EQ(decoded_as<RmcData>(parse_sentence(rmc_with(9, "010180"))).date, (Date{1980, 1, 1}));
    EXPECT_EQ(decoded_as<RmcData>(parse_sentence(rmc_with(9, "311299"))).date, (Date{1999, 12, 31}));
    EXPECT_EQ(decoded_as<RmcData>(parse_sentence(rmc_with(9, "010100"))).date, (Date{2000, 1, 1}));
    EXPECT_EQ(decoded_as<RmcData>(parse_sentence(rmc_with(9, "311279"))).date, (Date{2079, 12, 31}));
    EXPECT_EQ(decoded_as<RmcData>(parse_sentence(rmc_with(9, "290220"))).date, (Date{2020, 2, 29}));  // leap year
    // gp-320fw: the GPS week-0 date 1999-08-22 of a receiver after a week rollover.
    EXPECT_EQ(decoded_as<RmcData>(parse_sentence("$GPRMC,000425.00,V,0000.0000,N,00000.0000,E,,,"
                                                 "220899,,,N*4D"))
                  .date,
              (Date{1999, 8, 22}));
}

TEST(GoodSentence, LeapSecondIsATime) {
    const auto rmc = decoded_as<RmcData>(parse_sentence(rmc_with(1, "235960.50")));
    EXPECT_EQ(rmc.utc_time, (UtcTime{23, 59, 60.5}));
}

TEST(GoodSentence, Vtg) {
    const auto vtg = decoded_as<VtgData>(parse_sentence("$GPVTG,054.7,T,034.4,M,005.5,N,010.2,K*48"));
    EXPECT_EQ(vtg.course_true_deg, 54.7);
    EXPECT_EQ(vtg.course_magnetic_deg, 34.4);
    EXPECT_EQ(vtg.speed_knots, 5.5);
    EXPECT_EQ(vtg.speed_km_h, 10.2);
    ASSERT_TRUE(vtg.speed_m_s);
    EXPECT_DOUBLE_EQ(*vtg.speed_m_s, 2.8294444444444444);  // 5.5 * 1852 / 3600
    EXPECT_FALSE(vtg.mode);
}

TEST(GoodSentence, Gll) {
    const ParseResult result = parse_sentence("$GPGLL,4916.45,N,12311.12,W,225444,A,*1D");
    const auto gll = decoded_as<GllData>(result);
    ASSERT_TRUE(gll.position);
    EXPECT_DOUBLE_EQ(gll.position->lat_deg, 49.274166666666666);   // 49 + 16.45/60
    EXPECT_DOUBLE_EQ(gll.position->lon_deg, -123.18533333333333);  // -(123 + 11.12/60)
    EXPECT_EQ(gll.utc_time, (UtcTime{22, 54, 44.0}));
    EXPECT_EQ(gll.status, DataStatus::valid);
    EXPECT_FALSE(gll.mode);
}

TEST(GoodSentence, Zda) {
    const auto zda = decoded_as<ZdaData>(parse_sentence("$GPZDA,201530.00,04,07,2002,00,00*60"));
    EXPECT_EQ(zda.utc_time, (UtcTime{20, 15, 30.0}));
    EXPECT_EQ(zda.date, (Date{2002, 7, 4}));
    EXPECT_EQ(zda.local_zone_hours, 0);
    EXPECT_EQ(zda.local_zone_minutes, 0);
}

TEST(GoodSentence, Hdt) {
    const auto hdt = decoded_as<HdtData>(parse_sentence("$GPHDT,274.07,T*03"));
    EXPECT_EQ(hdt.heading_true_deg, 274.07);
    const auto empty = decoded_as<HdtData>(parse_sentence("$GPHDT,,T*1B"));  // hemi.log
    EXPECT_FALSE(empty.heading_true_deg);
}

TEST(GoodSentence, RecognisedButNotDecoded) {
    const ParseResult gsv = parse_sentence("$GPGSV,3,3,11,20,09,138,36,13,04,183,51,32,03,113,44,,,,*44");
    ASSERT_TRUE(gsv.ok());
    EXPECT_EQ(gsv.sentence->type, "GSV");
    EXPECT_FALSE(gsv.sentence->is_decoded());
    EXPECT_FALSE(gsv.sentence->is_proprietary());
    EXPECT_EQ(std::get<UndecodedData>(gsv.sentence->data).fields.size(), 19U);

    const ParseResult txt = parse_sentence("$GPTXT,01,01,02,ANTSTATUS=OK*3B");
    ASSERT_TRUE(txt.ok());
    EXPECT_EQ(std::get<UndecodedData>(txt.sentence->data).fields,
              (std::vector<std::string>{"01", "01", "02", "ANTSTATUS=OK"}));

    const ParseResult sirf = parse_sentence("$PSRF151,3,1833,28692,0x7EFFFFFF*15");
    ASSERT_TRUE(sirf.ok());
    EXPECT_TRUE(sirf.sentence->is_proprietary());
    EXPECT_EQ(sirf.sentence->talker, "P");
    EXPECT_EQ(sirf.sentence->type, "SRF151");
    EXPECT_EQ(std::get<UndecodedData>(sirf.sentence->data).fields,
              (std::vector<std::string>{"3", "1833", "28692", "0x7EFFFFFF"}));
}

TEST(Checksum, XorOfBody) {
    EXPECT_EQ(nmea_checksum(""), 0);
    EXPECT_EQ(nmea_checksum("GPHDT,,T"), 0x1B);  // hemi.log: $GPHDT,,T*1B
    EXPECT_EQ(nmea_checksum("GPGGA,123519,4807.038,N,01131.000,E,1,08,0.9,545.4,M,46.9,M,,"), 0x47);
}

// ---------------------------------------------------------------------------
// Damaged sentences: whatever the damage, exactly one of sentence / error is set,
// an error has a message, and nothing crashes (the sanitizer build checks reads).

TEST(Robustness, MutatedSentencesNeverCrash) {
    const std::vector<std::string> seeds{
        "$GNGGA,133900.00,4134.50180323,N,09345.03586581,W,4,19,0.7,280.827,M,-31.442,M,6.0,0002*61",
        "$GPRMC,123519,A,4807.038,N,01131.000,E,022.4,084.4,230394,003.1,W*6A",
        "$GPVTG,054.7,T,034.4,M,005.5,N,010.2,K*48",
        "$GPGLL,4916.45,N,12311.12,W,225444,A,*1D",
        "$GPZDA,201530.00,04,07,2002,00,00*60",
        "$GPHDT,274.07,T*03",
        "$PSRF151,3,1833,28692,0x7EFFFFFF*15",
    };
    std::mt19937 random(20240611);
    std::uniform_int_distribution<int> any_byte(0, 255);
    int accepted = 0;
    constexpr int kMutations = 200000;
    for (int i = 0; i < kMutations; ++i) {
        std::string line = seeds[static_cast<std::size_t>(i) % seeds.size()];
        const int edits = 1 + i % 4;
        for (int e = 0; e < edits && !line.empty(); ++e) {
            const std::size_t at = static_cast<std::size_t>(random()) % line.size();
            switch (random() % 4) {
                case 0: line[at] = static_cast<char>(any_byte(random)); break;
                case 1: line.erase(at, 1); break;
                case 2: line.insert(at, 1, ",.*$09AZ"[random() % 8]); break;
                default: line.resize(at); break;
            }
        }
        const ParseResult result = parse_sentence(line);
        ASSERT_NE(result.sentence.has_value(), result.error.has_value()) << line;
        if (result.error) {
            ASSERT_FALSE(result.error->message.empty()) << line;
        } else {
            ++accepted;
        }
    }
    // A few mutations leave a valid sentence (e.g. two edits whose XORs cancel);
    // what matters here is that none crashes.  The count is recorded for reading.
    RecordProperty("accepted_mutations", accepted);
}

}  // namespace
}  // namespace rig::nmea
