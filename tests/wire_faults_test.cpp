// Wire faults as case faults (emulators/wire_faults.h, issue 14 item 4):
//  * the NMEA faults damage sentences at their rates (fixed seeds, so the
//    counts are exact; the bounds say the rates are what the parameters say),
//    deterministically, and leave every byte alone when off;
//  * every damaged sentence the rig's NMEA parser sees is rejected, except the
//    ones the injector itself counts as passing (NMEA's XOR checksum);
//  * the reference controller counts the bad sentences and never takes a
//    position from one;
//  * the Modbus RTU line noise hits responses at its rates, and each hit
//    response fails its CRC.
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "controller/controller_config.h"
#include "controller/spray_controller.h"
#include "controller/wired_board_controller.h"
#include "emulators/wire_faults.h"
#include "rig/nmea/nmea_encoder.h"
#include "rig/nmea/nmea_parser.h"
#include "rig/wire/modbus_protocol.h"

namespace {

using rig::emulators::NmeaWireFaultRates;
using rig::emulators::NmeaWireFaults;
using rig::emulators::RtuLineNoise;
using rig::emulators::RtuLineNoiseRates;

rig::nmea::GnssFix fix_at(double seconds_of_day, double lat_deg, double lon_deg) {
    rig::nmea::GnssFix fix;
    fix.year = 2023;
    fix.month = 7;
    fix.day = 15;
    fix.utc_seconds_of_day = seconds_of_day;
    fix.lat_deg = lat_deg;
    fix.lon_deg = lon_deg;
    fix.altitude_msl_m = 50.0;
    fix.fix_quality = 4;
    fix.satellites = 18;
    fix.hdop = 0.7;
    fix.speed_m_s = 6.0 / 3.6;
    fix.course_deg = 90.0;
    fix.differential_age_s = 1.0;
    fix.station_id = 1;
    return fix;
}

// A 5 Hz stream of GGA and RMC, as the G970II sends, moving east.
std::vector<std::string> receiver_stream(int epochs) {
    std::vector<std::string> sentences;
    for (int k = 0; k < epochs; ++k) {
        const auto fix = fix_at(7200.0 + 0.2 * k, 40.18, 116.44 + 1e-7 * k);
        sentences.push_back(rig::nmea::encode_gga("GP", fix));
        sentences.push_back(rig::nmea::encode_rmc("GP", fix));
    }
    return sentences;
}

// |observed - expected| within 5 standard deviations of a binomial count: a
// wrong rate (off by a factor, or per sentence instead of per byte) lands far
// outside; the seed is fixed, so the count itself never changes between runs.
void expect_binomial(std::uint64_t observed, double trials, double probability, const char* what) {
    const double expected = trials * probability;
    const double sd = std::sqrt(trials * probability * (1.0 - probability));
    EXPECT_NEAR(static_cast<double>(observed), expected, 5.0 * sd) << what << ": " << observed << " of " << trials;
}

TEST(NmeaWireFaults, OffLeavesEveryByteAlone) {
    NmeaWireFaults faults(NmeaWireFaultRates{}, 1);
    for (const std::string& sentence : receiver_stream(100)) EXPECT_EQ(faults.apply(sentence), sentence);
    EXPECT_EQ(faults.counts().sentences, 200u);
    EXPECT_EQ(faults.counts().sentences_damaged, 0u);
    EXPECT_EQ(faults.counts().bytes_lost, 0u);
}

TEST(NmeaWireFaults, SameSeedSameBytesAnotherSeedOthers) {
    const NmeaWireFaultRates rates{1.0, 10.0, 10.0};
    NmeaWireFaults first(rates, 7);
    NmeaWireFaults second(rates, 7);
    NmeaWireFaults other(rates, 8);
    std::size_t differ = 0;
    for (const std::string& sentence : receiver_stream(500)) {
        const std::string bytes = first.apply(sentence);
        EXPECT_EQ(second.apply(sentence), bytes);
        if (other.apply(sentence) != bytes) ++differ;
    }
    EXPECT_GT(differ, 100u);
}

TEST(NmeaWireFaults, ByteLossIsPerByteAtItsRate) {
    NmeaWireFaults faults(NmeaWireFaultRates{2.0, 0.0, 0.0}, 3);
    std::uint64_t bytes = 0;
    for (const std::string& sentence : receiver_stream(1000)) {
        bytes += sentence.size();
        const std::string wire = faults.apply(sentence);
        EXPECT_LE(wire.size(), sentence.size());
    }
    expect_binomial(faults.counts().bytes_lost, static_cast<double>(bytes), 0.02, "bytes lost");
    // A sentence is damaged when any of its ~75 bytes is: far more than 2 % of them.
    EXPECT_GT(faults.counts().sentences_damaged, 2000u * 0.6);
}

TEST(NmeaWireFaults, CorruptChecksumsAreWrongAndOnlyTheChecksumChanges) {
    NmeaWireFaults faults(NmeaWireFaultRates{0.0, 20.0, 0.0}, 4);
    std::uint64_t mismatches = 0;
    for (const std::string& sentence : receiver_stream(2500)) {
        const std::string wire = faults.apply(sentence);
        ASSERT_EQ(wire.size(), sentence.size());
        if (wire == sentence) continue;
        const std::size_t star = sentence.rfind('*');
        EXPECT_EQ(wire.substr(0, star + 1), sentence.substr(0, star + 1));  // the text is intact
        const auto parsed = rig::nmea::parse_sentence(wire);
        ASSERT_FALSE(parsed.ok()) << wire;
        if (parsed.error->code == rig::nmea::ParseErrorCode::checksum_mismatch) ++mismatches;
    }
    expect_binomial(faults.counts().checksums_corrupted, 5000, 0.20, "checksums corrupted");
    EXPECT_EQ(mismatches, faults.counts().checksums_corrupted);
    EXPECT_EQ(faults.counts().sentences_damaged_parsed, 0u);
}

TEST(NmeaWireFaults, TruncatedSentencesStopBeforeTheirChecksumEnds) {
    NmeaWireFaults faults(NmeaWireFaultRates{0.0, 0.0, 25.0}, 5);
    std::uint64_t rejected = 0;
    for (const std::string& sentence : receiver_stream(2500)) {
        const std::string wire = faults.apply(sentence);
        if (wire == sentence) continue;
        ASSERT_FALSE(wire.empty());
        EXPECT_EQ(sentence.compare(0, wire.size(), wire), 0) << "a prefix of the sentence";
        EXPECT_LT(wire.size(), sentence.rfind('*') + 3) << "the checksum's last digit is cut";
        if (!rig::nmea::parse_sentence(wire).ok()) ++rejected;
    }
    expect_binomial(faults.counts().sentences_truncated, 5000, 0.25, "sentences truncated");
    EXPECT_EQ(rejected, faults.counts().sentences_truncated);
}

// A sentence without its line end (CR, LF or both).
std::string text_of(std::string sentence) {
    while (!sentence.empty() && (sentence.back() == '\r' || sentence.back() == '\n')) sentence.pop_back();
    return sentence;
}

// Every damaged sentence is rejected by the rig's parser, or counted by the
// injector as one that passes (lost bytes whose XOR cancels): the two add up.
TEST(NmeaWireFaults, ParserRejectsEveryDamagedSentenceTheInjectorDoesNotCountAsPassing) {
    NmeaWireFaults faults(NmeaWireFaultRates{1.0, 5.0, 5.0}, 6);
    std::uint64_t rejected = 0;
    std::uint64_t crlf_only = 0;
    for (const std::string& sentence : receiver_stream(3000)) {
        const std::string wire = faults.apply(sentence);
        if (wire == sentence || wire.empty()) continue;
        if (!rig::nmea::parse_sentence(wire).ok()) {
            ++rejected;
        } else if (text_of(wire) == text_of(sentence)) {
            ++crlf_only;  // only CR or LF lost: the text is whole
        }
    }
    const auto& counts = faults.counts();
    EXPECT_EQ(rejected + crlf_only + counts.sentences_damaged_parsed + counts.sentences_lost, counts.sentences_damaged);
    EXPECT_GT(rejected, 1000u);
}

TEST(NmeaWireFaults, RatesOutsideZeroToHundredAreRefused) {
    EXPECT_THROW(NmeaWireFaults(NmeaWireFaultRates{-1.0, 0.0, 0.0}, 1), std::invalid_argument);
    EXPECT_THROW(NmeaWireFaults(NmeaWireFaultRates{0.0, 101.0, 0.0}, 1), std::invalid_argument);
    EXPECT_THROW(NmeaWireFaults(NmeaWireFaultRates{0.0, 0.0, std::nan("")}, 1), std::invalid_argument);
    EXPECT_THROW(RtuLineNoise(RtuLineNoiseRates{200.0, 0.0}, 1), std::invalid_argument);
}

// ---------------------------------------------------------------- the reference controller

std::filesystem::path fresh_state_dir(const std::string& name) {
    // Under GoogleTest's temp dir (scripts/test's scratch folder), like every other test's files.
    const auto dir = std::filesystem::path(::testing::TempDir()) / ("wire-faults-test-" + name + "-" + std::to_string(::getpid()));
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    return dir;
}

// Where the controller stores a breakpoint when the button is pressed after
// `lines` (nullopt: it stored none).
std::optional<double> stored_lon_after(const std::vector<std::string>& lines, const std::string& name,
                                       std::uint32_t* rejected = nullptr) {
    rig::controller::SprayController controller(rig::controller::ControllerConfig{}, fresh_state_dir(name));
    controller.start(0);
    rig::TimeNs t = 0;
    for (const std::string& line : lines) controller.on_nmea_sentence(line, t += 1'000'000);
    controller.on_breakpoint_button(true, t += 1'000'000);
    if (rejected != nullptr) *rejected = controller.rejected_sentences();
    for (const auto& event : controller.take_events()) {
        if (event.kind() == rig::msg::BREAKPOINT_STORED) return event.lon_deg();
    }
    return std::nullopt;
}

// The controller takes its position from the last GGA it accepted: a damaged
// GGA at another place (100 m east) must leave it where the good one said.
TEST(ControllerUnderWireFaults, CountsBadSentencesAndNeverTakesAPositionFromOne) {
    const auto here = fix_at(7200.0, 40.18, 116.44);
    const auto far = fix_at(7200.2, 40.18, 116.44 + 100.0 / 85000.0);
    const std::vector<std::string> good = {rig::nmea::encode_gga("GP", here), rig::nmea::encode_rmc("GP", here)};
    const auto reference = stored_lon_after(good, "reference");
    ASSERT_TRUE(reference.has_value());

    auto with_far_gga = good;
    with_far_gga.push_back(rig::nmea::encode_gga("GP", far));
    const auto moved = stored_lon_after(with_far_gga, "moved");
    ASSERT_TRUE(moved.has_value());
    ASSERT_GT(std::abs(*moved - *reference), 50.0 / 85000.0) << "a good far GGA moves the breakpoint";

    struct Damage {
        const char* name;
        NmeaWireFaultRates rates;
    };
    for (const Damage& damage : {Damage{"corrupt-checksum", {0.0, 100.0, 0.0}}, Damage{"truncated", {0.0, 0.0, 100.0}},
                                 Damage{"byte-loss", {20.0, 0.0, 0.0}}}) {
        NmeaWireFaults faults(damage.rates, 11);
        auto lines = good;
        const std::string damaged = faults.apply(rig::nmea::encode_gga("GP", far));
        ASSERT_FALSE(rig::nmea::parse_sentence(damaged).ok()) << damage.name << ": " << damaged;
        lines.push_back(damaged);
        std::uint32_t rejected = 0;
        const auto stored = stored_lon_after(lines, damage.name, &rejected);
        ASSERT_TRUE(stored.has_value()) << damage.name;
        EXPECT_EQ(*stored, *reference) << damage.name;
        EXPECT_EQ(rejected, 1u) << damage.name;
    }
}

// On the serial line a truncated sentence has no CR LF: the next sentence's
// '$' follows its fragment at once. The wired controller's line framing
// starts a new line there, so the fragment alone is rejected and the whole
// sentence after it is used.
TEST(ControllerUnderWireFaults, SerialFramingStartsANewLineAtEveryDollar) {
    const auto fix = fix_at(7200.0, 40.18, 116.44);
    const std::string gga = rig::nmea::encode_gga("GP", fix);
    const std::string rmc = rig::nmea::encode_rmc("GP", fix);
    NmeaWireFaults cut(NmeaWireFaultRates{0.0, 0.0, 100.0}, 2);
    const std::string fragment = cut.apply(gga);
    std::string uart = fragment + rmc + gga.substr(0, 20);  // the last still arriving
    const std::vector<std::string> lines = rig::controller::take_nmea_lines(uart);
    ASSERT_EQ(lines.size(), 2u);
    EXPECT_EQ(lines[0], fragment);
    EXPECT_EQ(lines[1], rmc);
    EXPECT_EQ(uart, gga.substr(0, 20));
    EXPECT_FALSE(rig::nmea::parse_sentence(lines[0]).ok());
    EXPECT_TRUE(rig::nmea::parse_sentence(lines[1]).ok());
    uart += gga.substr(20);
    EXPECT_EQ(rig::controller::take_nmea_lines(uart), std::vector<std::string>{gga});
    EXPECT_TRUE(uart.empty());
}

// ---------------------------------------------------------------- Modbus RTU line noise

std::vector<std::uint8_t> read_registers_response() {
    // Slave 1, FC 04, 14 bytes (registers 0-6), CRC: what the rig's slave answers to a board's poll.
    std::vector<std::uint8_t> frame = {0x01, 0x04, 0x0E};
    for (std::uint8_t i = 0; i < 14; ++i) frame.push_back(static_cast<std::uint8_t>(i * 17));
    const std::uint16_t crc = rig::modbus::crc16_modbus(frame);
    frame.push_back(static_cast<std::uint8_t>(crc & 0xFF));
    frame.push_back(static_cast<std::uint8_t>(crc >> 8));
    return frame;
}

bool crc_holds(const std::vector<std::uint8_t>& frame) {
    return frame.size() >= 3 && rig::modbus::crc16_modbus(std::span(frame.data(), frame.size() - 2)) ==
                                    (frame[frame.size() - 2] | frame[frame.size() - 1] << 8);
}

TEST(RtuLineNoise, OffLeavesEveryFrameAlone) {
    RtuLineNoise noise(RtuLineNoiseRates{}, 1);
    const auto frame = read_registers_response();
    for (int i = 0; i < 100; ++i) EXPECT_EQ(noise.apply(frame), frame);
    EXPECT_EQ(noise.counts().responses, 100u);
    EXPECT_EQ(noise.counts().responses_corrupted + noise.counts().noise_bursts, 0u);
}

TEST(RtuLineNoise, CorruptedResponsesFailTheirCrcAtTheirRate) {
    RtuLineNoise noise(RtuLineNoiseRates{10.0, 0.0}, 2);
    const auto frame = read_registers_response();
    ASSERT_TRUE(crc_holds(frame));
    std::uint64_t failing = 0;
    for (int i = 0; i < 10'000; ++i) {
        const auto wire = noise.apply(frame);
        ASSERT_EQ(wire.size(), frame.size());
        if (!crc_holds(wire)) ++failing;
    }
    expect_binomial(noise.counts().responses_corrupted, 10'000, 0.10, "responses corrupted");
    EXPECT_EQ(failing, noise.counts().responses_corrupted);  // CRC-16 sees every one-byte error
    EXPECT_GE(noise.counts().bits_flipped, noise.counts().responses_corrupted);
}

TEST(RtuLineNoise, NoiseBurstsFollowTheResponseAtTheirRate) {
    RtuLineNoise noise(RtuLineNoiseRates{0.0, 5.0}, 3);
    const auto frame = read_registers_response();
    std::uint64_t extra = 0;
    for (int i = 0; i < 10'000; ++i) {
        const auto wire = noise.apply(frame);
        ASSERT_GE(wire.size(), frame.size());
        ASSERT_LE(wire.size(), frame.size() + RtuLineNoise::kMaxBurstBytes);
        EXPECT_TRUE(std::equal(frame.begin(), frame.end(), wire.begin())) << "the response itself is intact";
        extra += wire.size() - frame.size();
    }
    expect_binomial(noise.counts().noise_bursts, 10'000, 0.05, "noise bursts");
    EXPECT_EQ(extra, noise.counts().noise_bytes);
}

}  // namespace
