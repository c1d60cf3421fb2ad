#include "harness/systems/breakpoint/breakpoint_system.h"

#include <functional>
#include <optional>

#include "emulators/boom_height_sensor.h"
#include "emulators/flow_meter_kf11.h"
#include "emulators/panel_switch.h"
#include "emulators/plant.h"
#include "emulators/pump_flow_sensor.h"
#include "emulators/spray_circuit.h"
#include "emulators/spray_circuit_node.h"
#include "emulators/wheel_encoder.h"
#include "harness/session/case_session.h"
#include "harness/systems/breakpoint/breakpoint_case.h"
#include "harness/systems/breakpoint/breakpoint_judge.h"
#include "harness/systems/breakpoint/breakpoint_world.h"
#include "harness/systems/breakpoint/gnss_wire_faults.h"
#include "harness/trace/trace_json.h"
#include "harness/trace/trace_recorder.h"
#include "idl/topics.h"
#include "rig/runtime/io_image.h"
#include "rig/wire/wire_adapters.h"

namespace rig::harness {

namespace {

// How often the plant publishes its truth (the judge's time resolution).
constexpr double kVehicleTruthRateHz = 20.0;
constexpr double kHydraulicsTruthRateHz = 100.0;

emulators::Kf11Params kf11_params(const FlowMeterSpec& meter) {
    emulators::Kf11Params params;  // the meter's own minimum flow
    params.pulses_per_l = meter.pulses_per_l;
    params.k_factor_error_pct = meter.k_factor_error_pct;
    params.rate_hz = meter.rate_hz;
    return params;
}

// The device emulators and the plant as the case's local nodes, in the order
// they step each instant: plant truth and the spray circuit (which takes the
// actuator commands) before the devices sample them, the wire adapters last
// (they carry what the devices published). The circuit itself is the master's
// to advance (truth()), once per instant before any of them steps.
class BreakpointNodes final : public SystemNodes {
public:
    BreakpointNodes(const BreakpointSections& own, const BreakpointWorld& world, emulators::SprayCircuit& circuit,
                    std::uint64_t seed, const WiringSpec& wiring, BenchWires& wires)
        : circuit_(circuit),
          plant_(world.plant, kVehicleTruthRateHz),
          spray_circuit_(circuit, kHydraulicsTruthRateHz),
          gnss_(world.plant, world.gnss),
          encoder_(world.plant, emulators::WheelEncoderParams{own.encoder.pulses_per_rev, own.encoder.wheel_diameter_m,
                                                              own.encoder.rate_hz}),
          flow_meter_(circuit, kf11_params(own.flow_meter)),
          pump_sensor_(circuit, emulators::PumpFlowSensorParams{own.pump_sensor.full_scale_m3_h, own.pump_sensor.noise_mv,
                                                                own.pump_sensor.offset_ma, own.pump_sensor.rate_hz, seed}),
          boom_height_(world.plant,
                       emulators::BoomHeightSensorParams{own.boom_height_sensor.range_m, own.boom_height_sensor.rate_hz}),
          button_("breakpoint_button", topics::kBreakpointButton, world.scenario.button),
          spray_switch_("spray_switch", topics::kSpraySwitch, world.scenario.spray_switch),
          wire_faults_(own.gnss.wire_faults) {
        all_ = {&plant_, &spray_circuit_, &gnss_, &encoder_, &flow_meter_, &pump_sensor_, &boom_height_, &button_, &spray_switch_};
        if (wires.gnss_port) all_.push_back(&nmea_adapter_.emplace(*wires.gnss_port));
        if (wires.board_io) all_.push_back(&board_adapter_.emplace(*wires.board_io, wiring.board_update_hz));
    }

    std::vector<Node*> nodes() override { return all_; }
    TruthModel* truth() override { return &circuit_; }
    void run_completed(TimeNs end_ns) override { circuit_.advance_to(end_ns); }

    void finish(TraceFile& trace, RunFacts& facts, const std::filesystem::path& case_dir) override {
        (void)facts;
        (void)case_dir;
        // Whatever the ending, the spray on the ground so far is part of the record.
        record_deposition(trace, circuit_.deposition());
        std::vector<LandingEdgeRow> edges;
        for (const emulators::LandingEdge& edge : circuit_.landing_edges()) edges.push_back({edge.at_ns, edge.landing});
        trace.record_landing_edges(edges);
        if (wire_faults_.any()) {
            trace.set_meta(kGnssWireFaultsMeta, gnss_wire_fault_json(wire_faults_, gnss_.wire_fault_counts()).dump());
        }
    }

private:
    emulators::SprayCircuit& circuit_;
    emulators::PlantNode plant_;
    emulators::SprayCircuitNode spray_circuit_;
    emulators::GnssG970 gnss_;
    emulators::WheelEncoder encoder_;
    emulators::FlowMeterKf11 flow_meter_;
    emulators::PumpFlowSensor pump_sensor_;
    emulators::BoomHeightSensor boom_height_;
    emulators::PanelSwitch button_;
    emulators::PanelSwitch spray_switch_;
    std::optional<NmeaSerialAdapter> nmea_adapter_;
    std::optional<BoardIoAdapter> board_adapter_;
    GnssWireFaultsSpec wire_faults_;
    std::vector<Node*> all_;
};

// One field of each sample of `topic` as a key signal; samples without it
// (a number) are left out, and so is a signal without any.
void add_signal(std::vector<KeySignal>& signals, const RecordedTrace& trace, const char* topic, KeySignal signal,
                const std::function<std::optional<double>(const nlohmann::json&)>& value_of) {
    for (const RecordedSample& sample : trace.samples(topic)) {
        if (const std::optional<double> value = value_of(sample.json)) {
            signal.points.push_back({ns_to_seconds(sample.t_ns), *value});
        }
    }
    if (!signal.points.empty()) signals.push_back(std::move(signal));
}

std::function<std::optional<double>(const nlohmann::json&)> field(const char* key) {
    return [key](const nlohmann::json& sample) -> std::optional<double> {
        const auto it = sample.find(key);
        if (it == sample.end() || !it->is_number()) return std::nullopt;
        return it->get<double>();
    };
}

// Flow, valve, sections and where the nozzle line is against the breakpoint:
// what the paper's Fig. 14 and Table 2 are made of.
std::vector<KeySignal> breakpoint_key_signals(const RecordedTrace& trace) {
    std::vector<KeySignal> signals;
    add_signal(signals, trace, topics::kHydraulicsTruth, {"main-pipeline flow (truth)", "L/min", false, {}},
               field("main_flow_l_min"));
    add_signal(signals, trace, topics::kHydraulicsTruth, {"valve opening (truth)", "%", false, {}},
               field("valve_opening_pct"));
    add_signal(signals, trace, topics::kSectionValves,
               {"sections commanded open (bit i: section i)", "mask", true, {}}, field("open_mask"));
    add_signal(signals, trace, topics::kHydraulicsTruth, {"sections spraying (bit i: section i)", "mask", true, {}},
               field("sections_spraying_mask"));
    // The breakpoint is the case's, in the judging plan; a plan without one has nothing to measure against.
    const nlohmann::json plan = nlohmann::json::parse(trace.meta_or("judging"), nullptr, /*allow_exceptions=*/false);
    if (plan.is_object() && plan.contains("breakpoint_along_m") && plan["breakpoint_along_m"].is_number()) {
        const double breakpoint_along_m = plan["breakpoint_along_m"].get<double>();
        const auto nozzle_line_along_m = field("nozzle_line_along_m");
        add_signal(signals, trace, topics::kVehicleTruth,
                   {"nozzle line to the breakpoint, negative before it", "m", false, {}},
                   [&](const nlohmann::json& sample) -> std::optional<double> {
                       const std::optional<double> along_m = nozzle_line_along_m(sample);
                       if (!along_m) return std::nullopt;
                       return *along_m - breakpoint_along_m;
                   });
    }
    return signals;
}

class BreakpointRun final : public SystemRun {
public:
    BreakpointRun(const CaseSpec& spec, std::uint64_t seed)
        : own_(breakpoint_sections(spec)),
          wiring_(spec.wiring),
          seed_(seed),
          world_(build_case_world(own_, seed)),
          circuit_(world_.plant, world_.circuit),
          plan_(plan_judging(own_, world_, effective_limits(spec))) {}

    TimeNs end_ns() const override { return world_.end_ns; }

    void check_timeline(const CaseSpec& spec) const override {
        check_case_timeline(spec, ns_to_seconds(world_.end_ns), world_.breakpoint_crossing_s);
    }

    void add_judging_plan(nlohmann::json& plan) const override { add_breakpoint_keys(plan_, plan); }

    void record(TraceRecorder& trace) const override {
        // Fixed channel order: part of what makes the trace reproducible.
        trace.record<msg::VehicleTruth>(topics::kVehicleTruth);
        trace.record<msg::NmeaSentence>(topics::kGnssNmea);
        trace.record<msg::EncoderCount>(topics::kWheelEncoder);
        trace.record<msg::HydraulicsTruth>(topics::kHydraulicsTruth);
        trace.record<msg::FlowMeterCount>(topics::kMainFlowMeter);
        trace.record<msg::AnalogInput>(topics::kPumpFlowSensor);
        trace.record<msg::AnalogInput>(topics::kBoomHeightSensor);
        trace.record<msg::SwitchLevel>(topics::kBreakpointButton);
        trace.record<msg::SwitchLevel>(topics::kSpraySwitch);
        trace.record<msg::BallValveRelays>(topics::kBallValveRelays);
        trace.record<msg::SectionValves>(topics::kSectionValves);
        trace.record<msg::UnloadingValve>(topics::kUnloadingValve);
        trace.record<msg::ControllerStatus>(topics::kControllerStatus);
        trace.record<msg::BreakpointEvent>(topics::kBreakpointEvent);
        // The plant at the instant the controller acted (a pure function of t):
        // the judge then needs no interpolation, and no plant, to say where the sprayer was.
        const emulators::Plant& plant = world_.plant;
        trace.record_truth_at_controller_outputs<msg::VehicleTruth>(
            topics::kVehicleTruth, [&plant](TimeNs t) { return plant.truth_at(t); });
    }

    void describe_attach(nlohmann::json& attach, std::uint32_t dds_domain) const override {
        (void)dds_domain;
        // This case's sensor parameters behind the register map's scalings
        // (docs/modbus-register-map.md "Scalings" gives the defaults and formulas).
        attach["scalings"] = {{"adc_full_scale_counts", io::kAdcFullScale},
                              {"adc_reference_v", io::kAdcReferenceV},
                              {"pump_flow_full_scale_m3_h", own_.pump_sensor.full_scale_m3_h},
                              {"boom_height_range_m", own_.boom_height_sensor.range_m},
                              {"main_flow_pulses_per_l", own_.flow_meter.pulses_per_l},
                              {"wheel_encoder_pulses_per_rev", own_.encoder.pulses_per_rev},
                              {"wheel_diameter_m", own_.encoder.wheel_diameter_m},
                              {"capture_timer_hz", io::kCaptureTimerHz},
                              {"valve_travel_s", own_.hydraulics.valve_travel_s},
                              {"valve_motor_start_delay_s", own_.hydraulics.valve_motor_start_delay_s},
                              {"valve_backlash_pct", own_.hydraulics.valve_backlash_pct}};
    }

    std::unique_ptr<SystemNodes> make_nodes(BenchWires& wires) override {
        return std::make_unique<BreakpointNodes>(own_, world_, circuit_, seed_, wiring_, wires);
    }

private:
    const BreakpointSections& own_;
    WiringSpec wiring_;
    std::uint64_t seed_;
    BreakpointWorld world_;
    emulators::SprayCircuit circuit_;
    BreakpointJudgingPlan plan_;
};

class BreakpointSystem final : public System {
public:
    std::string_view name() const override { return "breakpoint"; }

    std::shared_ptr<const SystemSections> read_sections(const YamlSection& root) const override {
        return read_breakpoint_sections(root);
    }

    ReferenceController reference_controller() const override {
        return {"rig-controller", "rig-controller-plugin.so", "seed 000's reference controller"};
    }

    std::unique_ptr<SystemRun> plan_run(const CaseSpec& spec, std::uint64_t seed) const override {
        return std::make_unique<BreakpointRun>(spec, seed);
    }

    SystemJudgement judge(const RecordedTrace& trace, const nlohmann::json& plan) const override {
        return judge_breakpoint_trace(trace, breakpoint_judging_plan_from_json(plan));
    }

    std::vector<KeySignal> key_signals(const RecordedTrace& trace) const override {
        return breakpoint_key_signals(trace);
    }
};

}  // namespace

const System& breakpoint_system() {
    static const BreakpointSystem system;
    return system;
}

}  // namespace rig::harness
