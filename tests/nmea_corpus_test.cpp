// Regression test of the NMEA parser against gpsd 3.22's decoding of ten real
// receiver logs (tests/data/gpsd-nmea, with gpsd's licence; see its README.md).
//
// How X.log.chk relates to X.log (worked out from the files):
//  - The .chk is gpsd's output in log order: every sentence gpsd's packet layer
//    accepted is echoed on its own line (CR LF and leading blanks removed),
//    followed by any JSON reports (TPV, SKY...) that sentence triggered.
//  - An echoed sentence is either a whole log line, or, where a log line holds
//    two sentences run together, the tail of that line from the embedded '$'
//    (gpsd resynchronises on '$').  Tails occur in triton400.log (line 19) and
//    gp-320fw-2019-04-07-coldboot.log (lines 35, 37, 59, 62, 74).
//  - A log line with a well-formed "*HH" whose checksum is wrong is never echoed.
//  - gpsd also echoes (accepts) sentences without any checksum ("$GP",
//    "$PLCS,...", "$GPVTG,,T,,M,2C", "$GPGSV,3,2,11,25,32,097" in gp-320fw); the
//    parser rejects these on purpose (missing_checksum).  None of them carries a
//    position or a time that a TPV then reports.
//
// Correspondence rule used for TPV reports (gpsd merges several sentences into
// one fix, so a TPV is compared with the sentences echoed before it):
//  - position: a TPV with lat/lon must equal the position of the most recent
//    echoed sentence that carried a VALID position for gpsd: GGA with fix
//    quality > 0, RMC with status A, GLL with status A (gpsd ignores positions
//    flagged invalid, e.g. the 0000.0000 of gp-320fw's void RMCs).  Its UTC
//    time of day must equal that sentence's time.
//  - time only: a TPV with a time but no lat/lon (mode 1) must have the time of
//    the most recent echoed sentence with a non-empty time (GGA, RMC, GLL, ZDA).
//  - date: the date of the most recent echoed RMC or ZDA that had one, compared
//    modulo 1024 weeks (7168 days): gpsd 3.22 "corrects" dates that look like
//    GPS week rollover victims (2013-04-01 is reported as 2032-11-15, 1999-08-22
//    as 2019-04-07); the parser reports what the wire says.
//  - tolerances: gpsd prints 9 decimals of a degree, so the parser's value must
//    be within half of 1e-9 deg plus 1e-12 deg of arithmetic slack (gpsd computes
//    degrees differently: modf(x / 100)); time within half a millisecond (gpsd
//    prints milliseconds).
// Excluded: a TPV whose position (for a time-only TPV: whose time) came from a
// tail fragment, and a date comparison whose date came from one.  The parser,
// fed whole lines, rejects such a line as two sentences run together (checked),
// so it never saw the sentence.  In this corpus that is one fix (triton400.log,
// the GLL of 03:01:31 on line 19) and one date (gp-320fw line 74, the RMC of
// 00:04:25).  The counts are printed.  TPVs that gpsd printed without a time
// (no date known yet) are compared on position only.
//
// Checksums: every log line that is a single well-formed sentence with a wrong
// "*HH" must be absent from the .chk (gpsd rejected it) and rejected by the
// parser with checksum_mismatch.  Every line gpsd echoed whole must be accepted
// by the parser, except the checksum-less ones above.  Every line of both files
// (comments, garbage and JSON included) goes through the parser once.
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <optional>
#include <sstream>
#include <string>
#include <variant>
#include <vector>

#include <nlohmann/json.hpp>

#include "rig/nmea/nmea_parser.h"

namespace rig::nmea {
namespace {

namespace fs = std::filesystem;

constexpr double kPositionToleranceDeg = 0.5e-9 + 1e-12;
constexpr double kTimeToleranceS = 0.5e-3 + 1e-9;
constexpr long kDaysPerGpsWeekRollover = 1024 * 7;

fs::path corpus_dir() { return fs::path(RIG_SOURCE_DIR) / "tests" / "data" / "gpsd-nmea"; }

std::vector<std::string> corpus_logs() {
    std::vector<std::string> names;
    std::error_code error;
    for (const auto& entry : fs::directory_iterator(corpus_dir(), error)) {
        if (entry.path().extension() == ".log") names.push_back(entry.path().filename().string());
    }
    std::sort(names.begin(), names.end());
    return names;
}

std::vector<std::string> read_lines(const fs::path& path) {
    std::ifstream file(path, std::ios::binary);
    const std::string content{std::istreambuf_iterator<char>(file), {}};
    std::vector<std::string> lines;
    std::size_t begin = 0;
    while (begin < content.size()) {
        std::size_t end = content.find('\n', begin);
        if (end == std::string::npos) end = content.size();
        lines.push_back(content.substr(begin, end - begin));
        begin = end + 1;
    }
    return lines;
}

// What gpsd echoes of a line: no leading blanks, no CR.
std::string echo_form(const std::string& raw) {
    const std::size_t begin = std::min(raw.find_first_not_of(" \t"), raw.size());
    std::size_t end = raw.size();
    while (end > begin && (raw[end - 1] == '\r' || raw[end - 1] == '\n')) --end;
    return raw.substr(begin, end - begin);
}

bool is_hex(char c) { return (c >= '0' && c <= '9') || (c >= 'A' && c <= 'F') || (c >= 'a' && c <= 'f'); }

// A single sentence "$...*HH" (printable ASCII, one '$', one '*', two hex
// digits) whose checksum does not match.  Computed here, not by the parser.
bool has_wrong_checksum(const std::string& text) {
    if (text.size() < 4 || text.front() != '$') return false;
    if (text.find_first_of("$!", 1) != std::string::npos) return false;
    const std::size_t star = text.find('*');
    if (star == std::string::npos || star + 3 != text.size()) return false;
    if (!is_hex(text[star + 1]) || !is_hex(text[star + 2])) return false;
    unsigned computed = 0;
    for (std::size_t i = 1; i < star; ++i) {
        const auto byte = static_cast<unsigned char>(text[i]);
        if (byte < 0x20 || byte > 0x7E) return false;
        computed ^= byte;
    }
    return computed != std::stoul(text.substr(star + 1), nullptr, 16);
}

struct LogLine {
    std::size_t number = 0;  // 1-based
    std::string echo_text;
    ParseResult result;
    bool echoed_whole = false;
};

struct Echo {
    std::string text;
    std::size_t log_index = 0;
    bool whole = true;  // false: the tail of a line after an embedded '$'
};

// One line of the .chk: an echoed sentence, or (echo empty) a JSON report.
struct ChkEntry {
    std::optional<Echo> echo;
    nlohmann::json report;
};

struct UtcStamp {
    std::optional<Date> date;
    double seconds_of_day = 0.0;
};

std::optional<UtcStamp> parse_iso_time(const nlohmann::json& tpv) {
    if (!tpv.contains("time")) return std::nullopt;
    const std::string text = tpv["time"].get<std::string>();
    int year = 0, month = 0, day = 0, hour = 0, minute = 0;
    double second = 0.0;
    if (std::sscanf(text.c_str(), "%d-%d-%dT%d:%d:%lfZ", &year, &month, &day, &hour, &minute, &second) != 6) {
        ADD_FAILURE() << "unreadable TPV time " << text;
        return std::nullopt;
    }
    return UtcStamp{Date{year, month, day}, hour * 3600.0 + minute * 60.0 + second};
}

long days_since_epoch(const Date& date) {
    using namespace std::chrono;
    const sys_days days{year{date.year} / month{static_cast<unsigned>(date.month)} /
                        day{static_cast<unsigned>(date.day)}};
    return static_cast<long>(days.time_since_epoch().count());
}

// The merged state gpsd's TPVs are compared against; each piece remembers
// whether it came from a tail fragment the parser never saw as a sentence.
struct PositionFix {
    Position position;
    std::optional<UtcTime> time;
    bool from_fragment = false;
    std::string sentence;
};
struct TimeOfDay {
    UtcTime time;
    bool from_fragment = false;
};
struct CalendarDate {
    Date date;
    bool from_fragment = false;
};

struct MergedState {
    std::optional<PositionFix> position;
    std::optional<TimeOfDay> time;
    std::optional<CalendarDate> date;

    void update(const Sentence& sentence, bool from_fragment, const std::string& text) {
        auto note_time = [&](const std::optional<UtcTime>& sentence_time) {
            if (sentence_time) time = TimeOfDay{*sentence_time, from_fragment};
        };
        auto note_date = [&](const std::optional<Date>& sentence_date) {
            if (sentence_date) date = CalendarDate{*sentence_date, from_fragment};
        };
        auto note_position = [&](const std::optional<Position>& sentence_position, bool valid,
                                 const std::optional<UtcTime>& sentence_time) {
            if (sentence_position && valid) {
                position = PositionFix{*sentence_position, sentence_time, from_fragment, text};
            }
        };
        if (const auto* gga = std::get_if<GgaData>(&sentence.data)) {
            note_time(gga->utc_time);
            note_position(gga->position, gga->fix_quality.value_or(0) > 0, gga->utc_time);
        } else if (const auto* rmc = std::get_if<RmcData>(&sentence.data)) {
            note_time(rmc->utc_time);
            note_date(rmc->date);
            note_position(rmc->position, rmc->status == DataStatus::valid, rmc->utc_time);
        } else if (const auto* gll = std::get_if<GllData>(&sentence.data)) {
            note_time(gll->utc_time);
            note_position(gll->position, gll->status == DataStatus::valid, gll->utc_time);
        } else if (const auto* zda = std::get_if<ZdaData>(&sentence.data)) {
            note_time(zda->utc_time);
            note_date(zda->date);
        }
    }
};

struct FileCounts {
    int tpv_with_position = 0;
    int fixes_compared = 0;
    int dates_compared = 0;
    int dates_shifted_by_rollover = 0;
    int time_only_compared = 0;
    int excluded_fixes = 0;      // position came from a tail fragment
    int excluded_time_only = 0;  // time came from a tail fragment
    int dates_skipped_fragment = 0;
    int checksum_rejections = 0;
    int checksumless_accepted_by_gpsd = 0;
    int tail_fragments = 0;
    double worst_position_error_deg = 0.0;
    double worst_time_error_s = 0.0;
};

class GpsdCorpus : public ::testing::TestWithParam<std::string> {
protected:
    void compare_date(const UtcStamp& stamp, const MergedState& state, const std::string& where, FileCounts& counts) {
        if (!stamp.date || !state.date) return;
        if (state.date->from_fragment) {
            ++counts.dates_skipped_fragment;
            return;
        }
        const long difference = days_since_epoch(*stamp.date) - days_since_epoch(state.date->date);
        EXPECT_EQ(difference % kDaysPerGpsWeekRollover, 0)
            << where << ": gpsd date " << stamp.date->year << "-" << stamp.date->month << "-" << stamp.date->day
            << ", parser " << state.date->date.year << "-" << state.date->date.month << "-" << state.date->date.day;
        ++counts.dates_compared;
        if (difference != 0) ++counts.dates_shifted_by_rollover;
    }

    void compare_time(double gpsd_seconds, const UtcTime& parsed, const std::string& where, FileCounts& counts) {
        const double error = std::fabs(gpsd_seconds - parsed.seconds_of_day());
        counts.worst_time_error_s = std::max(counts.worst_time_error_s, error);
        EXPECT_LE(error, kTimeToleranceS) << where;
    }
};

TEST_P(GpsdCorpus, ParserAgreesWithGpsd) {
    const fs::path log_path = corpus_dir() / GetParam();
    const std::vector<std::string> raw_log = read_lines(log_path);
    const std::vector<std::string> raw_chk = read_lines(fs::path(log_path.string() + ".chk"));
    ASSERT_FALSE(raw_log.empty());
    ASSERT_FALSE(raw_chk.empty());

    // Every line of both files through the parser: nothing may crash.
    std::vector<LogLine> log;
    for (std::size_t i = 0; i < raw_log.size(); ++i) {
        log.push_back(LogLine{i + 1, echo_form(raw_log[i]), parse_sentence(raw_log[i])});
        const ParseResult& result = log.back().result;
        ASSERT_NE(result.sentence.has_value(), result.error.has_value());
    }
    for (const std::string& line : raw_chk) {
        const ParseResult result = parse_sentence(line);
        ASSERT_NE(result.sentence.has_value(), result.error.has_value());
    }

    // The .chk in order, echoes matched to the log lines they came from.
    FileCounts counts;
    std::vector<ChkEntry> chk;
    std::size_t cursor = 0;
    for (const std::string& raw : raw_chk) {
        const std::string text = echo_form(raw);
        if (text.empty()) continue;
        if (text.front() == '{') {
            nlohmann::json json = nlohmann::json::parse(text, nullptr, false);
            ASSERT_FALSE(json.is_discarded()) << "bad JSON in .chk: " << text;
            chk.emplace_back().report = std::move(json);
            continue;
        }
        bool matched = false;
        for (std::size_t k = cursor; k < log.size() && !matched; ++k) {
            const std::string& candidate = log[k].echo_text;
            const bool whole = candidate == text;
            const bool tail = !whole && text.front() == '$' && candidate.size() > text.size() &&
                              candidate.compare(candidate.size() - text.size(), text.size(), text) == 0;
            if (whole || tail) {
                chk.emplace_back().echo = Echo{text, k, whole};
                log[k].echoed_whole = whole;
                cursor = k + 1;
                matched = true;
            }
        }
        ASSERT_TRUE(matched) << "echoed sentence not found in the log (in order): " << text;
    }

    // Replay: sentences update the merged state, TPVs are compared with it.
    MergedState state;
    for (const ChkEntry& entry : chk) {
        if (const std::optional<Echo>& echo = entry.echo) {
            const LogLine& line = log[echo->log_index];
            const std::string where = GetParam() + ":" + std::to_string(line.number);
            if (!echo->whole) {
                ++counts.tail_fragments;
                ASSERT_FALSE(line.result.ok()) << where;
                EXPECT_EQ(line.result.error->code, ParseErrorCode::embedded_start_delimiter) << where;
                // Parsed only to learn what gpsd took from it, so that TPVs that depend
                // on it are excluded rather than compared with stale data.
                const ParseResult fragment = parse_sentence(echo->text);
                if (fragment.ok()) state.update(*fragment.sentence, true, echo->text);
                continue;
            }
            if (line.result.ok()) {
                state.update(*line.result.sentence, false, echo->text);
            } else {
                EXPECT_EQ(echo->text.find('*'), std::string::npos)
                    << where
                    << ": gpsd accepted a sentence with a checksum the parser rejects: " << line.result.error->message;
                EXPECT_EQ(line.result.error->code, ParseErrorCode::missing_checksum) << where;
                ++counts.checksumless_accepted_by_gpsd;
            }
            continue;
        }
        const nlohmann::json& report = entry.report;
        if (report.value("class", "") != "TPV") continue;
        const std::optional<UtcStamp> stamp = parse_iso_time(report);
        const std::string where = GetParam() + " TPV " + report.dump().substr(0, 120);
        if (report.contains("lat") && report.contains("lon")) {
            ++counts.tpv_with_position;
            ASSERT_TRUE(state.position) << where << ": no decoded sentence supplied a position";
            const PositionFix& fix = *state.position;
            if (fix.from_fragment) {
                ++counts.excluded_fixes;
                continue;
            }
            const double lat_error = std::fabs(report["lat"].get<double>() - fix.position.lat_deg);
            const double lon_error = std::fabs(report["lon"].get<double>() - fix.position.lon_deg);
            counts.worst_position_error_deg = std::max({counts.worst_position_error_deg, lat_error, lon_error});
            EXPECT_LE(lat_error, kPositionToleranceDeg) << where << "\n  sentence: " << fix.sentence;
            EXPECT_LE(lon_error, kPositionToleranceDeg) << where << "\n  sentence: " << fix.sentence;
            if (stamp) {
                EXPECT_TRUE(fix.time) << where << ": gpsd has a time, the sentence had none";
                if (fix.time) compare_time(stamp->seconds_of_day, *fix.time, where, counts);
                compare_date(*stamp, state, where, counts);
            }
            ++counts.fixes_compared;
        } else if (stamp) {
            ASSERT_TRUE(state.time) << where << ": no decoded sentence supplied a time";
            if (state.time->from_fragment) {
                ++counts.excluded_time_only;
                continue;
            }
            compare_time(stamp->seconds_of_day, state.time->time, where, counts);
            compare_date(*stamp, state, where, counts);
            ++counts.time_only_compared;
        }
    }

    // Checksums: what gpsd rejected for its checksum, the parser rejects too.
    for (const LogLine& line : log) {
        if (!has_wrong_checksum(line.echo_text)) continue;
        const std::string where = GetParam() + ":" + std::to_string(line.number);
        EXPECT_FALSE(line.echoed_whole) << where << ": gpsd accepted a bad checksum?";
        ASSERT_FALSE(line.result.ok()) << where;
        EXPECT_EQ(line.result.error->code, ParseErrorCode::checksum_mismatch)
            << where << ": " << line.result.error->message;
        ++counts.checksum_rejections;
    }

    // Not vacuous: a file where gpsd reported fixes must have had fixes compared.
    if (counts.tpv_with_position > 0) {
        EXPECT_GT(counts.fixes_compared, 0);
    }

    RecordProperty("fixes_compared", counts.fixes_compared);
    RecordProperty("dates_compared", counts.dates_compared);
    RecordProperty("time_only_compared", counts.time_only_compared);
    RecordProperty("excluded_fixes", counts.excluded_fixes);
    RecordProperty("checksum_rejections", counts.checksum_rejections);
    std::ostringstream summary;
    summary << GetParam() << ": " << counts.fixes_compared << " of " << counts.tpv_with_position
            << " TPV fixes compared (lat/lon/time), " << counts.dates_compared << " dates ("
            << counts.dates_shifted_by_rollover << " shifted 1024 weeks by gpsd, " << counts.dates_skipped_fragment
            << " skipped: from a tail fragment), " << counts.time_only_compared
            << " time-only TPVs; excluded (tail fragment): " << counts.excluded_fixes << " fixes, "
            << counts.excluded_time_only << " time-only; " << counts.checksum_rejections << " bad checksums rejected, "
            << counts.checksumless_accepted_by_gpsd << " checksum-less lines gpsd accepted, " << counts.tail_fragments
            << " tail fragments; worst error " << counts.worst_position_error_deg << " deg, "
            << counts.worst_time_error_s << " s\n";
    std::cout << summary.str();
}

std::string test_name(const ::testing::TestParamInfo<std::string>& info) {
    std::string name = info.param.substr(0, info.param.rfind(".log"));
    for (char& c : name) {
        if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
    }
    return name;
}

INSTANTIATE_TEST_SUITE_P(Logs, GpsdCorpus, ::testing::ValuesIn(corpus_logs()), test_name);

TEST(GpsdCorpusFiles, AllTenLogsArePresent) {
    const std::vector<std::string> logs = corpus_logs();
    EXPECT_EQ(logs.size(), 10U) << "in " << corpus_dir();
    for (const std::string& log : logs) {
        EXPECT_TRUE(fs::exists(corpus_dir() / (log + ".chk"))) << log;
    }
}

}  // namespace
}  // namespace rig::nmea
