// Case files: a full file, defaults, and a table of broken files with the exact
// `file:line:col: key:` each must be reported at.
#include "harness/spec/case_spec.h"
#include "harness/systems/breakpoint/breakpoint_case.h"
#include "harness/systems/systems.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <sys/stat.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <functional>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "controller/controller_config.h"
#include "rig/config/config_error.h"
#include "rig/config/yaml_fields.h"

namespace rig::harness {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;

// A fresh directory per test, removed afterwards.
class TempDir {
public:
    TempDir() {
        std::random_device entropy;
        path_ = fs::temp_directory_path() /
                ("case_spec_test_" + std::to_string(::getpid()) + "_" + std::to_string(entropy()));
        fs::create_directories(path_);
    }
    ~TempDir() {
        std::error_code ignored;
        fs::remove_all(path_, ignored);
    }
    TempDir(const TempDir&) = delete;
    TempDir& operator=(const TempDir&) = delete;

    fs::path write(const std::string& name, const std::string& content) const {
        const fs::path file = path_ / name;
        std::ofstream(file, std::ios::binary) << content;
        return file;
    }
    const fs::path& path() const { return path_; }

private:
    fs::path path_;
};

// The schema's example, every key given.
constexpr const char* kFullCase = R"(name: breakpoint-6kmh-fusion-s1
description: "free text"
seed: 7
mode: realtime
utc_start: "2023-07-15T02:00:00.25Z"
field:
  origin: { lat_deg: 40.18, lon_deg: 116.44, height_m: 50.0 }
  heading_deg: 90
vehicle:
  speed_km_h: 6.0
  accel_m_s2: 0.4
  start_m: -60
  overrun_m: 7
boom: { l1_m: 0.55, l2_m: 0.85, l3_m: 0.40, linkage_rise_m: 0.6 }
breakpoint:
  along_m: 2.5
  button_at_s: 1.5
gnss:
  talker: GN
  rate_hz: 10
  latency_s: 0.05
  fix: rtk_float
  noise: { base_m: 0.01, ppm: 2.0, baseline_km: 5.0 }
  dropouts:   [ { at_s: 31.0, for_s: 0.6 }, { at_s: 40, for_s: 1 } ]
  degraded:   [ { at_s: 20.0, for_s: 2.0, fix: dgps, sigma_m: 0.3 } ]
encoder:
  pulses_per_rev: 2000
  wheel_diameter_m: 0.9
  rate_hz: 200
  slip_pct: 1.5
  slip_sd_pct: 0.5
controller:
  command: [ "rig-controller", "--verbose" ]
  positioning: fusion
  pid: { kp: 0.20, ki: 0.18, kd: 0.001 }
limits:
  breakpoint_error_m: 0.2
  overlap_m: 3.3
expect:
  fail: [ overlap_m ]
timeouts:
  node_ack_s: 20
  case_wall_s: 900
)";

// Only what has no default.
constexpr const char* kMinimalCase = R"(name: minimal
field:
  origin: { lat_deg: 40.18, lon_deg: 116.44 }
  heading_deg: 90
vehicle:
  speed_km_h: 6.0
  start_m: -60
)";

// Cases move about in vectors (a shard's selection, sorting): assigning one
// case's kept YAML over another's must not write into the nodes a third copy
// still shares (yaml-cpp's Node::operator= does), nor lose its own.
TEST(RawYaml, AssignmentTakesTheOthersNodeAndLeavesCopiesAlone) {
    RawYaml first{YAML::Load("target_flow_l_min: 15"), {}, true};
    const RawYaml copy_of_first = first;
    const RawYaml second{YAML::Load("target_flow_l_min: 17"), {}, true};
    first = second;
    EXPECT_EQ(first.node["target_flow_l_min"].as<int>(), 17);
    EXPECT_EQ(copy_of_first.node["target_flow_l_min"].as<int>(), 15);
    EXPECT_EQ(second.node["target_flow_l_min"].as<int>(), 17);

    std::vector<RawYaml> sections = {RawYaml{YAML::Load("n: 1"), {}, true}, RawYaml{YAML::Load("n: 2"), {}, true},
                                     RawYaml{YAML::Load("n: 3"), {}, true}};
    const std::vector<RawYaml> before = sections;
    std::erase_if(sections, [](const RawYaml& section) { return section.node["n"].as<int>() == 1; });
    ASSERT_EQ(sections.size(), 2u);
    EXPECT_EQ(sections[0].node["n"].as<int>(), 2);
    EXPECT_EQ(sections[1].node["n"].as<int>(), 3);
    EXPECT_EQ(before[0].node["n"].as<int>(), 1);
    EXPECT_EQ(before[1].node["n"].as<int>(), 2);
}

TEST(CaseSpec, FullFileParsesToTheWrittenValues) {
    TempDir dir;
    const fs::path file = dir.write("full.yaml", kFullCase);
    const CaseSpec spec = load_case_file(file);

    EXPECT_EQ(spec.source_path, file);
    EXPECT_EQ(spec.name, "breakpoint-6kmh-fusion-s1");
    EXPECT_EQ(spec.description, "free text");
    EXPECT_EQ(spec.seed, 7u);
    EXPECT_EQ(spec.mode, ClockMode::realtime);
    EXPECT_EQ(breakpoint_sections(spec).utc_start_iso, "2023-07-15T02:00:00.25Z");
    EXPECT_EQ(breakpoint_sections(spec).utc_start, std::chrono::sys_days{std::chrono::year{2023} / 7 / 15} + 2h + 250ms);

    EXPECT_DOUBLE_EQ(breakpoint_sections(spec).field.origin.lat_deg, 40.18);
    EXPECT_DOUBLE_EQ(breakpoint_sections(spec).field.origin.lon_deg, 116.44);
    EXPECT_DOUBLE_EQ(breakpoint_sections(spec).field.origin.height_m, 50.0);
    EXPECT_DOUBLE_EQ(breakpoint_sections(spec).field.heading_deg, 90.0);

    EXPECT_DOUBLE_EQ(breakpoint_sections(spec).vehicle.speed_km_h, 6.0);
    EXPECT_DOUBLE_EQ(breakpoint_sections(spec).vehicle.accel_m_s2, 0.4);
    EXPECT_DOUBLE_EQ(breakpoint_sections(spec).vehicle.start_m, -60.0);
    EXPECT_DOUBLE_EQ(breakpoint_sections(spec).vehicle.overrun_m, 7.0);

    EXPECT_DOUBLE_EQ(breakpoint_sections(spec).boom.l1_m, 0.55);
    EXPECT_DOUBLE_EQ(breakpoint_sections(spec).boom.l2_m, 0.85);
    EXPECT_DOUBLE_EQ(breakpoint_sections(spec).boom.l3_m, 0.40);
    EXPECT_DOUBLE_EQ(breakpoint_sections(spec).boom.linkage_rise_m, 0.6);

    EXPECT_DOUBLE_EQ(breakpoint_sections(spec).breakpoint.along_m, 2.5);
    EXPECT_DOUBLE_EQ(breakpoint_sections(spec).breakpoint.button_at_s, 1.5);

    EXPECT_EQ(breakpoint_sections(spec).gnss.talker, GnssTalker::gn);
    EXPECT_EQ(to_string(breakpoint_sections(spec).gnss.talker), "GN");
    EXPECT_DOUBLE_EQ(breakpoint_sections(spec).gnss.rate_hz, 10.0);
    EXPECT_DOUBLE_EQ(breakpoint_sections(spec).gnss.latency_s, 0.05);
    EXPECT_EQ(breakpoint_sections(spec).gnss.fix, GnssFix::rtk_float);
    EXPECT_DOUBLE_EQ(breakpoint_sections(spec).gnss.noise.base_m, 0.01);
    EXPECT_DOUBLE_EQ(breakpoint_sections(spec).gnss.noise.ppm, 2.0);
    EXPECT_DOUBLE_EQ(breakpoint_sections(spec).gnss.noise.baseline_km, 5.0);
    EXPECT_DOUBLE_EQ(breakpoint_sections(spec).gnss.noise.horizontal_sigma_m(), 0.02);
    ASSERT_EQ(breakpoint_sections(spec).gnss.dropouts.size(), 2u);
    EXPECT_DOUBLE_EQ(breakpoint_sections(spec).gnss.dropouts[0].at_s, 31.0);
    EXPECT_DOUBLE_EQ(breakpoint_sections(spec).gnss.dropouts[0].for_s, 0.6);
    EXPECT_DOUBLE_EQ(breakpoint_sections(spec).gnss.dropouts[1].at_s, 40.0);
    ASSERT_EQ(breakpoint_sections(spec).gnss.degraded.size(), 1u);
    EXPECT_DOUBLE_EQ(breakpoint_sections(spec).gnss.degraded[0].at_s, 20.0);
    EXPECT_DOUBLE_EQ(breakpoint_sections(spec).gnss.degraded[0].for_s, 2.0);
    EXPECT_EQ(breakpoint_sections(spec).gnss.degraded[0].fix, GnssFix::dgps);
    EXPECT_DOUBLE_EQ(breakpoint_sections(spec).gnss.degraded[0].sigma_m, 0.3);

    EXPECT_EQ(breakpoint_sections(spec).encoder.pulses_per_rev, 2000u);
    EXPECT_DOUBLE_EQ(breakpoint_sections(spec).encoder.wheel_diameter_m, 0.9);
    EXPECT_DOUBLE_EQ(breakpoint_sections(spec).encoder.rate_hz, 200.0);
    EXPECT_DOUBLE_EQ(breakpoint_sections(spec).encoder.slip_pct, 1.5);
    EXPECT_DOUBLE_EQ(breakpoint_sections(spec).encoder.slip_sd_pct, 0.5);

    EXPECT_EQ(spec.controller.command, (std::vector<std::string>{"rig-controller", "--verbose"}));
    ASSERT_TRUE(spec.controller.params.present);
    EXPECT_EQ(spec.controller.params.node["positioning"].as<std::string>(), "fusion");
    EXPECT_DOUBLE_EQ(spec.controller.params.node["pid"]["ki"].as<double>(), 0.18);
    EXPECT_EQ(spec.controller.params.location.file, file.string());
    EXPECT_EQ(spec.controller.params.location.line, 33);  // its first key
    EXPECT_EQ(spec.controller.params.location.key_path, "controller");

    EXPECT_EQ(spec.limits, (std::map<std::string, double>{{"breakpoint_error_m", 0.2}, {"overlap_m", 3.3}}));
    EXPECT_EQ(spec.expect.fail, (std::vector<std::string>{"overlap_m"}));
    EXPECT_DOUBLE_EQ(spec.timeouts.node_ack_s, 20.0);
    EXPECT_DOUBLE_EQ(spec.timeouts.case_wall_s, 900.0);

    // The file's limits win over the defaults.
    EXPECT_EQ(effective_limits(spec), spec.limits);
}

TEST(CaseSpec, DefaultsApplyToEverythingNotWritten) {
    TempDir dir;
    const CaseSpec spec = load_case_file(dir.write("minimal.yaml", kMinimalCase));
    const BreakpointSections defaults;

    EXPECT_EQ(spec.name, "minimal");
    EXPECT_EQ(spec.description, "");
    EXPECT_EQ(spec.seed, 1u);
    EXPECT_EQ(spec.mode, ClockMode::lockstep);
    EXPECT_EQ(breakpoint_sections(spec).utc_start, std::chrono::sys_days{std::chrono::year{2023} / 7 / 15} + 2h);
    EXPECT_DOUBLE_EQ(breakpoint_sections(spec).field.origin.height_m, 0.0);
    EXPECT_DOUBLE_EQ(breakpoint_sections(spec).vehicle.accel_m_s2, 0.5);
    EXPECT_DOUBLE_EQ(breakpoint_sections(spec).vehicle.overrun_m, 5.0);
    EXPECT_DOUBLE_EQ(breakpoint_sections(spec).boom.l1_m, 0.50);
    EXPECT_DOUBLE_EQ(breakpoint_sections(spec).boom.l2_m, 0.80);
    EXPECT_DOUBLE_EQ(breakpoint_sections(spec).boom.l3_m, 0.45);
    EXPECT_DOUBLE_EQ(breakpoint_sections(spec).boom.linkage_rise_m, 0.50);
    EXPECT_DOUBLE_EQ(breakpoint_sections(spec).breakpoint.along_m, 0.0);
    EXPECT_DOUBLE_EQ(breakpoint_sections(spec).breakpoint.button_at_s, 1.0);
    EXPECT_EQ(breakpoint_sections(spec).gnss.talker, GnssTalker::gp);
    EXPECT_DOUBLE_EQ(breakpoint_sections(spec).gnss.rate_hz, 5.0);
    EXPECT_DOUBLE_EQ(breakpoint_sections(spec).gnss.latency_s, 0.10);  // the Table 3 fit
    EXPECT_DOUBLE_EQ(breakpoint_sections(spec).encoder.deflection_pct, 3.0);
    EXPECT_EQ(breakpoint_sections(spec).gnss.fix, GnssFix::rtk_fixed);
    EXPECT_DOUBLE_EQ(breakpoint_sections(spec).gnss.noise.base_m, 0.008);
    EXPECT_DOUBLE_EQ(breakpoint_sections(spec).gnss.noise.ppm, 1.0);
    EXPECT_DOUBLE_EQ(breakpoint_sections(spec).gnss.noise.baseline_km, 2.0);
    EXPECT_TRUE(breakpoint_sections(spec).gnss.dropouts.empty());
    EXPECT_TRUE(breakpoint_sections(spec).gnss.degraded.empty());
    EXPECT_EQ(breakpoint_sections(spec).encoder.pulses_per_rev, 1000u);
    EXPECT_DOUBLE_EQ(breakpoint_sections(spec).encoder.wheel_diameter_m, 1.0);
    EXPECT_DOUBLE_EQ(breakpoint_sections(spec).encoder.rate_hz, 100.0);
    EXPECT_DOUBLE_EQ(breakpoint_sections(spec).encoder.slip_pct, defaults.encoder.slip_pct);
    EXPECT_DOUBLE_EQ(breakpoint_sections(spec).encoder.slip_sd_pct, defaults.encoder.slip_sd_pct);
    EXPECT_TRUE(spec.controller.command.empty());
    EXPECT_FALSE(spec.controller.params.present);
    EXPECT_TRUE(spec.limits.empty());
    EXPECT_TRUE(spec.expect.fail.empty());
    EXPECT_DOUBLE_EQ(spec.timeouts.node_ack_s, 10.0);
    EXPECT_DOUBLE_EQ(spec.timeouts.case_wall_s, 600.0);
    // An identification case measures only the breakpoint error of the defaults.
    EXPECT_EQ(breakpoint_sections(spec).scenario_kind, Scenario::breakpoint_identification);
    EXPECT_EQ(effective_limits(spec), (std::map<std::string, double>{{"breakpoint_error_m", 0.20}}));
    // The sprayer is on autosteer unless the case says `guidance: off` (docs/guidance.md).
    ASSERT_TRUE(breakpoint_sections(spec).guidance.has_value());
    EXPECT_DOUBLE_EQ(breakpoint_sections(spec).guidance->roll_sd_deg, rig::emulators::guidance::GuidanceParams{}.roll_sd_deg);
    EXPECT_DOUBLE_EQ(breakpoint_sections(spec).antenna.height_m, defaults.antenna.height_m);
    const CaseSpec exact = load_case_file(dir.write("exact.yaml", std::string(kMinimalCase) + "guidance: off\n"));
    EXPECT_FALSE(breakpoint_sections(exact).guidance.has_value());
}

TEST(CaseSpec, DefaultLimitsFollowWhatTheScenarioMeasures) {
    const CaseSpec continuation =
        parse_case(std::string(kMinimalCase) + "scenario: breakpoint_continuation\n", "continuation.yaml");
    EXPECT_EQ(effective_limits(continuation), kDefaultLimits);
    const CaseSpec static_test = parse_case(std::string(kMinimalCase) + "scenario: static_flow\n", "static.yaml");
    EXPECT_EQ(effective_limits(static_test),
              (std::map<std::string, double>{{"flow_adjust_time_s", 1.7}, {"flow_error_pct", 3.0}}));
    // A default the scenario does not measure cannot be expected to fail...
    EXPECT_THROW(parse_case(std::string(kMinimalCase) + "scenario: static_flow\nexpect: { fail: [ missed_m ] }\n",
                            "static.yaml"),
                 ConfigError);
    // ...unless the file gives it a limit of its own.
    EXPECT_NO_THROW(parse_case(std::string(kMinimalCase) +
                                   "scenario: static_flow\nlimits: { missed_m: 0 }\nexpect: { fail: [ missed_m ] }\n",
                               "static.yaml"));
}

TEST(CaseSpec, StaticTestNeedsNoVehicle) {
    const CaseSpec spec = parse_case(R"(name: static
scenario: static_flow
field: { origin: { lat_deg: 40.18, lon_deg: 116.44 }, heading_deg: 90 }
static_flow: { spray_on_at_s: 9, spray_for_s: 5 }
controller: { target_flow_l_min: 24 }
)",
                                     "static.yaml");
    EXPECT_DOUBLE_EQ(breakpoint_sections(spec).static_flow.spray_on_at_s, 9.0);
    EXPECT_DOUBLE_EQ(breakpoint_sections(spec).target_flow_l_min, 24.0);
}

TEST(CaseSpec, EmptySectionsTakeDefaultsAndDefaultLimitsCanBeExpectedToFail) {
    TempDir dir;
    const CaseSpec spec = load_case_file(dir.write("empty-sections.yaml", std::string(kMinimalCase) + R"(gnss:
boom: {}
expect: { fail: [ breakpoint_error_m ] }
)"));
    EXPECT_DOUBLE_EQ(breakpoint_sections(spec).gnss.rate_hz, 5.0);
    EXPECT_DOUBLE_EQ(breakpoint_sections(spec).boom.l2_m, 0.80);
    EXPECT_EQ(spec.expect.fail, (std::vector<std::string>{"breakpoint_error_m"}));
}

TEST(CaseSpec, SeedsExpectedErrorsAndTheStripAllowances) {
    const CaseSpec spec = parse_case(std::string(kMinimalCase) +
                                         "seeds: [ 11, 3, 7 ]\nexpect: { error: topic_role_violation }\n"
                                         "deposition: { strip_start_allowance_m: 2.5, strip_end_allowance_m: 0.5 }\n",
                                     "seeds.yaml");
    EXPECT_EQ(spec.seeds, (std::vector<std::uint64_t>{11, 3, 7}));
    EXPECT_EQ(spec.seed, 11u) << "the first of the seeds";
    EXPECT_EQ(spec.expect.error, "topic_role_violation");
    EXPECT_EQ(breakpoint_sections(spec).deposition.strip_start_allowance_m, 2.5);
    EXPECT_EQ(breakpoint_sections(spec).deposition.strip_end_allowance_m, 0.5);
    EXPECT_FALSE(spec.source_text.empty());
    // Allowances that leave nothing of a continuation's strip are refused.
    try {
        parse_case(std::string(kMinimalCase) +
                       "scenario: breakpoint_continuation\ndeposition: { strip_start_allowance_m: 10, "
                       "strip_end_allowance_m: 5 }\n",
                   "strip.yaml");
        ADD_FAILURE() << "allowances longer than the strip were accepted";
    } catch (const rig::ConfigError& error) {
        EXPECT_NE(std::string(error.what()).find("leave nothing of the 15 m strip"), std::string::npos) << error.what();
    }
}

// An expectation describes the reference controller unless it says `any`: a
// case run with another controller (command or plugin) is judged on its limits,
// and the reason names the controller and what was expected.
TEST(CaseSpec, AnExpectationOfTheReferenceControllerIsSetAsideForAnother) {
    const std::string expecting = std::string(kMinimalCase) + "expect: { fail: [ breakpoint_error_m ] }\n";
    const CaseSpec reference = parse_case(expecting, "reference.yaml");
    std::string why;
    EXPECT_EQ(applied_expectation(reference, &why).fail, (std::vector<std::string>{"breakpoint_error_m"}));
    EXPECT_EQ(why, "");

    const CaseSpec mine = parse_case(expecting + "controller: { command: [ ./mine, --fast ] }\n", "mine.yaml");
    const ExpectSpec applied = applied_expectation(mine, &why);
    EXPECT_TRUE(applied.fail.empty());
    EXPECT_TRUE(applied.error.empty());
    EXPECT_NE(why.find("failures of breakpoint_error_m of the reference controller"), std::string::npos) << why;
    EXPECT_NE(why.find("it ran ./mine"), std::string::npos) << why;
    EXPECT_EQ(mine.expect.fail, reference.expect.fail) << "the case as written is unchanged";

    const CaseSpec plugin = parse_case(std::string(kMinimalCase) +
                                           "expect: { error: node_exited }\ncontroller: { plugin: ./libmine.so }\n",
                                       "plugin.yaml");
    EXPECT_TRUE(applied_expectation(plugin, &why).error.empty());
    EXPECT_NE(why.find("an error, node_exited"), std::string::npos) << why;

    const CaseSpec any = parse_case(std::string(kMinimalCase) +
                                        "expect: { error: node_exited, controller: any }\n"
                                        "controller: { command: [ ./crashes ] }\n",
                                    "any.yaml");
    why.clear();
    EXPECT_EQ(applied_expectation(any, &why).error, "node_exited");
    EXPECT_EQ(why, "");

    const CaseSpec board = parse_case(expecting + "mode: realtime\nwiring: { gnss: serial, gnss_port: pty, controller: external }\n",
                                      "board.yaml");
    EXPECT_TRUE(applied_expectation(board, &why).fail.empty());
    EXPECT_NE(why.find("it ran an external board"), std::string::npos) << why;

    const CaseSpec explicit_reference = parse_case(expecting.substr(0, expecting.size() - 3) +
                                                       ", controller: reference }\ncontroller: { command: [ ./mine ] }\n",
                                                   "explicit.yaml");
    EXPECT_TRUE(applied_expectation(explicit_reference).fail.empty());
}

// ------------------------------------------------------------------ broken files

struct BrokenFile {
    const char* legend;
    std::string content;
    // What what() must start with after "<file>:" — "LINE:COL: KEY:".
    const char* location_and_key;
    // And a piece of the message.
    const char* message_part;
};

// The minimal case with one line replaced (1-based), to keep positions obvious.
std::string minimal_with_line(int line_number, const std::string& replacement) {
    std::string out;
    std::istringstream lines(kMinimalCase);
    std::string line;
    for (int number = 1; std::getline(lines, line); ++number) out += (number == line_number ? replacement : line) + "\n";
    return out;
}

const std::vector<BrokenFile>& broken_files() {
    static const std::vector<BrokenFile> table = {
        {"YAML syntax error: an unclosed flow sequence",
         "name: t\nfield: [ 1, 2\nvehicle: {}\n", "3:8: (document):", "YAML syntax error"},
        {"unknown key: a typo is named, with the closest known key",
         minimal_with_line(6, "  speed_kmh: 6.0"), "6:3: vehicle.speed_kmh:",
         "unknown key 'speed_kmh'; did you mean 'speed_km_h'?"},
        {"unknown key: the bare quantity without its unit suffix",
         minimal_with_line(6, "  speed: 6.0"), "6:3: vehicle.speed:", "did you mean 'speed_km_h'?"},
        {"unknown key: a misspelt section name",
         minimal_with_line(5, "vehical:"), "5:1: vehical:", "did you mean 'vehicle'?"},
        {"unknown key: nothing close, so the known keys are listed",
         std::string(kMinimalCase) + "gnss: { colour: red }\n", "8:9: gnss.colour:",
         "known keys here: degraded, dropouts, epoch_phase_s, fix, latency_s, noise, rate_hz, talker"},
        {"wrong type: a word where a number belongs",
         minimal_with_line(6, "  speed_km_h: fast"), "6:15: vehicle.speed_km_h:", "expected a number, got 'fast'"},
        {"wrong type: a quoted number",
         minimal_with_line(6, "  speed_km_h: \"6\""), "6:15: vehicle.speed_km_h:",
         "expected a number, got the quoted string '6' (write it without quotes)"},
        {"wrong type: a fraction where an integer belongs",
         std::string(kMinimalCase) + "encoder: { pulses_per_rev: 1000.5 }\n", "8:28: encoder.pulses_per_rev:",
         "expected a non-negative integer, got '1000.5'"},
        {"wrong type: a negative seed",
         std::string(kMinimalCase) + "seed: -1\n", "8:7: seed:", "expected a non-negative integer, got '-1'"},
        {"wrong type: an empty value is reported at its key, not on the next line",
         minimal_with_line(6, "  speed_km_h:"), "6:3: vehicle.speed_km_h:", "empty value, expected a number"},
        {"out of range: below a closed lower bound",
         std::string(kMinimalCase) + "gnss:\n  rate_hz: -5\n", "9:12: gnss.rate_hz:", "must be >= 1, got -5"},
        {"out of range: above a closed upper bound",
         minimal_with_line(6, "  speed_km_h: 45"), "6:15: vehicle.speed_km_h:", "must be <= 30, got 45"},
        {"out of range: inside a list item, with the item index in the path",
         std::string(kMinimalCase) + "gnss:\n  dropouts: [ { at_s: 1, for_s: 1 }, { at_s: 2, for_s: 0 } ]\n",
         "9:56: gnss.dropouts[1].for_s:", "must be > 0, got 0"},
        {"missing required key: reported at the parent mapping",
         minimal_with_line(7, ""), "6:3: vehicle.start_m:", "required key missing"},
        {"missing required key: inside a list item",
         std::string(kMinimalCase) + "gnss:\n  dropouts:\n    - { at_s: 1, for_s: 1 }\n    - { at_s: 2 }\n",
         "11:7: gnss.dropouts[1].for_s:", "required key missing"},
        {"missing required section",
         "name: t\nfield:\n  origin: { lat_deg: 1, lon_deg: 2 }\n  heading_deg: 0\n", "1:1: vehicle:",
         "required section missing"},
        {"missing required key: name",
         minimal_with_line(1, ""), "2:1: name:", "required key missing"},
        {"sequence where a mapping is expected",
         std::string(kMinimalCase) + "gnss: [ 5 ]\n", "8:7: gnss:", "expected a mapping (key: value), got a sequence"},
        {"mapping where a sequence is expected",
         std::string(kMinimalCase) + "gnss: { dropouts: { at_s: 1 } }\n", "8:19: gnss.dropouts:",
         "expected a sequence"},
        {"list item that is not a mapping",
         std::string(kMinimalCase) + "gnss: { dropouts: [ 5 ] }\n", "8:21: gnss.dropouts[0]:",
         "expected a mapping (key: value), got '5'"},
        {"bad enum value, with a suggestion",
         std::string(kMinimalCase) + "mode: lockstp\n", "8:7: mode:",
         "must be one of lockstep, realtime; got 'lockstp' (did you mean 'lockstep'?)"},
        {"bad enum value inside a list item",
         std::string(kMinimalCase) + "gnss: { degraded: [ { at_s: 1, for_s: 1, sigma_m: 0.3, fix: rtk } ] }\n",
         "8:61: gnss.degraded[0].fix:", "must be one of rtk_fixed, rtk_float, dgps, autonomous"},
        {"cross-field: start_m not before the breakpoint",
         minimal_with_line(7, "  start_m: 3") + "breakpoint: { along_m: 2.5 }\n", "7:12: vehicle.start_m:",
         "must be < breakpoint.along_m (2.5) so the vehicle approaches the breakpoint, got 3"},
        {"bad limit name: no unit suffix",
         std::string(kMinimalCase) + "limits:\n  breakpoint_error: 0.16\n", "9:3: limits.breakpoint_error:",
         "metric name 'breakpoint_error' has no unit suffix"},
        {"bad limit name: not snake_case",
         std::string(kMinimalCase) + "limits: { Overlap_M: 3.3 }\n", "8:11: limits.Overlap_M:", "is not snake_case"},
        {"limit value that is not a number",
         std::string(kMinimalCase) + "limits: { overlap_m: [ 3 ] }\n", "8:22: limits.overlap_m:",
         "expected a number, got a sequence"},
        {"expect.fail names a metric without a limit",
         std::string(kMinimalCase) + "limits: { overlap_m: 3.3 }\nexpect:\n  fail: [ overlap_m, missed_m ]\n",
         "10:22: expect.fail[1]:", "'missed_m' has no limit"},
        {"expect.fail written as a scalar",
         std::string(kMinimalCase) + "expect: { fail: breakpoint_error_m }\n", "8:17: expect.fail:",
         "write [ breakpoint_error_m ]"},
        {"duplicate key",
         std::string(kMinimalCase) + "seed: 1\nseed: 2\n", "9:1: seed:", "duplicate key 'seed' (first at line 8, column 1)"},
        {"empty file", "", "1:1: (document):", "the file is empty"},
        {"a file with only comments is empty too", "# nothing yet\n", "1:1: (document):", "the file is empty"},
        {"top level is a list", "- name: t\n", "1:1: (document):", "expected a mapping of settings"},
        // yaml-cpp 0.7's LoadAll looped forever, allocating, on these (case_file_fuzz).
        {"a ',' outside [ ] or { } at the top level", ",", "1:1: (document):", "YAML syntax error: a ','"},
        {"a ',' after a flow mapping", "{a: 1}\n,\n", "2:1: (document):", "YAML syntax error: a ','"},
        {"a ',' after a comment", "# c\n, name: t\n", "2:1: (document):", "YAML syntax error"},
        {"two YAML documents in one file",
         std::string(kMinimalCase) + "---\nname: u\n", "8:1: (document):", "a second YAML document"},  // at its '---'
        {"bad case name", minimal_with_line(1, "name: bad name!"), "1:7: name:",
         "must be letters, digits, '.', '_' or '-'"},
        {"utc_start not in UTC", std::string(kMinimalCase) + "utc_start: 2023-07-15T02:00:00+08:00\n",
         "8:12: utc_start:", "expected an ISO-8601 UTC time"},
        {"utc_start with an impossible date", std::string(kMinimalCase) + "utc_start: 2023-02-30T02:00:00Z\n",
         "8:12: utc_start:", "expected an ISO-8601 UTC time"},
        {"controller that is not a mapping", std::string(kMinimalCase) + "controller: fusion\n", "8:13: controller:",
         "expected a mapping"},
        {"controller command that names nothing", std::string(kMinimalCase) + "controller: { command: [] }\n",
         "8:24: controller.command:", "must name the controller executable"},
        {"seed and seeds both", std::string(kMinimalCase) + "seed: 3\nseeds: [ 1, 2 ]\n", "9:8: seeds:",
         "either `seed` or `seeds`"},
        {"a seed listed twice", std::string(kMinimalCase) + "seeds: [ 1, 2, 1 ]\n", "8:16: seeds[2]:",
         "seed 1 is listed twice"},
        {"a seed that is not a number", std::string(kMinimalCase) + "seeds: [ 1, x ]\n", "8:13: seeds[1]:",
         "a seed is a whole number"},
        {"an expected error that is no kind of failure", std::string(kMinimalCase) + "expect: { error: crashed }\n",
         "8:18: expect.error:", "'crashed' is not a kind of run failure; one of: node_exited"},
        {"an expectation of nobody in particular", std::string(kMinimalCase) +
             "expect: { fail: [ breakpoint_error_m ], controller: mine }\n",
         "8:53: expect.controller:", "'mine' is not whose behaviour an expectation can describe"},
        {"an expected error and expected metric breaks", std::string(kMinimalCase) +
             "expect: { fail: [ breakpoint_error_m ], error: node_exited }\n",
         "8:48: expect.error:", "cannot also expect metrics to break"},
        // yaml-cpp gives an alias the mark of the node it refers to.
        {"an alias that contains itself", std::string(kMinimalCase) + "controller: &loop { again: *loop }\n",
         "8:13: controller.again:", "an alias refers to its own ancestor"},
    };
    return table;
}

TEST(CaseSpec, BrokenFilesAreReportedAtFileLineColumnAndKey) {
    TempDir dir;
    int index = 0;
    for (const BrokenFile& broken : broken_files()) {
        SCOPED_TRACE(broken.legend);
        const fs::path file = dir.write("broken-" + std::to_string(index++) + ".yaml", broken.content);
        try {
            load_case_file(file);
            ADD_FAILURE() << "no error for: " << broken.legend;
        } catch (const ConfigError& error) {
            const std::string what = error.what();
            const std::string expected_prefix = file.string() + ":" + broken.location_and_key;
            EXPECT_EQ(what.rfind(expected_prefix, 0), 0u) << "what(): " << what << "\nexpected prefix: " << expected_prefix;
            EXPECT_NE(what.find(broken.message_part), std::string::npos)
                << "what(): " << what << "\nexpected to contain: " << broken.message_part;
            EXPECT_EQ(error.file(), file.string());
        }
    }
}

// ------------------------------------------------------------------ hostile input (issue 14)

// Names that are path components, or too long to be one, are refused at the
// name: the name is a directory under --out (`..` was --out itself).
TEST(CaseSpec, CaseNamesThatAreNotPlainFileNamesAreRefusedAtTheName) {
    TempDir dir;
    const std::vector<std::string> bad = {".", "..", "...", ".hidden", "a/b", "../escape", "/abs", "a b", "tab\tname",
                                          std::string(kMaxCaseNameLength + 1, 'a'), std::string(500'000, 'n')};
    int index = 0;
    for (const std::string& name : bad) {
        SCOPED_TRACE("name of " + std::to_string(name.size()) + " characters: " + name.substr(0, 20));
        // Quoted, so YAML keeps every byte (a plain `.` or a tab would read the same).
        std::string quoted;
        for (const char c : name) quoted += c == '\t' ? std::string("\\t") : std::string(1, c);
        const fs::path file =
            dir.write("name-" + std::to_string(index++) + ".yaml", minimal_with_line(1, "name: \"" + quoted + "\""));
        try {
            load_case_file(file);
            ADD_FAILURE() << "accepted";
        } catch (const ConfigError& error) {
            EXPECT_EQ(std::string(error.what()).rfind(file.string() + ":1:7: name: case name ", 0), 0u) << error.what();
            // Messages stay one readable line, even for a 1 MB name.
            EXPECT_LT(std::string(error.what()).size(), 400u) << error.what();
        }
    }
    const std::string longest(kMaxCaseNameLength, 'a');
    EXPECT_EQ(parse_case(minimal_with_line(1, "name: " + longest), "ok.yaml").name, longest);
    EXPECT_EQ(parse_case(minimal_with_line(1, "name: a.b_c-9"), "ok.yaml").name, "a.b_c-9");
}

TEST(CaseSpec, TwoCasesWithOneNameAreReportedNamingBothFiles) {
    TempDir dir;
    const fs::path first = dir.write("first.yaml", kMinimalCase);
    const fs::path other = dir.write("other.yaml", std::string(kMinimalCase) + "name_is_above: 1\n");
    const fs::path second = dir.write("second.yaml", "# same name as first.yaml\n" + std::string(kMinimalCase));
    const fs::path third = dir.write("third.yaml", minimal_with_line(1, "name: third"));
    std::vector<CaseSpec> specs = {load_case_file(first), load_case_file(third), load_case_file(second)};
    EXPECT_THROW(load_case_file(other), ConfigError);  // (an unknown key; not part of the run)
    const std::vector<std::string> errors = duplicate_case_name_errors(specs);
    ASSERT_EQ(errors.size(), 1u);
    EXPECT_EQ(errors[0].rfind(second.string() + ":2:7: name: case name 'minimal' is also the name of " +
                                  first.string() + ":1:7",
                              0),
              0u)
        << errors[0];
    specs.pop_back();
    EXPECT_TRUE(duplicate_case_name_errors(specs).empty());
}

// The key path of every key a section knows, from the "known keys here" list
// that an unknown key far from all of them gets.
std::vector<std::string> known_keys_of(const std::function<void(const std::string& key, const std::string& value)>& load,
                                       const std::string& section_path) {
    try {
        load("zqxjzqxjzqxjzqxjzqxj", "1");
    } catch (const ConfigError& error) {
        const std::string message = error.message();
        const std::string marker = "known keys here: ";
        const std::size_t at = message.find(marker);
        if (at == std::string::npos) {
            ADD_FAILURE() << section_path << ": " << error.what();
            return {};
        }
        std::vector<std::string> keys;
        std::stringstream list(message.substr(at + marker.size()));
        for (std::string key; std::getline(list, key, ',');) keys.push_back(key.substr(key.find_first_not_of(' ')));
        return keys;
    }
    ADD_FAILURE() << section_path << ": an unknown key was accepted";
    return {};
}

// Keys that are not numbers: a number in their place is a type error, or (for
// the strings) a legal value; everything else must have a range.
bool is_non_numeric_key(const std::string& key) {
    // (`seed` is any 64-bit number; `command`, `plugin` and `in_process` are the
    // rig's, read by the harness.)
    static const std::vector<std::string> strings = {"name",       "description",           "gnss_port", "modbus_port",
                                                     "modbus_tcp", "breakpoint_store_file", "seed",      "command",
                                                     "plugin",     "in_process",            "diagnostics_topic"};
    return std::find(strings.begin(), strings.end(), key) != strings.end();
}

// Every numeric key of `sections` refuses values far outside physics, at the
// key: 1e300 and -1e300 everywhere, and 1e-300 for rates and per-unit counts
// (a timer of 1/rate). A key added later without a range fails this test.
// Returns how many keys were found to be numbers with a range.
int expect_every_number_bounded(
    const std::vector<std::string>& sections,
    const std::function<void(const std::string& section, const std::string& key, const std::string& value)>& load) {
    int ranged = 0;
    for (const std::string& section : sections) {
        const auto load_in_section = [&](const std::string& key, const std::string& value) { load(section, key, value); };
        const std::vector<std::string> keys = known_keys_of(load_in_section, section);
        EXPECT_FALSE(keys.empty()) << section;
        for (const std::string& key : keys) {
            if (is_non_numeric_key(key)) continue;
            std::vector<std::string> values = {"1e300", "-1e300"};
            if (key.ends_with("_hz") || key.ends_with("per_l") || key.ends_with("per_rev")) values.push_back("1e-300");
            for (std::size_t v = 0; v < values.size(); ++v) {
                const std::string value = values[v];
                const std::string where = (section.empty() ? "" : section + ".") + key;
                SCOPED_TRACE(where + ": " + value);
                try {
                    load(section, key, value);
                    ADD_FAILURE() << where << " accepted " << value;
                } catch (const ConfigError& error) {
                    const std::string message = error.message();
                    const bool type_error = message.starts_with("expected") || message.starts_with("must be one of") ||
                                            message.find("must be between") != std::string::npos;
                    if (type_error && message.find("integer") != std::string::npos && value != "2000000000") {
                        // An integer key: its type refuses 1e300, so try the largest
                        // value both int and uint32 hold.
                        values = {"2000000000"};
                        v = static_cast<std::size_t>(-1);
                        continue;
                    }
                    if (type_error) break;  // not a number (a section, an enum, a bool)
                    EXPECT_TRUE(error.key_path().ends_with(key)) << error.what();
                    EXPECT_TRUE(message.starts_with("must be")) << error.what();
                    if (v == 0) ++ranged;
                }
            }
        }
    }
    return ranged;
}

// `section` (dotted, list items as name[0]) set to { key: value } in the minimal case.
std::string minimal_with(const std::string& section, const std::string& key, const std::string& value) {
    YAML::Node root = YAML::Load(kMinimalCase);
    std::vector<std::string> parts;
    std::stringstream path(section);
    for (std::string part; std::getline(path, part, '.');) parts.push_back(part);
    std::vector<YAML::Node> chain = {root};
    for (const std::string& part : parts) {
        YAML::Node parent = chain.back();
        if (part.ends_with("[0]")) {
            const std::string list = part.substr(0, part.size() - 3);
            if (!parent[list]) {
                // An item with what it requires, so only `key` can be wrong.
                YAML::Node item;
                if ((list == "dropouts" && key != "before_breakpoint_s") || list == "degraded") {
                    item["at_s"] = 1;
                }
                if (list == "dropouts" || list == "degraded") item["for_s"] = 1;
                if (list == "degraded") item["sigma_m"] = 0.1;
                if (list == "lifts") {
                    item["at_s"] = 1;
                    item["to_m"] = 0.2;
                    item["rate_m_s"] = 0.05;
                }
                if (list == "pump_throttle") {
                    item["at_s"] = 60;
                    item["flow_l_min"] = 40;
                }
                parent[list].push_back(item);
            }
            chain.push_back(parent[list][0]);
        } else {
            chain.push_back(parent[part]);
        }
    }
    YAML::Node target = chain.back();
    target[key] = YAML::Load(value);
    YAML::Emitter out;
    out << root;
    return out.c_str();
}

TEST(CaseSpec, EveryNumericKeyOfACaseFileHasAPhysicalRange) {
    const std::vector<std::string> sections = {
        "",           "field",       "field.origin",       "vehicle",    "boom",       "breakpoint",
        "gnss",       "gnss.noise",  "gnss.dropouts[0]",   "gnss.degraded[0]",       "encoder",
        "hydraulics", "hydraulics.valve", "hydraulics.flow_map", "hydraulics.pump_throttle[0]", "flow_meter", "pump_sensor",
        "boom_height_sensor",        "deposition",         "static_flow", "wiring",   "timeouts",
        "realtime",   "rig_faults", "gnss.wire_faults", "board.line_noise", "boom.lifts[0]"};
    const int ranged =
        expect_every_number_bounded(sections, [](const std::string& section, const std::string& key,
                                                 const std::string& value) {
            parse_case(minimal_with(section, key, value), "bounds.yaml");
        });
    // The sweep found the keys, not an empty list: a case file has 95 numbers
    // (a new one with a range changes this count; one without fails above).
    EXPECT_EQ(ranged, 95);
    // Limits are data keys: their values are bounded too.
    for (const char* value : {"1e300", "-1e300"}) {
        EXPECT_THROW(parse_case(std::string(kMinimalCase) + "limits: { overlap_m: " + value + " }\n", "l.yaml"),
                     ConfigError);
    }
}

TEST(CaseSpec, EveryNumericKeyOfTheReferenceControllersSectionHasAPhysicalRange) {
    const std::vector<std::string> sections = {"",         "boom",        "odometer",           "pid",  "flow_meter",
                                               "pump_sensor", "boom_height_sensor", "valve", "valve.calibration[0]",
                                               "calibration_run"};
    const int ranged = expect_every_number_bounded(sections, [](const std::string& section, const std::string& key,
                                                                const std::string& value) {
        // (YAML::Node's operator= assigns content; reset() rebinds.)
        YAML::Node root(YAML::NodeType::Map);
        YAML::Node target = root;
        std::stringstream path(section);
        for (std::string part; std::getline(path, part, '.');) {
            if (part == "calibration[0]") {
                YAML::Node line;
                line["opening_pct"] = 50;
                line["slope"] = 1;
                line["intercept_l_min"] = 0;
                target["calibration"].push_back(line);
                target.reset(target["calibration"][0]);
            } else {
                target.reset(target[part]);
            }
        }
        target[key] = YAML::Load(value);
        controller::parse_controller_config(YamlSection(root, "controller.yaml"));
    });
    EXPECT_EQ(ranged, 46);  // the section's numbers, all found
}

// The store is the one file the controller writes: its name stays inside --state-dir.
TEST(CaseSpec, TheControllersStoreFileIsAPlainNameInsideItsStateDirectory) {
    for (const std::string& bad : {std::string("../x"), std::string("/etc/passwd"), std::string("a/b"),
                                   std::string(".."), std::string("."), std::string(".hidden"), std::string(""),
                                   std::string("/dev/zero"), std::string(201, 'x')}) {
        SCOPED_TRACE(bad);
        YAML::Node root;
        root["breakpoint_store_file"] = bad;
        try {
            controller::parse_controller_config(YamlSection(root, "controller.yaml"));
            ADD_FAILURE() << "accepted";
        } catch (const ConfigError& error) {
            EXPECT_EQ(error.key_path(), "breakpoint_store_file") << error.what();
        }
    }
    YAML::Node good;
    good["breakpoint_store_file"] = "store-1.txt";
    EXPECT_EQ(controller::parse_controller_config(YamlSection(good, "controller.yaml")).breakpoint_store_file,
              "store-1.txt");
}

// Every place the route can make the case long (positions, distances, speed)
// is held so that simulated time stays far from int64 overflow and the land
// wheel's modelled ground (10 km) is never left.
TEST(CaseSpec, RoutesLongerThanTheModelledGroundAreRefused) {
    EXPECT_NO_THROW(parse_case(minimal_with_line(7, "  start_m: -8000"), "ok.yaml"));
    try {
        parse_case(minimal_with_line(7, "  start_m: -9999") + "breakpoint: { along_m: 9999 }\n", "long.yaml");
        FAIL() << "accepted a 20 km approach";
    } catch (const ConfigError& error) {
        EXPECT_EQ(error.key_path(), "vehicle.start_m") << error.what();
        EXPECT_NE(error.message().find("at most 10000 m of ground"), std::string::npos) << error.what();
    }
}

TEST(CaseSpec, EpisodesOutsideTheCasesTimelineAreRefusedAtTheirKey) {
    const std::string text = std::string(kMinimalCase) + R"(gnss:
  dropouts:
    - { at_s: 10, for_s: 1 }
    - { before_breakpoint_s: 0.5, for_s: 0.6 }
  degraded:
    - { at_s: 2, for_s: 3, sigma_m: 0.2 }
)";
    const CaseSpec spec = parse_case(text, "timeline.yaml");
    // A case of 60 s whose approach crosses the breakpoint at 40 s.
    EXPECT_NO_THROW(check_case_timeline(spec, 60.0, 40.0));
    struct Change {
        const char* legend;
        std::function<void(BreakpointSections&)> apply;
        const char* key_path;
        const char* message_part;
    };
    const std::vector<Change> changes = {
        {"dropout longer than the case", [](BreakpointSections& c) { c.gnss.dropouts[0].for_s = 1e5; }, "gnss.dropouts[0].for_s",
         "longer than the whole case (60 s)"},
        {"dropout after the end", [](BreakpointSections& c) { c.gnss.dropouts[0].at_s = 60; }, "gnss.dropouts[0].at_s",
         "after the case ends"},
        {"dropout before the start", [](BreakpointSections& c) { c.gnss.dropouts[1].before_breakpoint_s = 41; },
         "gnss.dropouts[1].before_breakpoint_s", "before the case does"},
        {"degraded episode longer than the case", [](BreakpointSections& c) { c.gnss.degraded[0].for_s = 61; },
         "gnss.degraded[0].for_s", "longer than the whole case"},
        {"degraded episode after the end", [](BreakpointSections& c) { c.gnss.degraded[0].at_s = 1000; },
         "gnss.degraded[0].at_s", "after the case ends"},
    };
    for (const Change& change : changes) {
        SCOPED_TRACE(change.legend);
        // A copy of the case with its seed-000 sections changed.
        auto own = std::make_shared<BreakpointSections>(breakpoint_sections(spec));
        change.apply(*own);
        CaseSpec changed = spec;
        changed.system = own;
        try {
            check_case_timeline(changed, 60.0, 40.0);
            ADD_FAILURE() << "accepted";
        } catch (const ConfigError& error) {
            EXPECT_EQ(error.key_path(), change.key_path) << error.what();
            EXPECT_EQ(error.file(), "timeline.yaml");
            EXPECT_GT(error.line(), 0) << error.what();
            EXPECT_NE(error.message().find(change.message_part), std::string::npos) << error.what();
        }
    }
    // A dropout placed before the breakpoint in a static test has nothing to be placed by.
    EXPECT_THROW(check_case_timeline(spec, 60.0, std::nan("")), ConfigError);
}

// The boom's push-rod moves: read as written, each checked at its key, one
// move at a time, and held to the case's timeline like the GNSS episodes.
TEST(CaseSpec, BoomLiftsParseAndAreCheckedAtTheirKeys) {
    EXPECT_TRUE(breakpoint_sections(parse_case(kMinimalCase, "none.yaml")).boom.lifts.empty());
    const std::string text = std::string(kMinimalCase) + R"(boom:
  linkage_rise_m: 1.0
  lifts:
    - { at_s: 10, to_m: 0.0, rate_m_s: 0.05 }
    - { at_s: 30, to_m: 0.4, rate_m_s: 0.1 }
)";
    const CaseSpec spec = parse_case(text, "lifts.yaml");
    ASSERT_EQ(breakpoint_sections(spec).boom.lifts.size(), 2u);
    EXPECT_EQ(breakpoint_sections(spec).boom.lifts[1].at_s, 30.0);
    EXPECT_EQ(breakpoint_sections(spec).boom.lifts[1].to_m, 0.4);
    EXPECT_EQ(breakpoint_sections(spec).boom.lifts[1].rate_m_s, 0.1);
    EXPECT_DOUBLE_EQ(breakpoint_sections(spec).boom.lift_duration_s(0), 20.0);  // 1.0 m down at 50 mm/s
    EXPECT_DOUBLE_EQ(breakpoint_sections(spec).boom.lift_duration_s(1), 4.0);   // 0.4 m up at 100 mm/s

    struct Broken {
        const char* legend;
        std::string text;
        const char* key_path;
        const char* message_part;
    };
    const std::string head = std::string(kMinimalCase) + "boom:\n  linkage_rise_m: 1.0\n  lifts:\n";
    const std::vector<Broken> broken = {
        {"the second starts before the first arrives (10 + 20 s)",
         head + "    - { at_s: 10, to_m: 0.0, rate_m_s: 0.05 }\n    - { at_s: 29.5, to_m: 0.4, rate_m_s: 0.1 }\n",
         "boom.lifts[1].at_s", "before the previous lift arrives (30 s)"},
        {"no rate", head + "    - { at_s: 10, to_m: 0.0 }\n", "boom.lifts[0].rate_m_s", "required key missing"},
        {"a push rod at 2 m/s", head + "    - { at_s: 10, to_m: 0.0, rate_m_s: 2 }\n", "boom.lifts[0].rate_m_s",
         "must be <= 1"},
        {"below the linkage's range", head + "    - { at_s: 10, to_m: -0.1, rate_m_s: 0.05 }\n",
         "boom.lifts[0].to_m", "must be >= 0"},
        {"an unknown key", head + "    - { at_s: 10, to_m: 0.0, rate_m_s: 0.05, speed_m_s: 1 }\n",
         "boom.lifts[0].speed_m_s", "unknown key"},
    };
    for (const Broken& one : broken) {
        SCOPED_TRACE(one.legend);
        try {
            parse_case(one.text, "lifts.yaml");
            ADD_FAILURE() << "accepted";
        } catch (const ConfigError& error) {
            EXPECT_EQ(error.key_path(), one.key_path) << error.what();
            EXPECT_GT(error.line(), 0) << error.what();
            EXPECT_NE(error.message().find(one.message_part), std::string::npos) << error.what();
        }
    }

    // The timeline: a 60 s case holds both moves; in a 25 s case the second starts after the end.
    EXPECT_NO_THROW(check_case_timeline(spec, 60.0, 40.0));
    try {
        check_case_timeline(spec, 25.0, 20.0);
        ADD_FAILURE() << "accepted a lift after the case's end";
    } catch (const ConfigError& error) {
        EXPECT_EQ(error.key_path(), "boom.lifts[1].at_s") << error.what();
        EXPECT_NE(error.message().find("after the case ends"), std::string::npos) << error.what();
    }
}

// The operator's throttle steps (Fig. 11's pump flows): read as written, each
// checked at its key, one ramp at a time.
TEST(CaseSpec, PumpThrottleStepsParseAndAreCheckedAtTheirKeys) {
    EXPECT_TRUE(breakpoint_sections(parse_case(kMinimalCase, "none.yaml")).hydraulics.pump_throttle.empty());
    const std::string head = std::string(kMinimalCase) + "hydraulics:\n  throttle_ramp_s: 2\n  pump_throttle:\n";
    const CaseSpec spec = parse_case(head + "    - { at_s: 10, flow_l_min: 44.2 }\n    - { at_s: 12, flow_l_min: 57.3 }\n",
                                     "throttle.yaml");
    ASSERT_EQ(breakpoint_sections(spec).hydraulics.pump_throttle.size(), 2u);
    EXPECT_EQ(breakpoint_sections(spec).hydraulics.pump_throttle[1].at_s, 12.0);
    EXPECT_EQ(breakpoint_sections(spec).hydraulics.pump_throttle[1].flow_l_min, 57.3);
    EXPECT_EQ(breakpoint_sections(spec).hydraulics.throttle_ramp_s, 2.0);

    struct Broken {
        const char* legend;
        std::string text;
        const char* key_path;
        const char* message_part;
    };
    const std::vector<Broken> broken = {
        {"the second starts inside the first's 2 s ramp",
         head + "    - { at_s: 10, flow_l_min: 44.2 }\n    - { at_s: 11.5, flow_l_min: 57.3 }\n",
         "hydraulics.pump_throttle[1].at_s", "before the previous step's ramp ends (12 s)"},
        {"no flow", head + "    - { at_s: 10 }\n", "hydraulics.pump_throttle[0].flow_l_min", "required key missing"},
        {"a pump of 500 L/min", head + "    - { at_s: 10, flow_l_min: 500 }\n", "hydraulics.pump_throttle[0].flow_l_min",
         "must be <= 200"},
    };
    for (const Broken& one : broken) {
        SCOPED_TRACE(one.legend);
        try {
            parse_case(one.text, "throttle.yaml");
            ADD_FAILURE() << "accepted";
        } catch (const ConfigError& error) {
            EXPECT_EQ(error.key_path(), one.key_path) << error.what();
            EXPECT_GT(error.line(), 0) << error.what();
            EXPECT_NE(error.message().find(one.message_part), std::string::npos) << error.what();
        }
    }
}

// Anything but a regular file is refused by what it is, naming the path,
// without opening a device or waiting on a FIFO.
TEST(CaseSpec, SpecialFilesGivenAsCaseFilesAreRefusedByType) {
    TempDir dir;
    const fs::path fifo = dir.path() / "fifo.yaml";
    ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
    const fs::path link_to_fifo = dir.path() / "link.yaml";
    fs::create_symlink(fifo, link_to_fifo);
    const std::vector<std::pair<fs::path, std::string>> special = {
        {fifo, "is a FIFO (named pipe)"},
        {link_to_fifo, "is a FIFO (named pipe)"},
        {dir.path(), "is a directory"},
        {"/dev/null", "is a character device"},
        {"/dev/zero", "is a character device"},
    };
    for (const auto& [path, what] : special) {
        SCOPED_TRACE(path.string());
        try {
            load_case_file(path);
            ADD_FAILURE() << "accepted";
        } catch (const ConfigError& error) {
            EXPECT_EQ(std::string(error.what()), path.string() + ": (file): " + what +
                                                     ", expected a regular file (case file)");
        }
    }
}

TEST(CaseSpec, CaseFilesLargerThanAnyCaseAreRefusedBeforeParsing) {
    TempDir dir;
    std::string text = kMinimalCase;
    while (text.size() <= (1u << 20)) text += "# padding padding padding padding padding padding padding\n";
    const fs::path file = dir.write("huge.yaml", text);
    try {
        load_case_file(file);
        FAIL() << "accepted";
    } catch (const ConfigError& error) {
        EXPECT_NE(error.message().find("more than the 1 MiB a case file may have"), std::string::npos) << error.what();
    }
}

// The duplicate-key and unknown-key checks are hashed (linear): a file with
// very many keys is judged as one with few. (Timing is measured, not tested;
// this holds the behaviour on a big input: the first duplicate is found with
// the line of its first use, and of many unknown keys the earliest is named.)
TEST(CaseSpec, ManyKeysAreCheckedExactly) {
    std::string text = kMinimalCase;
    text += "limits:\n";
    for (int i = 0; i < 20000; ++i) text += "  metric_" + std::to_string(i) + "_m: 1\n";
    const CaseSpec spec = parse_case(text, "many.yaml");
    EXPECT_EQ(spec.limits.size(), 20000u);
    EXPECT_DOUBLE_EQ(spec.limits.at("metric_19999_m"), 1.0);
    try {
        parse_case(text + "  metric_7_m: 2\n", "dup.yaml");
        FAIL() << "accepted a duplicate";
    } catch (const ConfigError& error) {
        EXPECT_EQ(error.key_path(), "limits.metric_7_m");
        EXPECT_NE(error.message().find("first at line 16, column 3"), std::string::npos) << error.what();
    }
    std::string unknown = kMinimalCase;
    for (int i = 0; i < 20000; ++i) unknown += "unknown_" + std::to_string(i) + ": 1\n";
    try {
        parse_case(unknown, "unknown.yaml");
        FAIL() << "accepted unknown keys";
    } catch (const ConfigError& error) {
        EXPECT_EQ(error.key_path(), "unknown_0") << error.what();
        EXPECT_EQ(error.line(), 8);
    }
}

TEST(CaseSpec, ErrorFormatIsFileLineColumnKeyMessage) {
    const ConfigError error(SourceLocation{"cases/bp.yaml", 14, 12, "gnss.rate_hz"}, "must be > 0, got -5");
    EXPECT_STREQ(error.what(), "cases/bp.yaml:14:12: gnss.rate_hz: must be > 0, got -5");
    EXPECT_EQ(error.line(), 14);
    EXPECT_EQ(error.column(), 12);
    EXPECT_EQ(error.key_path(), "gnss.rate_hz");
    EXPECT_EQ(error.message(), "must be > 0, got -5");
}

TEST(CaseSpec, MissingFileIsAnErrorNamingIt) {
    TempDir dir;
    const fs::path file = dir.path() / "no-such-case.yaml";
    try {
        load_case_file(file);
        FAIL() << "no error";
    } catch (const ConfigError& error) {
        EXPECT_EQ(std::string(error.what()), file.string() + ": (file): no such file");
        EXPECT_EQ(error.line(), 0);
    }
}

TEST(CaseSpec, DirectoryGivenAsCaseFileIsAnError) {
    TempDir dir;
    EXPECT_THROW(
        {
            try {
                load_case_file(dir.path());
            } catch (const ConfigError& error) {
                EXPECT_NE(std::string(error.what()).find("is a directory"), std::string::npos);
                throw;
            }
        },
        ConfigError);
}

TEST(CaseSpec, ExpandCasePathsWalksADirectoryTreeSortedAndKeepsFiles) {
    TempDir dir;
    fs::create_directories(dir.path() / "suite" / "nested");
    dir.write("suite/b.yml", kMinimalCase);
    dir.write("suite/a.yaml", kMinimalCase);
    dir.write("suite/c.yaml", kMinimalCase);
    dir.write("suite/notes.txt", "not a case");
    dir.write("suite/.hidden.yaml", kMinimalCase);
    dir.write("suite/nested/deep.yaml", kMinimalCase);
    fs::create_directories(dir.path() / "suite" / ".git");
    dir.write("suite/.git/config.yaml", kMinimalCase);
    const fs::path single = dir.write("single.case", kMinimalCase);

    const auto paths = expand_case_paths({single.string(), (dir.path() / "suite").string()});
    const std::vector<fs::path> expected = {single, dir.path() / "suite" / "a.yaml", dir.path() / "suite" / "b.yml",
                                            dir.path() / "suite" / "c.yaml",
                                            dir.path() / "suite" / "nested" / "deep.yaml"};
    EXPECT_EQ(paths, expected);
}

TEST(CaseSpec, ExpandCasePathsRejectsMissingPathsAndEmptyDirectories) {
    TempDir dir;
    const std::string missing = (dir.path() / "nope").string();
    try {
        expand_case_paths({missing});
        FAIL() << "no error";
    } catch (const ConfigError& error) {
        EXPECT_EQ(std::string(error.what()), missing + ": (file): no such case file or directory");
    }
    fs::create_directories(dir.path() / "empty");
    try {
        expand_case_paths({(dir.path() / "empty").string()});
        FAIL() << "no error";
    } catch (const ConfigError& error) {
        EXPECT_NE(std::string(error.what()).find("directory has no *.yaml or *.yml case files"), std::string::npos);
    }
}

TEST(CaseSpec, MetricNames) {
    EXPECT_EQ(metric_name_problem("breakpoint_error_m"), "");
    EXPECT_EQ(metric_name_problem("flow_error_pct"), "");
    EXPECT_EQ(metric_name_problem("main_flow_l_min"), "");
    EXPECT_EQ(metric_name_problem("missed_count"), "");
    EXPECT_EQ(metric_name_problem("deposition_cv_pct"), "");
    EXPECT_NE(metric_name_problem("m"), "");          // a unit alone
    EXPECT_NE(metric_name_problem("_m"), "");
    EXPECT_NE(metric_name_problem("overlap"), "");
    EXPECT_NE(metric_name_problem("overlap__m"), "");
    EXPECT_NE(metric_name_problem("overlap-m"), "");
    EXPECT_NE(metric_name_problem("overlap_m_"), "");
    EXPECT_NE(metric_name_problem("overlap_furlongs"), "");
}

// ------------------------------------------------------------------ the YAML layer itself

TEST(YamlSection, ControllerCanValidateItsOwnSectionWithLocations) {
    const CaseSpec spec = parse_case(std::string(kMinimalCase) + "controller:\n  command: [ x ]\n  threshold: 5\n",
                                     "cases/c.yaml");
    const YamlSection controller(spec.controller.params);
    for (const std::string_view rig_key : kControllerRigKeys) controller.allow(rig_key);
    EXPECT_DOUBLE_EQ(controller.optional<double>("threshold_m", 5.0), 5.0);
    try {
        controller.finish();
        FAIL() << "no error";
    } catch (const ConfigError& error) {
        EXPECT_STREQ(error.what(),
                     "cases/c.yaml:10:3: controller.threshold: unknown key 'threshold'; did you mean 'threshold_m'?");
    }
}

TEST(YamlSection, AbsentRawSectionReportsAtItsParent) {
    const CaseSpec spec = parse_case(kMinimalCase, "cases/c.yaml");
    const YamlSection controller(spec.controller.params);
    EXPECT_FALSE(controller.present());
    (void)controller.required<double>("threshold_m");
    try {
        controller.finish();
        FAIL() << "no error";
    } catch (const ConfigError& error) {
        EXPECT_STREQ(error.what(),
                     "cases/c.yaml:1:1: controller.threshold_m: required key missing (the whole 'controller' section "
                     "is absent)");
    }
}

TEST(YamlSection, ScalarConversions) {
    const YamlSection section =
        YamlSection::load_string("a: +1.5e2\nb: true\nc: 18446744073709551615\nd: 7\ne: .inf\nf: 99999999999\n", "t");
    EXPECT_DOUBLE_EQ(section.required<double>("a"), 150.0);
    EXPECT_TRUE(section.required<bool>("b"));
    EXPECT_EQ(section.required<std::uint64_t>("c"), 18446744073709551615u);
    EXPECT_EQ(section.required<int>("d"), 7);
    EXPECT_EQ(section.maybe<int>("missing"), std::nullopt);
    EXPECT_THROW(section.required<double>("e"), ConfigError);
    try {
        section.required<int>("f");
        FAIL() << "no error";
    } catch (const ConfigError& error) {
        EXPECT_STREQ(error.what(), "t:6:4: f: must be between -2147483648 and 2147483647, got '99999999999'");
    }
}

TEST(YamlSection, StringEnumsListsAndKeys) {
    const YamlSection root = YamlSection::load_string(
        "mode: realtime\nitems: [ { id: a }, { id: b } ]\ntags: [ x, y ]\nmap: { k1: 1, k2: 2 }\n", "t");
    EXPECT_EQ(root.optional_enum("mode", {"lockstep", "realtime"}, "lockstep"), "realtime");
    EXPECT_EQ(root.optional_enum("absent", {"lockstep", "realtime"}, "lockstep"), "lockstep");
    std::vector<std::string> ids;
    for (const YamlSection& item : root.list("items")) ids.push_back(item.required<std::string>("id"));
    EXPECT_EQ(ids, (std::vector<std::string>{"a", "b"}));
    EXPECT_EQ(root.list("items")[1].key_path(), "items[1]");
    EXPECT_EQ(root.string_list("tags"), (std::vector<std::string>{"x", "y"}));
    const YamlSection map = root.section("map");
    EXPECT_EQ(map.keys(), (std::vector<std::string>{"k1", "k2"}));
    EXPECT_THROW(map.finish(), ConfigError);  // keys() alone does not make keys known
    map.allow("k1");
    map.allow("k2");
    EXPECT_NO_THROW(root.finish());
    EXPECT_TRUE(root.section("absent").keys().empty());
    EXPECT_FALSE(root.section("absent").present());
}

TEST(YamlSection, BoundsDescribeThemselves) {
    EXPECT_EQ(Bounds::open_closed(0, 30).describe(), "(0, 30]");
    EXPECT_EQ(Bounds::at_least(0).describe(), "[0, +inf)");
    EXPECT_EQ(Bounds::closed_open(0, 360).violation(360), "must be < 360");
    EXPECT_EQ(Bounds::greater_than(0).violation(0), "must be > 0");
    EXPECT_FALSE(Bounds::closed(-20, 20).violation(20).has_value());
}

TEST(YamlSection, ClosestSpelling) {
    const std::vector<std::string> keys = {"lat_deg", "lon_deg", "height_m"};
    EXPECT_EQ(closest_spelling("lat_dge", keys), "lat_deg");
    EXPECT_EQ(closest_spelling("height", keys), "height_m");
    EXPECT_EQ(closest_spelling("colour", keys), std::nullopt);
    const std::vector<std::string> fixes = {"rtk_fixed", "rtk_float", "dgps", "autonomous"};
    EXPECT_EQ(closest_spelling("float", fixes), "rtk_float");
    EXPECT_EQ(closest_spelling("rtk_fixd", fixes), "rtk_fixed");
}

// `board:` (harness/spec/board_spec.h): a wired board's attach, silence and fail-safe.
TEST(CaseSpec, BoardKeysParseWithDefaultsAndBounds) {
    const CaseSpec defaults = parse_case(std::string(kMinimalCase), "case.yaml");
    EXPECT_EQ(defaults.board.attach_timeout_s, 60.0);
    EXPECT_EQ(defaults.board.silence_timeout_s, 2.0);
    EXPECT_EQ(defaults.board.failsafe_timeout_s, 1.0);
    EXPECT_EQ(defaults.board.failsafe, rig::modbus::FailsafeMode::safe);
    const CaseSpec set = parse_case(std::string(kMinimalCase) +
                                        "board: { attach_timeout_s: 5, silence_timeout_s: 0.5, failsafe_timeout_s: 0, "
                                        "failsafe: hold }\n",
                                    "case.yaml");
    EXPECT_EQ(set.board.attach_timeout_s, 5.0);
    EXPECT_EQ(set.board.silence_timeout_s, 0.5);
    EXPECT_EQ(set.board.failsafe_timeout_s, 0.0);
    EXPECT_EQ(set.board.failsafe, rig::modbus::FailsafeMode::hold);
    for (const char* bad : {"board: { attach_timeout_s: 0 }\n", "board: { silence_timeout_s: 0.01 }\n",
                            "board: { failsafe_timeout_s: 0.01 }\n", "board: { failsafe: off }\n",
                            "board: { watchdog_s: 1 }\n"}) {
        try {
            parse_case(std::string(kMinimalCase) + bad, "case.yaml");
            ADD_FAILURE() << "accepted: " << bad;
        } catch (const rig::ConfigError& error) {
            EXPECT_NE(std::string(error.what()).find("board"), std::string::npos) << error.what();
        }
    }
}

// Wire faults (emulators/wire_faults.h): off unless written, percentages in [0, 100].
TEST(CaseSpec, WireFaultsAreOffByDefaultAndReadAsWritten) {
    const CaseSpec defaults = parse_case(std::string(kMinimalCase), "case.yaml");
    EXPECT_FALSE(breakpoint_sections(defaults).gnss.wire_faults.any());
    EXPECT_FALSE(defaults.board.line_noise.any());
    const CaseSpec set = parse_case(
        std::string(kMinimalCase) +
            "gnss: { wire_faults: { byte_loss_pct: 0.5, corrupt_checksum_pct: 15, truncate_pct: 25 } }\n",
        "case.yaml");
    EXPECT_EQ(breakpoint_sections(set).gnss.wire_faults.byte_loss_pct, 0.5);
    EXPECT_EQ(breakpoint_sections(set).gnss.wire_faults.corrupt_checksum_pct, 15.0);
    EXPECT_EQ(breakpoint_sections(set).gnss.wire_faults.truncate_pct, 25.0);
    const std::string wired = "mode: realtime\nwiring: { gnss: serial, board_io: modbus_rtu }\n";
    const CaseSpec noisy = parse_case(
        std::string(kMinimalCase) + wired + "board: { line_noise: { corrupt_response_pct: 2, noise_burst_pct: 1 } }\n",
        "case.yaml");
    EXPECT_EQ(noisy.board.line_noise.corrupt_response_pct, 2.0);
    EXPECT_EQ(noisy.board.line_noise.noise_burst_pct, 1.0);
}

TEST(CaseSpec, WireFaultsOutsideTheirRangeOrWireAreRefusedAtTheirKey) {
    const std::vector<std::pair<std::string, std::string>> bad = {
        {"gnss: { wire_faults: { byte_loss_pct: 101 } }\n", "gnss.wire_faults.byte_loss_pct"},
        {"gnss: { wire_faults: { truncate_pct: -1 } }\n", "gnss.wire_faults.truncate_pct"},
        {"gnss: { wire_faults: { bit_flip_pct: 1 } }\n", "gnss.wire_faults"},
        // Line noise is injected on an RTU line: on DDS (or TCP) there is none to inject.
        {"board: { line_noise: { corrupt_response_pct: 2 } }\n", "board.line_noise"},
        {"mode: realtime\nwiring: { gnss: serial, board_io: modbus_tcp }\nboard: { line_noise: { noise_burst_pct: 1 } }\n",
         "board.line_noise"},
    };
    for (const auto& [text, key] : bad) {
        try {
            parse_case(std::string(kMinimalCase) + text, "case.yaml");
            ADD_FAILURE() << "accepted: " << text;
        } catch (const ConfigError& error) {
            EXPECT_TRUE(error.key_path().starts_with(key)) << error.what();
        }
    }
}

// Every case the repository ships (what `rig run cases` and scripts/demo run)
// loads: a key renamed in the loader cannot leave a case behind.
TEST(CaseSpec, EveryCaseInTheRepositoryLoads) {
    const std::vector<std::filesystem::path> files = expand_case_paths({RIG_SOURCE_DIR "/cases"});
    EXPECT_GT(files.size(), 50u);
    bool wire_faults = false;
    for (const std::filesystem::path& file : files) {
        SCOPED_TRACE(file.string());
        try {
            const CaseSpec spec = load_case_file(file);
            const auto* own = dynamic_cast<const BreakpointSections*>(spec.system.get());
            wire_faults = wire_faults || (own != nullptr && own->gnss.wire_faults.any()) || spec.board.line_noise.any();
        } catch (const ConfigError& error) {
            ADD_FAILURE() << error.what();
        }
    }
    EXPECT_TRUE(wire_faults) << "cases/wire-faults/ is among them";
}

// `realtime:` (harness/spec/realtime_spec.h): the bound on the rig's own lateness;
// `rig_faults:`: the self-test stall. Real-time cases only.
TEST(CaseSpec, RealtimeLatenessKeysParseWithDefaultsAndBounds) {
    const std::string realtime = std::string(kMinimalCase) + "mode: realtime\n";
    const CaseSpec defaults = parse_case(realtime, "case.yaml");
    EXPECT_EQ(defaults.realtime.late_after_ms, 10.0);
    EXPECT_EQ(defaults.realtime.max_late_pct, 1.0);
    EXPECT_EQ(defaults.realtime.max_lateness_ms, 100.0);
    EXPECT_FALSE(defaults.rig_faults.has_value());
    const CaseSpec set = parse_case(realtime +
                                        "realtime: { late_after_ms: 5, max_late_pct: 0.5, max_lateness_ms: 40 }\n"
                                        "rig_faults: { master_stall_at_s: 3, master_stall_for_s: 0.5 }\n",
                                    "case.yaml");
    EXPECT_EQ(set.realtime.late_after_ms, 5.0);
    EXPECT_EQ(set.realtime.max_late_pct, 0.5);
    EXPECT_EQ(set.realtime.max_lateness_ms, 40.0);
    EXPECT_TRUE(set.realtime.devices.empty());
    // A device's own limits: what it leaves out takes the case's.
    const CaseSpec own = parse_case(realtime +
                                        "realtime:\n  late_after_ms: 50\n  devices:\n"
                                        "    camera_left: { late_after_ms: 85, max_lateness_ms: 85 }\n",
                                    "case.yaml");
    ASSERT_EQ(own.realtime.devices.count("camera_left"), 1u);
    EXPECT_EQ(own.realtime.devices.at("camera_left").late_after_ms, 85.0);
    EXPECT_EQ(own.realtime.devices.at("camera_left").max_lateness_ms, 85.0);
    EXPECT_EQ(own.realtime.devices.at("camera_left").max_late_pct, 1.0);
    EXPECT_EQ(own.realtime.limits_of("camera_left").late_after_ms, 85.0);
    EXPECT_EQ(own.realtime.limits_of("boundary_plant").late_after_ms, 50.0);
    ASSERT_TRUE(set.rig_faults.has_value());
    EXPECT_EQ(set.rig_faults->master_stall_at_s, 3.0);
    EXPECT_EQ(set.rig_faults->master_stall_for_s, 0.5);
    struct Bad {
        std::string text;
        const char* key_path;
        const char* message_part;
    };
    const std::vector<Bad> bad = {
        {realtime + "realtime: { late_after_ms: 0 }\n", "realtime.late_after_ms", "must be"},
        {realtime + "realtime: { max_late_pct: 101 }\n", "realtime.max_late_pct", "must be"},
        {realtime + "realtime: { max_lateness_ms: 0.5 }\n", "realtime.max_lateness_ms", "must be"},
        {realtime + "realtime: { late_after_ms: 50, max_lateness_ms: 20 }\n", "realtime.max_lateness_ms",
         "is below late_after_ms"},
        {realtime + "realtime: { late_after_ms: 500 }\n", "realtime.late_after_ms", "is below late_after_ms"},
        {realtime + "realtime: { max_jitter_ms: 5 }\n", "realtime.max_jitter_ms", ""},
        {realtime + "realtime: { devices: { camera_left: { late_after_ms: 0 } } }\n",
         "realtime.devices.camera_left.late_after_ms", "must be"},
        // A device's maximum below the case's late_after_ms it inherits.
        {realtime + "realtime: { late_after_ms: 50, devices: { camera_left: { max_lateness_ms: 20 } } }\n",
         "realtime.devices.camera_left.max_lateness_ms", "is below late_after_ms"},
        {realtime + "realtime: { devices: { camera_left: { late_ms: 5 } } }\n", "realtime.devices.camera_left.late_ms", ""},
        {realtime + "rig_faults: { master_stall_at_s: 3 }\n", "rig_faults.master_stall_for_s", ""},
        {realtime + "rig_faults: { master_stall_at_s: 3, master_stall_for_s: 0 }\n", "rig_faults.master_stall_for_s",
         "must be"},
        // Lockstep has no wall clock to be late on.
        {std::string(kMinimalCase) + "realtime: { max_lateness_ms: 50 }\n", "realtime", "only with `mode: realtime`"},
        {std::string(kMinimalCase) + "rig_faults: { master_stall_at_s: 3, master_stall_for_s: 1 }\n", "rig_faults",
         "only with `mode: realtime`"},
    };
    for (const Bad& one : bad) {
        SCOPED_TRACE(one.text);
        try {
            parse_case(one.text, "case.yaml");
            ADD_FAILURE() << "accepted";
        } catch (const rig::ConfigError& error) {
            EXPECT_EQ(error.key_path(), one.key_path) << error.what();
            EXPECT_NE(error.message().find(one.message_part), std::string::npos) << error.what();
        }
    }
    // The stall must fall within the case, as any timed event.
    const CaseSpec stall = parse_case(realtime + "rig_faults: { master_stall_at_s: 30, master_stall_for_s: 1 }\n",
                                      "case.yaml");
    EXPECT_NO_THROW(check_case_timeline(stall, 60.0, 40.0));
    try {
        check_case_timeline(stall, 20.0, 10.0);
        ADD_FAILURE() << "accepted a stall after the end";
    } catch (const rig::ConfigError& error) {
        EXPECT_EQ(error.key_path(), "rig_faults.master_stall_at_s") << error.what();
        EXPECT_NE(error.message().find("after the case ends"), std::string::npos) << error.what();
    }
}

}  // namespace
}  // namespace rig::harness
