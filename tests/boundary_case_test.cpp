// Seed 001's boundary cases without DDS: the loader (harness/systems/boundary/
// boundary_case.h through the case loader), the job a seed-001 controller is
// given and the reference controller's reading of it, the judging plan's round
// trip through the trace's JSON, and the judge's rebuilding of the ground and
// of flow per duty from truth samples with a known answer
// (harness/systems/boundary/boundary_judge.h).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <map>
#include <string>
#include <vector>

#include "controller/boundary/boundary_node_config.h"
#include "harness/spec/case_spec.h"
#include "harness/systems/boundary/boundary_case.h"
#include "harness/systems/boundary/boundary_judge.h"
#include "harness/systems/systems.h"
#include "run_support.h"

namespace {

namespace fs = std::filesystem;
using namespace rig::harness;

std::string shipped(const std::string& relative) {
    std::ifstream in(fs::path(RIG_SOURCE_DIR) / "cases" / relative);
    std::stringstream text;
    text << in.rdbuf();
    return text.str();
}

// The shipped drive-out case with one line replaced (the test fails if the line is gone).
std::string edited(const std::string& from, const std::string& to) {
    std::string text = shipped("seed001-table8-boundary/drive-out.yaml");
    const auto at = text.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    if (at != std::string::npos) text.replace(at, from.size(), to);
    return text;
}

std::string load_error(const std::string& text) {
    try {
        parse_case(text, "case.yaml");
    } catch (const rig::ConfigError& error) {
        return error.what();
    }
    return "(accepted)";
}

TEST(BoundaryCase, TheShippedDriveOutCaseReadsAsWritten) {
    const CaseSpec spec = parse_case(shipped("seed001-table8-boundary/drive-out.yaml"), "drive-out.yaml");
    ASSERT_EQ(system_of(spec).name(), "boundary");
    const BoundarySections& b = boundary_sections(spec);
    EXPECT_EQ(b.corners.size(), 4u);
    EXPECT_DOUBLE_EQ(b.route_start.position.north_m, -12.0);
    EXPECT_EQ(b.route_segments.size(), 2u);
    ASSERT_EQ(b.edges.size(), 1u);
    EXPECT_EQ(b.edges[0].metric, "drive_out_excess");
    EXPECT_EQ(spec.seeds, (std::vector<std::uint64_t>{1, 2, 3}));
    // No seed-000 default limit is added to a boundary case.
    EXPECT_EQ(effective_limits(spec), (std::map<std::string, double>{{"drive_out_excess_mean_m", 0.50}}));
    // The controller's section is the controller's, as written: the rig adds none of its keys.
    EXPECT_FALSE(spec.controller.params.present && spec.controller.params.node["areas"]);
}

// The area goes to the controller in the job (docs/controller-contract.md "The
// job"), which the reference controller reads back to the same numbers: its
// areas unless its section names its own, and the cameras when the case has them.
TEST(BoundaryCase, TheJobCarriesTheAreaAndTheCamerasToTheController) {
    const fs::path dir = rig::testing::fresh_dir("boundary-job");
    const CaseSpec spec = parse_case(shipped("seed001-table8-boundary/drive-out.yaml"), "drive-out.yaml");
    const std::vector<std::string> args = system_of(spec).plan_run(spec, 1)->write_controller_inputs(dir);
    ASSERT_EQ(args, (std::vector<std::string>{"--job", (dir / "job.yaml").string()}));
    const rig::controller::boundary::BoundaryJob job = rig::controller::boundary::load_boundary_job(dir / "job.yaml");
    const BoundarySections& b = boundary_sections(spec);
    ASSERT_EQ(job.areas.size(), 1u);
    EXPECT_EQ(job.areas[0].name, b.area_name);
    EXPECT_EQ(job.areas[0].density, b.area_density);
    ASSERT_EQ(job.areas[0].corners.size(), b.corners.size());
    for (std::size_t i = 0; i < b.corners.size(); ++i) {
        EXPECT_EQ(job.areas[0].corners[i].lat_deg, b.corners[i].lat_deg);  // exactly: the same double
        EXPECT_EQ(job.areas[0].corners[i].lon_deg, b.corners[i].lon_deg);
    }
    EXPECT_FALSE(job.cameras);
    // Without areas of its own the controller takes the job's; its own win.
    const auto config = [&](const std::string& section) {
        return rig::controller::boundary::parse_boundary_node_config(
            rig::YamlSection::load_string(section, "controller.yaml"), job);
    };
    EXPECT_EQ(config("{}").controller.areas.size(), 1u);
    const auto own = config("areas: [ { name: mine, corners: [ { lat_deg: 1, lon_deg: 1 }, { lat_deg: 1, lon_deg: 1.001 }, "
                            "{ lat_deg: 1.001, lon_deg: 1 } ] } ]");
    ASSERT_EQ(own.controller.areas.size(), 1u);
    EXPECT_EQ(own.controller.areas[0].name, "mine");
    EXPECT_FALSE(config("{}").vision.enabled);

    // A vision case: the cameras, and the calibration scene's end, in the job.
    const CaseSpec vision =
        parse_case(shipped("seed001-vision-faults/calibrated-turned-camera.yaml"), "vision.yaml");
    const fs::path vision_dir = rig::testing::fresh_dir("boundary-job-vision");
    system_of(vision).plan_run(vision, 1)->write_controller_inputs(vision_dir);
    const rig::controller::boundary::BoundaryJob with_cameras =
        rig::controller::boundary::load_boundary_job(vision_dir / "job.yaml");
    EXPECT_TRUE(with_cameras.cameras);
    EXPECT_EQ(with_cameras.left_camera_topic, "device/camera_left/frame");
    EXPECT_GT(with_cameras.calibration_scene_until_s, 0.0);
    const auto node = rig::controller::boundary::parse_boundary_node_config(
        rig::YamlSection::load_string("{}", "controller.yaml"), with_cameras);
    EXPECT_TRUE(node.vision.enabled);
    EXPECT_EQ(node.vision.calibration_until_s, with_cameras.calibration_scene_until_s);
    // A section that says how to see keeps its say.
    EXPECT_FALSE(rig::controller::boundary::parse_boundary_node_config(
                     rig::YamlSection::load_string("vision: { enabled: false }", "controller.yaml"), with_cameras)
                     .vision.enabled);
}

// The job also carries the field's origin and the sprayer as the case builds
// it (docs/controller-contract.md "The job"): a case with its own four nozzles,
// lift, laser mounting and PWM frequency reaches the controller whole, and the
// reference controller takes it where its own section is silent.
TEST(BoundaryCase, TheJobCarriesTheFieldAndTheSprayerAsTheCaseHasThem) {
    const std::string text =
        edited("judge:\n",
               "spray:\n"
               "  flow_table:\n"
               "    - { points: [ { duty_pct: 30, flow_ml_min: 420 }, { duty_pct: 100, flow_ml_min: 650 } ] }\n"
               "    - { points: [ { duty_pct: 30, flow_ml_min: 420 }, { duty_pct: 100, flow_ml_min: 650 } ] }\n"
               "    - { points: [ { duty_pct: 30, flow_ml_min: 420 }, { duty_pct: 100, flow_ml_min: 650 } ] }\n"
               "    - { points: [ { duty_pct: 30, flow_ml_min: 420 }, { duty_pct: 100, flow_ml_min: 650 } ] }\n"
               "sprayer:\n"
               "  nozzle_count: 4\n"
               "  nozzle_spacing_m: 0.35\n"
               "  lift: { rod_length_m: 0.6, hinge_height_m: 0.85, antenna_to_o_m: 0.25, hinge_to_boom_centre_m: 1.1 }\n"
               "laser: { mount_offset_m: 0.07 }\n"
               "valves: { frequency_hz: 12.5 }\n"
               "judge:\n");
    const CaseSpec spec = parse_case(text, "own-sprayer.yaml");
    const BoundarySections& b = boundary_sections(spec);
    const fs::path dir = rig::testing::fresh_dir("boundary-job-sprayer");
    system_of(spec).plan_run(spec, 1)->write_controller_inputs(dir);
    const rig::controller::boundary::BoundaryJob job = rig::controller::boundary::load_boundary_job(dir / "job.yaml");
    // Exactly the case's doubles (shortest round-trip text).
    EXPECT_EQ(job.field_origin.lat_deg, b.origin.lat_deg);
    EXPECT_EQ(job.field_origin.lon_deg, b.origin.lon_deg);
    EXPECT_EQ(job.field_origin_height_m, b.origin.height_m);
    // The sprayer: nozzles, Eq. 18's I, Hp, M, L, the laser's mounting, the PWM
    // frequency (the job's and the reference configuration's names are the same).
    const auto sprayer_of = [](const auto& s) {
        return std::vector<double>{static_cast<double>(s.nozzle_count), s.nozzle_spacing_m, s.lift_rod_length_m,
                                   s.lift_hinge_height_m, s.antenna_to_o_m, s.hinge_to_boom_centre_m,
                                   s.laser_mount_offset_m, s.pwm_frequency_hz};
    };
    const std::vector<double> case_sprayer{4, 0.35, 0.6, 0.85, 0.25, 1.1, 0.07, 12.5};
    EXPECT_EQ(sprayer_of(job), case_sprayer);

    const auto config = [&](const std::string& section) {
        return rig::controller::boundary::parse_boundary_node_config(
                   rig::YamlSection::load_string(section, "controller.yaml"), job)
            .controller;
    };
    // The reference controller's own keys of the same meaning take the job's.
    EXPECT_EQ(sprayer_of(config("{}")), case_sprayer);
    // The controller's own section wins (a wrong belief is the case's to give).
    const rig::controller::boundary::BoundaryControllerConfig own = config("nozzle_spacing_m: 0.5\npwm_frequency_hz: 9\n");
    EXPECT_EQ(own.nozzle_spacing_m, 0.5);
    EXPECT_EQ(own.pwm_frequency_hz, 9.0);
    EXPECT_EQ(own.nozzle_count, 4);

    // A job without the sprayer is refused at its key, naming the file.
    std::string broken = rig::testing::read_all(dir / "job.yaml");
    const std::size_t at = broken.find("nozzle_spacing_m:");
    ASSERT_NE(at, std::string::npos) << broken;
    broken.replace(at, std::string("nozzle_spacing_m").size(), "nozzle_pitch_m");
    std::ofstream(dir / "broken-job.yaml") << broken;
    try {
        rig::controller::boundary::load_boundary_job(dir / "broken-job.yaml");
        ADD_FAILURE() << "a job without sprayer.nozzle_spacing_m was accepted";
    } catch (const rig::ConfigError& error) {
        const std::string message = error.what();
        EXPECT_NE(message.find("broken-job.yaml:"), std::string::npos) << message;
        EXPECT_NE(message.find("nozzle_pitch_m"), std::string::npos) << message;
    }
}

TEST(BoundaryCase, MistakesAreErrorsAtTheirKey) {
    // A misspelt key, with the known one suggested.
    EXPECT_NE(load_error(edited("judge:\n", "ad300: { latency: 0.05 }\njudge:\n")).find("ad300.latency"), std::string::npos);
    // A value an emulator refuses is reported at its section, naming the parameter.
    const std::string rate = load_error(edited("judge:\n", "ad300: { rate_hz: 0 }\njudge:\n"));
    EXPECT_NE(rate.find("case.yaml:"), std::string::npos) << rate;
    EXPECT_NE(rate.find("ad300"), std::string::npos) << rate;
    EXPECT_NE(rate.find("rate_hz"), std::string::npos) << rate;
    // An unknown edge metric.
    const std::string metric = load_error(edited("metric: drive_out_excess", "metric: drive_out"));
    EXPECT_NE(metric.find("judge.edges[0].metric"), std::string::npos) << metric;
    // An expected failure with no limit in the file.
    const std::string expect = load_error(edited("limits:\n", "expect: { fail: [drive_in_excess_mean_m] }\nlimits:\n"));
    EXPECT_NE(expect.find("expect.fail[0]"), std::string::npos) << expect;
    // A case that judges nothing.
    EXPECT_NE(load_error(edited("  edges:\n", "  unused_edges:\n")).find("judge"), std::string::npos);
    // A corner recorded twice is no polygon: refused at `area`, naming it.
    const std::string area = load_error(edited("    - { lat_deg: 35.1000000000, lon_deg: 113.2998903247 }",
                                               "    - { lat_deg: 35.1000000000, lon_deg: 113.3001096753 }"));
    EXPECT_NE(area.find(": area: "), std::string::npos) << area;
    EXPECT_NE(area.find("plot"), std::string::npos) << area;
    // A system the rig does not know.
    EXPECT_NE(load_error(edited("system: boundary", "system: boundry")).find("did you mean 'boundary'"), std::string::npos);
}

// `guidance:` (docs/guidance.md): absent or `{}`, every default (the sprayer
// is autosteered); `off`, the route is driven exactly; any other word is an
// error naming it; a value outside its bounds or an unknown key is an error at
// the section, naming the key.
TEST(BoundaryCase, GuidanceIsOnUnlessOffAndItsValuesAreHeldToTheirBounds) {
    const auto guidance_of = [](const std::string& text) { return boundary_sections(parse_case(text, "case.yaml")).guidance; };
    const auto without = guidance_of(edited("judge:\n", "judge:\n"));
    ASSERT_TRUE(without.has_value());
    EXPECT_EQ(without->yaw_disturbance_sd_deg_m, rig::emulators::guidance::GuidanceParams{}.yaw_disturbance_sd_deg_m);
    EXPECT_FALSE(guidance_of(edited("judge:\n", "guidance: off\njudge:\n")).has_value());
    const std::string word = load_error(edited("judge:\n", "guidance: on\njudge:\n"));
    EXPECT_NE(word.find("guidance: expected off (the route driven exactly) or a mapping"), std::string::npos) << word;
    EXPECT_NE(word.find("'on'"), std::string::npos) << word;
    EXPECT_NE(load_error(edited("judge:\n", "guidance: [ 1 ]\njudge:\n")).find("guidance: expected off"),
              std::string::npos);
    const auto defaults = guidance_of(edited("judge:\n", "guidance: {}\njudge:\n"));
    ASSERT_TRUE(defaults.has_value());
    EXPECT_EQ(defaults->wheelbase_m, rig::emulators::guidance::GuidanceParams{}.wheelbase_m);
    EXPECT_EQ(guidance_of(edited("judge:\n", "guidance: { wheelbase_m: 2.4 }\njudge:\n"))->wheelbase_m, 2.4);
    const std::string bounds = load_error(edited("judge:\n", "guidance: { terrain_compensation: 1.5 }\njudge:\n"));
    EXPECT_NE(bounds.find("case.yaml:"), std::string::npos) << bounds;
    EXPECT_NE(bounds.find("guidance.terrain_compensation: must be in [0.000000, 1.000000]"), std::string::npos) << bounds;
    const std::string unknown = load_error(edited("judge:\n", "guidance: { wheelbase: 2.4 }\njudge:\n"));
    EXPECT_NE(unknown.find("guidance.wheelbase"), std::string::npos) << unknown;
    // Seed 000's antenna keys are not seed 001's (its antenna is sprayer.mounting's).
    EXPECT_NE(load_error(edited("judge:\n", "guidance: { antenna_height_m: 2 }\njudge:\n")).find("antenna_height_m"),
              std::string::npos);
}

// The bench path's keys (docs/seed001-boundary.md "Bench path"): the shipped
// wired case reads as written; each wire that cannot work is refused at its key.
TEST(BoundaryCase, BenchWiringReadsAndWhatCannotWorkIsRefusedAtItsKey) {
    const CaseSpec wired = parse_case(shipped("bench-wired/seed001-drive-out-wired.yaml"), "drive-out-wired.yaml");
    EXPECT_EQ(wired.mode, rig::ClockMode::realtime);
    EXPECT_EQ(wired.wiring.gnss, GnssWire::serial);
    EXPECT_EQ(wired.wiring.laser, GnssWire::serial);
    EXPECT_EQ(wired.wiring.laser_port, "pty");
    EXPECT_EQ(wired.wiring.board_io, BoardIoWireKind::dds);
    EXPECT_FALSE(wired.wiring.external_controller);
    EXPECT_DOUBLE_EQ(wired.realtime.max_lateness_ms, 100.0);

    const auto with = [&](const std::string& extra) { return edited("seeds: [1, 2, 3]\n", "seeds: [1, 2, 3]\n" + extra); };
    // Real time on DDS wires only is a case of its own (no wire, no attach).
    EXPECT_EQ(load_error(with("mode: realtime\n")), "(accepted)");
    // A serial line has no virtual time.
    const std::string lockstep = load_error(with("wiring: { laser: serial }\n"));
    EXPECT_NE(lockstep.find("wiring"), std::string::npos) << lockstep;
    EXPECT_NE(lockstep.find("mode: realtime"), std::string::npos) << lockstep;
    // The Pi has no Modbus I/O.
    const std::string modbus = load_error(with("mode: realtime\nwiring: { gnss: serial, board_io: modbus_rtu }\n"));
    EXPECT_NE(modbus.find("wiring.board_io"), std::string::npos) << modbus;
    // The capture is a wired board's PWM: a controller process would be a second writer.
    const std::string hid = load_error(with("mode: realtime\nwiring: { gnss: serial, board_io: hid }\n"));
    EXPECT_NE(hid.find("controller: external"), std::string::npos) << hid;
    EXPECT_EQ(load_error(with("mode: realtime\nwiring: { gnss: serial, laser: serial, board_io: hid, controller: external }\n")),
              "(accepted)");
    // The capture is read at most at 1 kHz.
    const std::string rate =
        load_error(with("mode: realtime\nwiring: { gnss: serial, board_io: hid, controller: external, board_update_hz: 1500 }\n"));
    EXPECT_NE(rate.find("wiring.board_update_hz"), std::string::npos) << rate;
    // An external board needs a wire to attach to.
    EXPECT_NE(load_error(with("mode: realtime\nwiring: { controller: external }\n")).find("bench wire"), std::string::npos);
    // A misspelt value and a bad baud, at their keys.
    EXPECT_NE(load_error(with("mode: realtime\nwiring: { laser: serail }\n")).find("wiring.laser"), std::string::npos);
    EXPECT_NE(load_error(with("mode: realtime\nwiring: { laser: serial, laser_baud: 7 }\n")).find("wiring.laser_baud"),
              std::string::npos);
    // The real-time bound belongs to real-time runs.
    EXPECT_NE(load_error(with("realtime: { max_lateness_ms: 50 }\n")).find("realtime"), std::string::npos);
}

TEST(BoundaryJudge, ThePlanSurvivesTheTracesJson) {
    const CaseSpec spec = parse_case(shipped("seed001-table8-boundary/drive-out.yaml"), "drive-out.yaml");
    const BoundaryJudgingPlan plan = plan_boundary_judging(boundary_sections(spec));
    // The north edge (north = 0), the area on its left: from east +10 to -10.
    ASSERT_EQ(plan.edges.size(), 1u);
    EXPECT_NEAR(plan.edges[0].edge.from_east_m, 10.0, 1e-3);
    EXPECT_NEAR(plan.edges[0].edge.to_east_m, -10.0, 1e-3);
    EXPECT_NEAR(plan.edges[0].edge.from_north_m, 0.0, 1e-3);
    const BoundaryJudgingPlan back = boundary_judging_plan_from_json(nlohmann::json::parse(to_json(plan).dump()));
    EXPECT_EQ(to_json(back), to_json(plan));
    EXPECT_EQ(back.flow_table.size(), 6u);
    EXPECT_THROW(boundary_judging_plan_from_json(nlohmann::json::object()), std::runtime_error);
}

BoundaryJudgingPlan small_plan() {
    BoundaryJudgingPlan plan;
    plan.ground.east_min_m = -2;
    plan.ground.east_max_m = 2;
    plan.ground.north_min_m = -2;
    plan.ground.north_max_m = 2;
    plan.ground.cell_m = 0.02;
    plan.ground.nozzle_count = 1;
    return plan;
}

NozzleStepTruth step_at(double t_s, double north_m, double delivered_l, double duty_pct = 100.0) {
    NozzleStepTruth step;
    step.t_ns = rig::seconds_to_ns(t_s);
    step.heading_deg = 0.0;
    step.boom_height_m = 0.5;
    step.position = {{0.0, north_m}};
    step.duty_pct = {duty_pct};
    step.delivered_l = {delivered_l};
    return step;
}

TEST(BoundaryJudge, TheGroundIsEachStepsVolumeLaidAsTheFanBand) {
    // One nozzle driving north at 1 m/s, 1 mL per 5 ms step, from north -1 to +1.
    std::vector<NozzleStepTruth> steps;
    for (int k = 0; k <= 400; ++k) steps.push_back(step_at(k * 0.005, -1.0 + k * 0.005, 0.001 * k));
    const std::vector<DoseRaster> layers = ground_from_truth(steps, small_plan());
    ASSERT_EQ(layers.size(), 1u);
    double litres = 0.0;
    for (double dose : layers[0].dose_ul_cm2) litres += dose * 2.0 * 2.0 * 1e-6;  // uL/cm^2 x 4 cm^2 -> L
    EXPECT_NEAR(litres, 0.400, 1e-9);  // the first sample is the reference, the 400 after it deliver
    // Across the track the fan reaches H tan 55 deg = 0.714 m: an edge along
    // east = 0.5 (outside to the east) sees the wet edge 0.214 m past it.
    const BoundaryEdge edge{0.5, -1.5, 0.5, 1.5};
    EdgeProbe probe;
    probe.from_m = 1.0;
    probe.to_m = 2.0;
    std::map<std::string, std::string> not_measured;
    const auto m = excess_metrics("boundary_overrun", wet_edge_profile(layers[0], edge, probe), not_measured);
    EXPECT_NEAR(m.at("boundary_overrun_mean_m"), 0.714 - 0.5, 0.02);
}

TEST(BoundaryJudge, AVolumeThatGoesBackIsAnErrorNotAStepClampedToZero) {
    // delivered_l counts since the start: 2 mL then 1 mL is no step of -1 mL
    // to leave out (the judge once laid max(0, ...)), but a trace that does not hold together.
    const std::vector<NozzleStepTruth> steps = {step_at(0.0, 0.0, 0.002), step_at(0.005, 0.005, 0.001)};
    try {
        ground_from_truth(steps, small_plan());
        FAIL() << "a delivered volume going back passed";
    } catch (const std::runtime_error& error) {
        EXPECT_EQ(std::string(error.what()), "truth/nozzles at t_ns 5000000: nozzle 0 delivered_l 0.001 L after 0.002 L (it only grows)");
    }
}

TEST(BoundaryJudge, FlowPerDutyIsTheVolumeOverWholePwmPeriods) {
    BoundaryJudgingPlan plan = small_plan();
    plan.flow_settle_s = 0.5;
    // 0.6 L/min at 100 % for 5 s, then 0.3 L/min at 40 % for 5 s, sampled every 5 ms.
    std::vector<NozzleStepTruth> steps;
    double delivered = 0.0;
    for (int k = 0; k < 2000; ++k) {
        const bool first = k < 1000;
        delivered += (first ? 0.6 : 0.3) / 60.0 * 0.005;
        steps.push_back(step_at(k * 0.005, 0.0, delivered, first ? 100.0 : 40.0));
    }
    const std::vector<FlowRecord> records = flow_records_from_truth(steps, plan);
    ASSERT_EQ(records.size(), 2u);
    EXPECT_EQ(records[0].duty_pct, 100.0);
    EXPECT_NEAR(records[0].volume_l / records[0].duration_s * 60.0, 0.6, 1e-9);
    EXPECT_EQ(records[1].duty_pct, 40.0);
    EXPECT_NEAR(records[1].volume_l / records[1].duration_s * 60.0, 0.3, 1e-9);
    // A window a whole number of 1/9 s periods long, within one 5 ms step.
    for (const FlowRecord& r : records) {
        const double periods = r.duration_s * 9.0;
        EXPECT_NEAR(periods, std::round(periods), 0.005 * 9.0);
        EXPECT_GT(r.duration_s, 4.0);
    }
}

}  // namespace
