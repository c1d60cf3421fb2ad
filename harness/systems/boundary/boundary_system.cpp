#include "harness/systems/boundary/boundary_system.h"

#include <fstream>
#include <optional>

#include <yaml-cpp/yaml.h>

#include "harness/session/case_session.h"
#include "harness/systems/boundary/boundary_case.h"
#include "harness/systems/boundary/boundary_judge.h"
#include "harness/systems/boundary/boundary_world.h"
#include "harness/trace/trace_recorder.h"
#include "idl/topics.h"
#include "rig/text/number_text.h"
#include "rig/wire/wire_adapters.h"

namespace rig::harness {

namespace {

// While nothing flows the plant reports truth this often (the 1-D plant's 20 Hz
// would double the trace for nothing: a still boom deposits nothing).
constexpr double kIdleTruthRateHz = 10.0;
// The job's file name, beside the controller's configuration (and attach.json).
constexpr const char* kJobFile = "job.yaml";

// The plant, the AD300, the L4 and the cameras, then the bench wires' adapters.
class BoundaryNodes final : public SystemNodes {
public:
    BoundaryNodes(const BoundarySections& own, const BoundaryWorld& world, std::uint64_t seed, const WiringSpec& wiring,
                  ClockMode clock, BenchWires& wires)
        : clock_(clock),
          plant_(world.kinematics, emulators::PwmNozzleValves(world.valves, own.flow_table_or_paper()), own.spray,
                 kIdleTruthRateHz),
          ad300_(world.kinematics, world.ad300),
          laser_(world.kinematics, world.laser) {
        all_ = {&plant_, &ad300_, &laser_};
        // Seed 001's cameras: the left one sees the first half of the nozzles (Sec. 1.1).
        if (world.vision) {
            const int count = own.mounting.nozzle_count;
            for (int camera = 0; camera < 2; ++camera) {
                std::vector<int> nozzles;
                std::vector<double> right_m;
                for (int n = camera * count / 2; n < (camera + 1) * count / 2; ++n) {
                    nozzles.push_back(n);
                    right_m.push_back((n - 0.5 * (count - 1)) * own.mounting.nozzle_spacing_m);
                }
                cameras_.push_back(std::make_unique<CameraNode>(world.kinematics, *world.crop,
                                                                camera == 0 ? world.vision->left : world.vision->right,
                                                                seed, camera, nozzles, right_m,
                                                                seconds_to_ns(world.vision->calibration_until_s), clock));
                // The report shows each camera's frame from the middle of the run.
                cameras_.back()->keep_frame_at(world.end_ns / 2);
                all_.push_back(cameras_.back().get());
            }
        }
        if (wires.gnss_port) all_.push_back(&nmea_adapter_.emplace(*wires.gnss_port));
        if (wires.laser_port) all_.push_back(&laser_adapter_.emplace(*wires.laser_port));
        if (auto* hid = dynamic_cast<HidBoardWire*>(wires.board_io.get())) {
            all_.push_back(&pwm_capture_.emplace(hid->board(), own.flow_table_or_paper().nozzle_count(),
                                                 wiring.board_update_hz));
        }
    }

    std::vector<Node*> nodes() override { return all_; }

    void finish(TraceFile& trace, RunFacts& facts, const std::filesystem::path& case_dir) override {
        nlohmann::json report_frames = nlohmann::json::array();
        for (std::size_t c = 0; c < cameras_.size(); ++c) {
            facts.system[cameras_[c]->name() + "_frames"] = cameras_[c]->frames_rendered();
            // Real time: whether the rendering thread got the weight its deadlines need.
            if (clock_ == ClockMode::realtime) facts.system[cameras_[c]->name() + "_rendering"] = cameras_[c]->render_scheduling();
            const std::string file = "frame-" + cameras_[c]->name() + ".png";
            if (const std::optional<std::uint64_t> number = cameras_[c]->write_report_frame(case_dir / file)) {
                report_frames.push_back({{"camera", c}, {"frame_number", *number}, {"file", file}});
            }
        }
        if (!cameras_.empty()) trace.set_meta("vision_report_frames", report_frames.dump());
        if (pwm_capture_) facts.system["nozzle_pwm_captured"] = pwm_capture_->published();
    }

private:
    ClockMode clock_;
    BoundaryPlantNode plant_;
    Ad300Node ad300_;
    L4LaserNode laser_;
    std::vector<std::unique_ptr<CameraNode>> cameras_;
    std::optional<NmeaSerialAdapter> nmea_adapter_;
    std::optional<LaserSerialAdapter> laser_adapter_;
    std::optional<NozzlePwmCaptureAdapter> pwm_capture_;
    std::vector<Node*> all_;
};

// A number in the job as the shortest text that reads back as the same
// double: the controller's values are the case's, bit for bit.
YAML::Node number(double value) { return YAML::Node(shortest_text(value)); }

// The job as the operator set it up before work (Sec. 4.2.2: the area's
// corners recorded with the receiver), and the machine as it stands: what a
// seed-001 controller is given besides its configuration. `field`, `sprayer`,
// `laser` and `valves` hold the case file's keys of the same names, `areas`
// its `area` (docs/controller-contract.md "The job" gives each key with its
// frame and unit); the route, the boom-height profile and the devices' noise
// stay the plant's, as they would in a field.
std::string job_yaml(const BoundarySections& own) {
    YAML::Node job;
    YAML::Node origin;
    origin["lat_deg"] = number(own.origin.lat_deg);
    origin["lon_deg"] = number(own.origin.lon_deg);
    origin["height_m"] = number(own.origin.height_m);
    job["field"]["origin"] = origin;
    YAML::Node area;
    area["name"] = own.area_name;
    area["density"] = number(own.area_density);
    for (const field2d::GeodeticPoint& corner : own.corners) {
        YAML::Node c;
        c["lat_deg"] = number(corner.lat_deg);
        c["lon_deg"] = number(corner.lon_deg);
        area["corners"].push_back(c);
    }
    job["areas"].push_back(area);
    // The boom relative to the antenna: nozzles across it, Eq. 18's lift along.
    YAML::Node lift;
    lift["rod_length_m"] = number(own.mounting.lift.rod_length_m);
    lift["hinge_height_m"] = number(own.mounting.lift.hinge_height_m);
    lift["antenna_to_o_m"] = number(own.mounting.lift.antenna_to_o_m);
    lift["hinge_to_boom_centre_m"] = number(own.mounting.lift.hinge_to_boom_centre_m);
    YAML::Node sprayer;
    sprayer["nozzle_count"] = own.mounting.nozzle_count;
    sprayer["nozzle_spacing_m"] = number(own.mounting.nozzle_spacing_m);
    sprayer["lift"] = lift;
    job["sprayer"] = sprayer;
    YAML::Node laser;
    laser["mount_offset_m"] = number(own.laser.mount_offset_m);
    job["laser"] = laser;
    YAML::Node valves;
    valves["frequency_hz"] = number(own.valves.frequency_hz);
    job["valves"] = valves;
    if (own.vision) {
        job["cameras"]["left"] = topics::kCameraLeftFrame;
        job["cameras"]["right"] = topics::kCameraRightFrame;
        if (own.vision->calibration_until_s > 0.0) {
            job["cameras"]["calibration_scene_until_s"] = number(own.vision->calibration_until_s);
        }
    }
    YAML::Emitter out;
    out << job;
    return std::string("# The job of this run (docs/controller-contract.md \"The job\"): the field, the target\n"
                       "# areas the operator recorded before work, the sprayer and the cameras on the boom.\n") +
           out.c_str() + "\n";
}

// The duty the controller commanded per nozzle (Sec. 3.2.1's PWM), held from
// one command to the next: where the boundary shut-off and the rate show.
std::vector<KeySignal> boundary_key_signals(const RecordedTrace& trace) {
    std::vector<KeySignal> signals;
    for (const RecordedSample& sample : trace.samples(topics::kNozzlePwm)) {
        const auto duties = sample.json.find("duty_pct");
        if (duties == sample.json.end() || !duties->is_array()) continue;
        for (std::size_t nozzle = 0; nozzle < duties->size(); ++nozzle) {
            if (!(*duties)[nozzle].is_number()) continue;
            if (signals.size() <= nozzle) signals.resize(nozzle + 1);
            signals[nozzle].points.push_back({ns_to_seconds(sample.t_ns), (*duties)[nozzle].get<double>()});
        }
    }
    for (std::size_t nozzle = 0; nozzle < signals.size(); ++nozzle) {
        signals[nozzle].name = "nozzle " + std::to_string(nozzle) + " duty (commanded)";
        signals[nozzle].unit = "%";
        signals[nozzle].held = true;
    }
    // A nozzle no command named is not a signal of this run.
    std::erase_if(signals, [](const KeySignal& signal) { return signal.points.empty(); });
    return signals;
}

class BoundaryRun final : public SystemRun {
public:
    BoundaryRun(const CaseSpec& spec, std::uint64_t seed)
        : own_(boundary_sections(spec)), wiring_(spec.wiring), clock_(spec.mode), seed_(seed), world_(own_, seed) {}

    TimeNs end_ns() const override { return world_.end_ns; }

    void add_judging_plan(nlohmann::json& plan) const override { plan["boundary"] = to_json(plan_boundary_judging(own_)); }

    void record(TraceRecorder& trace) const override {
        trace.record<msg::NmeaSentence>(topics::kGnssNmea);
        trace.record<msg::SerialLine>(topics::kLaserHeightSerial);
        trace.record<msg::NozzlePwm>(topics::kNozzlePwm);
        trace.record<msg::Vehicle2dTruth>(topics::kVehicle2dTruth);
        trace.record<msg::NozzlesTruth>(topics::kNozzlesTruth);
        if (own_.vision) {
            // The controller's reports and the crop truth per frame (not the
            // frames: megabytes each, and a pure function of case and seed).
            trace.record<msg::VisionReport>(topics::kVisionReport);
            trace.record<msg::CameraViewTruth>(topics::kCameraViewTruth);
        }
    }

    std::vector<std::string> write_controller_inputs(const std::filesystem::path& case_dir) const override {
        const std::filesystem::path file = case_dir / kJobFile;
        std::ofstream out(file);
        out << job_yaml(own_);
        if (!out.flush()) throw std::runtime_error("cannot write the controller's job " + file.string());
        return {"--job", file.string()};
    }

    void describe_attach(nlohmann::json& attach, std::uint32_t dds_domain) const override {
        attach["job"] = kJobFile;
        // A wired Pi whose PWM comes on DDS (board_io: dds), or that takes the
        // camera frames (which travel on DDS only), must know the run's domain.
        if (wiring_.board_io == BoardIoWireKind::dds || world_.vision.has_value()) attach["dds_domain"] = dds_domain;
    }

    std::unique_ptr<SystemNodes> make_nodes(BenchWires& wires) override {
        return std::make_unique<BoundaryNodes>(own_, world_, seed_, wiring_, clock_, wires);
    }

private:
    const BoundarySections& own_;
    WiringSpec wiring_;
    ClockMode clock_;
    std::uint64_t seed_;
    BoundaryWorld world_;
};

class BoundarySystem final : public System {
public:
    std::string_view name() const override { return "boundary"; }

    std::shared_ptr<const SystemSections> read_sections(const YamlSection& root) const override {
        return read_boundary_sections(root);
    }

    ReferenceController reference_controller() const override {
        return {"rig-boundary-controller", "", "seed 001's boundary controller"};
    }

    std::unique_ptr<SystemRun> plan_run(const CaseSpec& spec, std::uint64_t seed) const override {
        return std::make_unique<BoundaryRun>(spec, seed);
    }

    SystemJudgement judge(const RecordedTrace& trace, const nlohmann::json& plan) const override {
        if (!plan.is_object() || !plan.contains("boundary")) throw std::runtime_error("judging plan: no key boundary");
        return judge_boundary_trace(trace, boundary_judging_plan_from_json(plan.at("boundary")));
    }

    std::vector<KeySignal> key_signals(const RecordedTrace& trace) const override { return boundary_key_signals(trace); }
};

}  // namespace

const System& boundary_system() {
    static const BoundarySystem system;
    return system;
}

}  // namespace rig::harness
