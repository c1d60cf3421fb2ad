// The trace's JSON text (harness/trace/trace_json.h) is written straight from each
// sample, without a JSON object in between. The trace digest is taken over that
// text, so it must be exactly what nlohmann::json::dump() gives: keys in
// order, nlohmann's number format (shortest round-trip digits, "1.0",
// "1e-07", null for a non-finite value), its string escapes. Each type is
// filled with awkward values and its text compared with the dump of its own
// parse: any difference in order, format or escape shows there. The values
// must also come back: a field written under a wrong name or from a wrong
// member fails on them.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <set>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "harness/trace/trace_cdr.h"
#include "harness/trace/trace_json.h"

namespace {

using rig::harness::cdr_hex_json_text;
using rig::harness::to_json_text;
namespace msg = rig::msg;

// Doubles that stress each branch of nlohmann's formatting.
const std::vector<double> kAwkwardDoubles = {
    0.0,   -0.0,    1.0,     -1.0,   0.1,     1.0 / 3.0, 123456789.125, 1e-7, 1e-4,  1.5e-5, 1e15, 1e16,
    1e21,  1e300,   -2.5e-300, 5e-324, std::numeric_limits<double>::max(), 6.02214076e23, 20.000000000000004,
    std::nan(""), std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity()};

// The text is nlohmann's canonical dump of itself, and parses.
nlohmann::json canonical(const std::string& text) {
    const nlohmann::json parsed = nlohmann::json::parse(text);
    EXPECT_EQ(parsed.dump(), text);
    return parsed;
}

// What nlohmann's dump gives for one double (the reference for each value).
std::string dumped(double value) { return nlohmann::json(value).dump(); }

TEST(TraceJsonText, IsNlohmannsDumpForAnExampleOfEachKind) {
    msg::EncoderCount encoder;
    encoder.count_pulses(5);
    encoder.last_edge_capture_us(4294967295u);
    EXPECT_EQ(to_json_text(encoder), R"({"count_pulses":5,"last_edge_capture_us":4294967295})");

    msg::BallValveRelays relays;
    relays.forward(true);
    relays.reverse(false);
    EXPECT_EQ(to_json_text(relays), R"({"forward":true,"reverse":false})");

    msg::AnalogInput analog;
    analog.voltage_v(2.0);
    EXPECT_EQ(to_json_text(analog), R"({"voltage_v":2.0})");
}

TEST(TraceJsonText, EveryDoubleIsWrittenAsNlohmannWritesIt) {
    for (const double value : kAwkwardDoubles) {
        SCOPED_TRACE(dumped(value));
        msg::VehicleTruth truth;
        truth.along_m(value);
        truth.lat_deg(-value);
        truth.pass_index(3);
        const std::string text = to_json_text(truth);
        const nlohmann::json parsed = canonical(text);
        EXPECT_NE(text.find("\"along_m\":" + dumped(value)), std::string::npos) << text;
        if (std::isfinite(value)) {
            EXPECT_EQ(parsed.at("along_m").get<double>(), value);
            EXPECT_EQ(parsed.at("lat_deg").get<double>(), -value);
        } else {
            EXPECT_TRUE(parsed.at("along_m").is_null());
        }
        EXPECT_EQ(parsed.at("pass_index"), 3);
    }
}

TEST(TraceJsonText, StringsAreEscapedAsNlohmannEscapesThem) {
    // SerialLine holds 64 characters: every ASCII character but NUL, in two halves.
    std::string low, high;
    for (int c = 1; c < 0x40; ++c) low += static_cast<char>(c);
    for (int c = 0x40; c < 0x80; ++c) high += static_cast<char>(c);
    const std::vector<std::string> texts = {
        "$GPGGA,092750.000,5321.6802,N,00630.3372,W,1,8,1.03,61.7,M*76",
        low,
        high,
        "quote \" backslash \\ tab \t bell \a escape \x1b del \x7f",
        "caf\xc3\xa9 \xe2\x82\xac",  // UTF-8: handed to nlohmann itself
        "",
    };
    for (const std::string& text : texts) {
        msg::SerialLine line;
        line.text(text);
        const nlohmann::json parsed = canonical(to_json_text(line));
        EXPECT_EQ(parsed.at("text"), text);
    }
    // A line end is not part of the recorded line, as before.
    msg::NmeaSentence sentence;
    sentence.sentence("$GNRMC,1*00\r\n");
    EXPECT_EQ(to_json_text(sentence), R"({"sentence":"$GNRMC,1*00"})");
    // Bytes that are not UTF-8 are refused by nlohmann, as they always were.
    msg::SerialLine broken;
    broken.text("bad \xff byte");
    EXPECT_THROW(to_json_text(broken), nlohmann::json::exception);
}

// One sample of each larger type, with awkward values.
msg::HydraulicsTruth awkward_hydraulics() {
    msg::HydraulicsTruth hydraulics;
    hydraulics.time_ns(-1);
    hydraulics.pump_flow_l_min(20.000000000000004);
    hydraulics.valve_opening_pct(1e-7);
    hydraulics.main_flow_l_min(1e21);
    hydraulics.main_volume_l(-0.0);
    hydraulics.sections_commanded_mask(65535);
    hydraulics.sections_spraying_mask(7);
    hydraulics.unloading_open(true);
    hydraulics.nozzles_spraying(24);
    return hydraulics;
}

msg::ControllerStatus awkward_status() {
    msg::ControllerStatus status;
    status.time_ns(std::numeric_limits<std::int64_t>::max());
    status.positioning_mode(msg::RTK_ONLY);
    status.spray_phase(msg::SPRAY_REGULATING);
    status.gnss_fix_quality(4);
    status.nmea_rejected_count(12);
    status.speed_km_h(6.0);
    status.boom_height_m(0.5);
    return status;
}

msg::BreakpointEvent awkward_event() {
    msg::BreakpointEvent event;
    event.breakpoint_id(9);
    event.kind(msg::SPRAY_RESUMED);
    event.lat_deg(31.123456789012);
    return event;
}

msg::Vehicle2dTruth awkward_vehicle2d() {
    msg::Vehicle2dTruth vehicle;
    vehicle.antenna_velocity_north_m_s(-1.0 / 3.0);
    vehicle.boom_centre_north_m(1e-300);
    return vehicle;
}

msg::NozzlesTruth awkward_nozzles() {
    msg::NozzlesTruth nozzles;
    nozzles.time_ns(5);
    for (int i = 0; i < 3; ++i) {
        msg::NozzleTruth nozzle;
        nozzle.east_m(i * 0.1);
        nozzle.duty_pct(100.0 / (i + 1));
        nozzle.opening(i == 1);
        nozzles.nozzles().push_back(nozzle);
    }
    return nozzles;
}

msg::VisionReport awkward_report() {
    msg::VisionReport report;
    report.time_ns(200'000'000);
    report.camera(1);
    report.frame_number(4294967295u);
    report.status("dark_frame");
    report.threshold(-1);
    report.speed_m_s(1.0 / 3.0);
    for (int i = 3; i < 6; ++i) {
        msg::NozzleDensityReport nozzle;
        nozzle.nozzle(static_cast<std::uint16_t>(i));
        nozzle.measured(i != 4);
        nozzle.density(i == 5 ? 5e-324 : 0.5625);
        nozzle.level(static_cast<std::int16_t>(i == 4 ? -1 : 2));
        report.nozzles().push_back(nozzle);
    }
    return report;
}

msg::CameraViewTruth awkward_view() {
    msg::CameraViewTruth view;
    view.time_ns(-7);
    view.camera(0);
    view.frame_number(12);
    view.delivered(true);
    view.rgb_sha256(std::string(64, 'f'));
    view.boom_height_m(0.5);
    msg::NozzleRoiTruth roi;
    roi.nozzle(2);
    roi.density(0.1 + 0.2);
    roi.roi_centre_east_m(-1e21);
    roi.roi_centre_north_m(1e-7);
    view.nozzles().push_back(roi);
    return view;
}

TEST(TraceJsonText, EveryTypeIsCanonicalAndKeepsItsValues) {
    const msg::HydraulicsTruth hydraulics = awkward_hydraulics();
    nlohmann::json parsed = canonical(to_json_text(hydraulics));
    EXPECT_EQ(parsed.at("time_ns"), -1);
    EXPECT_EQ(parsed.at("pump_flow_l_min").get<double>(), 20.000000000000004);
    EXPECT_EQ(parsed.at("sections_commanded_mask"), 65535);
    EXPECT_EQ(parsed.at("nozzles_spraying"), 24);
    EXPECT_EQ(parsed.size(), 9u);

    const msg::ControllerStatus status = awkward_status();
    parsed = canonical(to_json_text(status));
    EXPECT_EQ(parsed.at("time_ns"), std::numeric_limits<std::int64_t>::max());
    EXPECT_EQ(parsed.at("positioning_mode"), "rtk_only");
    EXPECT_EQ(parsed.at("spray_phase"), "regulating");
    EXPECT_EQ(parsed.at("gnss_fix_quality"), 4);
    EXPECT_EQ(parsed.at("speed_km_h"), 6.0);
    EXPECT_EQ(parsed.size(), 16u);

    const msg::BreakpointEvent event = awkward_event();
    parsed = canonical(to_json_text(event));
    EXPECT_EQ(parsed.at("kind"), "spray_resumed");
    EXPECT_EQ(parsed.at("lat_deg").get<double>(), 31.123456789012);
    EXPECT_EQ(parsed.size(), 5u);

    const msg::Vehicle2dTruth vehicle = awkward_vehicle2d();
    parsed = canonical(to_json_text(vehicle));
    EXPECT_EQ(parsed.at("antenna_velocity_north_m_s").get<double>(), -1.0 / 3.0);
    EXPECT_EQ(parsed.size(), 17u);

    msg::NozzlesTruth nozzles = awkward_nozzles();
    parsed = canonical(to_json_text(nozzles));
    ASSERT_EQ(parsed.at("nozzles").size(), 3u);
    EXPECT_EQ(parsed.at("nozzles")[2].at("duty_pct").get<double>(), 100.0 / 3.0);
    EXPECT_EQ(parsed.at("nozzles")[2].size(), 6u);
    nozzles.nozzles().clear();
    EXPECT_EQ(to_json_text(nozzles), R"({"nozzles":[],"time_ns":5})");

    msg::NozzlePwm pwm;
    pwm.frequency_hz(9.0);
    EXPECT_EQ(to_json_text(pwm), R"({"duty_pct":[],"frequency_hz":9.0})");
    pwm.duty_pct({37.5, 0.0, 100.0, 1.0 / 3.0});
    parsed = canonical(to_json_text(pwm));
    EXPECT_EQ(parsed.at("duty_pct"), nlohmann::json({37.5, 0.0, 100.0, 1.0 / 3.0}));

    const msg::VisionReport report = awkward_report();
    parsed = canonical(to_json_text(report));
    EXPECT_EQ(parsed.at("status"), "dark_frame");
    EXPECT_EQ(parsed.at("threshold"), -1);
    EXPECT_EQ(parsed.at("frame_number"), 4294967295u);
    EXPECT_EQ(parsed.at("speed_m_s").get<double>(), 1.0 / 3.0);
    EXPECT_EQ(parsed.size(), 8u);
    ASSERT_EQ(parsed.at("nozzles").size(), 3u);
    EXPECT_EQ(parsed.at("nozzles")[1].at("measured"), false);
    EXPECT_EQ(parsed.at("nozzles")[1].at("level"), -1);
    EXPECT_EQ(parsed.at("nozzles")[2].at("density").get<double>(), 5e-324);
    EXPECT_EQ(parsed.at("nozzles")[2].size(), 4u);

    const msg::CameraViewTruth view = awkward_view();
    parsed = canonical(to_json_text(view));
    EXPECT_EQ(parsed.at("rgb_sha256"), std::string(64, 'f'));
    EXPECT_EQ(parsed.at("delivered"), true);
    EXPECT_EQ(parsed.size(), 8u);
    EXPECT_EQ(parsed.at("nozzles")[0].at("density").get<double>(), 0.1 + 0.2);
    EXPECT_EQ(parsed.at("nozzles")[0].at("roi_centre_east_m").get<double>(), -1e21);
    EXPECT_EQ(parsed.at("nozzles")[0].size(), 4u);

    EXPECT_EQ(to_json_text(msg::SectionValves{}), R"({"open_mask":0})");
    EXPECT_EQ(to_json_text(msg::UnloadingValve{}), R"({"open":false})");
    EXPECT_EQ(to_json_text(msg::SwitchLevel{}), R"({"closed":false})");
    canonical(to_json_text(msg::FlowMeterCount{}));
    EXPECT_EQ(cdr_hex_json_text({0x00, 0x01, 0xab, 0xff}), R"({"cdr_hex":"0001abff"})");
}


// The trace keeps each sample as its CDR bytes (harness/trace/trace_cdr.h): the
// writer renders the JSON text from them, and the judge builds JSON values
// from them. Both must be what the text path gives: the text byte for byte
// (the digest is over it, so golden traces keep theirs), the value equal to
// parsing that text with the same number kinds. Every recorded type, awkward values.
namespace round_trip {

using rig::harness::SampleCodec;
using rig::harness::sample_codec;
using rig::harness::sample_codec_named;

// The same JSON, and each value of the same kind (unsigned, integer, float, null).
void expect_same_kinds(const nlohmann::json& a, const nlohmann::json& b, const std::string& where) {
    ASSERT_EQ(a.type(), b.type()) << where;
    if (a.is_object()) {
        ASSERT_EQ(a.size(), b.size()) << where;
        for (const auto& [key, value] : a.items()) expect_same_kinds(value, b.at(key), where + "." + key);
    } else if (a.is_array()) {
        ASSERT_EQ(a.size(), b.size()) << where;
        for (std::size_t i = 0; i < a.size(); ++i) expect_same_kinds(a[i], b[i], where + "[" + std::to_string(i) + "]");
    } else {
        EXPECT_EQ(a.dump(), b.dump()) << where;
    }
}

class RoundTrips {
public:
    template <class Msg>
    void check(const Msg& sample) {
        const SampleCodec& codec = sample_codec<Msg>();
        SCOPED_TRACE(codec.type_name);
        covered_.insert(codec.type_name);
        EXPECT_EQ(sample_codec_named(codec.type_name), &codec);
        // After other bytes, as in the writer's queue.
        std::vector<unsigned char> bytes = {0xaa, 0xbb, 0xcc};
        codec.append_cdr(&sample, bytes);
        ASSERT_GT(bytes.size(), 3u + 4u);
        const unsigned char* cdr = bytes.data() + 3;
        const std::size_t size = bytes.size() - 3;
        const std::string text = to_json_text(sample);
        EXPECT_EQ(codec.json_text(cdr, size), text);
        const nlohmann::json value = codec.json_value(cdr, size);
        EXPECT_EQ(value.dump(), text);
        expect_same_kinds(value, nlohmann::json::parse(text), "sample");
        // Cut short: refused, naming the type, never read past the end.
        try {
            codec.json_value(cdr, size - 1 > 4 ? 5 : size - 1);
            if (size > 8) ADD_FAILURE() << "a truncated " << codec.type_name << " was decoded";
        } catch (const std::runtime_error& error) {
            EXPECT_NE(std::string(error.what()).find(codec.type_name), std::string::npos) << error.what();
        }
    }
    const std::set<std::string>& covered() const { return covered_; }

private:
    std::set<std::string> covered_;
};

TEST(TraceCdr, EveryRecordedTypeGivesTodaysTextAndItsParsedValue) {
    RoundTrips trips;
    for (const double value : kAwkwardDoubles) {
        msg::VehicleTruth truth;
        truth.time_ns(-5);
        truth.along_m(value);
        truth.lat_deg(-value);
        truth.pass_index(3);
        trips.check(truth);
        msg::AnalogInput analog;
        analog.voltage_v(value);
        trips.check(analog);
    }
    msg::NmeaSentence sentence;
    sentence.sentence("$GNRMC,1*00\r\n");
    trips.check(sentence);
    msg::SerialLine line;
    line.text("quote \" backslash \\ tab \t caf\xc3\xa9 \x7f");
    trips.check(line);
    msg::EncoderCount encoder;
    encoder.count_pulses(5);
    encoder.last_edge_capture_us(4294967295u);
    trips.check(encoder);
    msg::FlowMeterCount meter;
    meter.count_pulses(4294967295u);
    trips.check(meter);
    msg::SwitchLevel level;
    level.closed(true);
    trips.check(level);
    msg::BallValveRelays relays;
    relays.forward(true);
    trips.check(relays);
    msg::SectionValves valves;
    valves.open_mask(65535);
    trips.check(valves);
    msg::UnloadingValve unloading;
    unloading.open(true);
    trips.check(unloading);
    trips.check(awkward_hydraulics());
    msg::ControllerStatus status = awkward_status();
    trips.check(status);
    status.nozzle_to_breakpoint_m(std::nan(""));
    status.spray_phase(msg::SPRAY_APPROACH);
    trips.check(status);
    trips.check(awkward_event());
    trips.check(awkward_vehicle2d());
    msg::NozzlesTruth nozzles = awkward_nozzles();
    trips.check(nozzles);
    nozzles.nozzles().back().delivered_l(std::numeric_limits<double>::infinity());
    trips.check(nozzles);
    nozzles.nozzles().clear();
    trips.check(nozzles);  // an empty array
    msg::NozzlePwm pwm;
    pwm.frequency_hz(9.0);
    trips.check(pwm);  // no duties
    pwm.duty_pct({37.5, 0.0, 100.0, 1.0 / 3.0});
    trips.check(pwm);
    trips.check(awkward_report());
    trips.check(awkward_view());

    // Every type the trace records as bytes, no fewer.
    std::set<std::string> recorded;
#define RIG_RECORDED_NAME(Type) recorded.insert(sample_codec<msg::Type>().type_name);
    RIG_TRACE_RECORDED_TYPES(RIG_RECORDED_NAME)
#undef RIG_RECORDED_NAME
    EXPECT_EQ(trips.covered(), recorded);
    EXPECT_EQ(recorded.size(), 18u);
    // Camera frames are never samples of the trace (truth/camera_view holds their SHA-256).
    EXPECT_EQ(sample_codec_named("rig::msg::CameraFrame"), nullptr);
}

}  // namespace round_trip

}  // namespace
