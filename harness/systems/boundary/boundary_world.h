#pragma once
// Seed 001's world for one run of a boundary case (harness/systems/boundary/boundary_case.h):
// the sprayer's 2-D kinematics, and the rig's local nodes that the lockstep
// master steps each instant, in this order:
//   BoundaryPlantNode  takes the controller's PWM duties (actuator/nozzle_pwm/duty;
//                      a malformed one ends the run, emulators/malformed_command.h),
//                      runs the six valves on the deposition step grid and
//                      publishes the truth the judge rebuilds the ground from
//                      (truth/vehicle2d, truth/nozzles);
//   Ad300Node          the AD300's RMC lines on device/gnss/nmea;
//   L4LaserNode        the L4 laser's lines on device/laser_height/serial;
//   CameraNode x 2     with `vision:`, each boom camera's frames on
//                      device/camera_left|right/frame and the crop truth under
//                      its nozzles' ROIs on truth/camera_view.
// A pure function of the case and the seed: same seed, same trace.
#include <cstdint>
#include <filesystem>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "emulators/ad300_receiver.h"
#include "emulators/boundary_spray_plant.h"
#include "emulators/field2d/sprayer_kinematics.h"
#include "emulators/l4_laser_sensor.h"
#include "emulators/pwm_nozzle_valves.h"
#include "emulators/field2d/crop_cover_map.h"
#include "emulators/vision/camera_emulator.h"
#include "rig/runtime/work_ahead.h"
#include "harness/systems/boundary/boundary_case.h"
#include "rig/runtime/dds_context.h"
#include "rig/runtime/node.h"

namespace rig::harness {

struct BoundaryWorld {
    BoundaryWorld(const BoundarySections& spec, std::uint64_t seed);
    field2d::SprayerKinematics kinematics;
    emulators::PwmValveParams valves;
    emulators::Ad300Params ad300;
    emulators::L4LaserParams laser;
    // With `vision:`: the crop truth (seeded by the run's seed) and the cameras.
    std::optional<field2d::CropCoverMap> crop;
    std::optional<BoundaryVisionSpec> vision;
    TimeNs end_ns = 0;
};

// The plant's side of the nozzles. Truth, per deposition step (spray.step_s,
// on a fixed grid from t = 0, as emulators/boundary_spray_plant.h integrates):
// a NozzlesTruth and a Vehicle2dTruth stamped at the step's middle (where the
// plant lays that step's volume), with each nozzle's delivered volume at the
// step's end, for every step in which any nozzle delivered; while nothing
// flows, one pair every 1 / idle_truth_rate_hz. The judge lays each step's
// volume (the difference of delivered_l) as the fan band there, which is
// exactly what the plant does: the ground is rebuilt from the trace alone.
class BoundaryPlantNode final : public Node {
public:
    BoundaryPlantNode(const field2d::SprayerKinematics& kinematics, emulators::PwmNozzleValves valves,
                      emulators::SprayDepositionParams spray, double idle_truth_rate_hz);
    const std::string& name() const override { return name_; }
    void configure(DdsContext& dds) override;
    TimeNs step(TimeNs now_ns) override;
    bool has_unread_input() const override { return duty_reader_->has_unread(); }

private:
    void publish_truth(TimeNs mid_ns);
    bool may_flow() const;

    std::string name_ = "boundary_plant";
    const field2d::SprayerKinematics& kinematics_;
    emulators::PwmNozzleValves valves_;
    emulators::SprayDepositionParams spray_;
    TimeNs step_ns_ = 0;
    TimeNs idle_period_ns_ = 0;
    TimeNs next_idle_truth_ns_ = 0;
    std::vector<double> commanded_pct_;
    std::unique_ptr<Reader<msg::NozzlePwm>> duty_reader_;
    std::unique_ptr<Writer<msg::Vehicle2dTruth>> vehicle_writer_;
    std::unique_ptr<Writer<msg::NozzlesTruth>> nozzles_writer_;
};

// A serial device's lines as samples on its device topic, each at the instant
// its last byte is on the wire.
class Ad300Node final : public Node {
public:
    Ad300Node(const field2d::SprayerKinematics& kinematics, emulators::Ad300Params params);
    const std::string& name() const override { return name_; }
    void configure(DdsContext& dds) override;
    TimeNs step(TimeNs now_ns) override;

private:
    std::string name_ = "ad300";
    emulators::Ad300Receiver receiver_;
    std::unique_ptr<Writer<msg::NmeaSentence>> writer_;
};

class L4LaserNode final : public Node {
public:
    L4LaserNode(const field2d::SprayerKinematics& kinematics, emulators::L4LaserParams params);
    const std::string& name() const override { return name_; }
    void configure(DdsContext& dds) override;
    TimeNs step(TimeNs now_ns) override;

private:
    std::string name_ = "l4_laser";
    emulators::L4LaserSensor sensor_;
    std::unique_ptr<Writer<msg::SerialLine>> writer_;
};

// One boom camera (emulators/vision/camera_emulator.h). At each frame instant,
// k / frame_rate_hz from t = 0, it renders the ground under the plant's true
// boom pose and publishes the frame on its device topic (none when the camera
// is dead with no_frame), and on truth/camera_view the true cover D of each of
// its nozzles' Sec. 2.1 ROIs (from the plant's true nozzle points; the
// controller's ROIs are its own estimate of these) with the frame's SHA-256.
// Rendering (30-60 ms a frame, more where new crop tiles are built) runs
// ahead on one thread of its own (rig/runtime/work_ahead.h), up to
// kRenderAheadS of frames: what a frame shows depends on the plant's boom pose
// at its instant, which the route fixes in advance (the controller drives no
// part of it). The frame is the same either way (a pure function of case, seed
// and frame number). The thread reads its own copy of the crop truth (the map
// builds its raster tiles on first use and is not shared between threads), and
// also counts the true cover under the ROIs there: a step only publishes.
//
// When a frame is due and not rendered yet: in lockstep the step waits for
// it (the frame belongs to its round). In real time it does not: a camera
// that falls behind is late on its own (Node::reports_own_emissions), its
// frame leaves when rendered and its lateness counts against the camera, and
// every other device keeps its time.
class CameraNode final : public Node {
public:
    // camera_index 0 = left (device/camera_left/frame), 1 = right; `nozzles`
    // the nozzle numbers it sees; nozzle_right_m each one's place across the boom.
    // Frames exposed before calibration_until_ns show Sec. 2.2.1's boards
    // (a green board in front of the camera, a red one over each of its nozzles).
    // `clock`: the case's mode, which says whether a step may leave a frame
    // that is not rendered yet for later (real time) or waits for it (lockstep).
    CameraNode(const field2d::SprayerKinematics& kinematics, const field2d::CropCoverMap& crop,
               emulators::vision::CameraEmulatorParams params, std::uint64_t seed, int camera_index,
               std::vector<int> nozzles, std::vector<double> nozzle_right_m, TimeNs calibration_until_ns = 0,
               ClockMode clock = ClockMode::lockstep);
    ~CameraNode() override;
    const std::string& name() const override { return name_; }
    void configure(DdsContext& dds) override;
    TimeNs step(TimeNs now_ns) override;
    bool has_unread_input() const override;
    bool reports_own_emissions() const override { return clock_ == ClockMode::realtime; }
    std::vector<TimeNs> take_emitted_deadlines() override { return std::exchange(emitted_deadlines_, {}); }
    void shutdown() override;
    std::uint64_t frames_rendered() const { return frame_count_; }
    // How the rendering thread was scheduled ("CPUs 0-1 of 2, SCHED_OTHER, nice -10"),
    // or what was refused; "" before it started.
    std::string render_scheduling() const;
    // Keeps a copy of the first frame exposed at or after `at_ns`, for the
    // report: the frame with the ROIs drawn (write_report_frame).
    void keep_frame_at(TimeNs at_ns) { keep_at_ns_ = at_ns; }
    // Writes the kept frame as a PNG with each nozzle's true Sec. 2.1 ROI
    // outlined (projected through the camera as it truly is, faults included);
    // returns its frame number, or nullopt when no frame was kept (a dead
    // camera). Throws std::runtime_error naming the file when it cannot be written.
    std::optional<std::uint64_t> write_report_frame(const std::filesystem::path& file) const;

private:
    struct Rendered {
        std::optional<rig::camera::RgbImage> image;  // nullopt: a dead camera sent nothing
        std::string sha256;                          // of image->bytes
        field2d::SprayerTruth truth;                 // the plant at the exposure
        msg::CameraViewTruth view;                   // the crop truth under the ROIs, and the above
    };
    TimeNs frame_time_ns(std::uint64_t k) const;
    Rendered render(std::uint64_t k) const;

    std::string name_;
    const field2d::SprayerKinematics& kinematics_;
    emulators::vision::CameraEmulator emulator_;
    int camera_index_;
    std::vector<int> nozzles_;
    std::vector<double> nozzle_right_m_;
    double frame_rate_hz_;
    TimeNs calibration_until_ns_;
    emulators::vision::CalibrationBoards boards_;
    field2d::CropCoverMap render_crop_;  // the rendering thread's own map of the crop truth (tiles shared with the other camera)
    ClockMode clock_;
    // How far ahead frames are rendered: enough to ride out the rendering
    // thread losing its CPU for a while on a busy machine (rig/runtime/work_ahead.h);
    // at the cases' 5 fps, 10 frames (28 MB at 1280 x 720).
    static constexpr double kRenderAheadS = 2.0;
    // The rendering thread's nice value in real time. CFS shares a CPU by
    // weight: nice -10 weighs 9548 against 1024 at nice 0, so the rendering
    // goes before the run's other time-sharing threads (lockstep cases of the
    // same `rig run`, its DDS threads) when it has a frame to render, and
    // sleeps when it is ahead, so they lose nothing while it does. Against
    // other sessions' work (a build) the session's own weight counts
    // (SessionCpuWeight, harness/run/case_loop.cpp).
    static constexpr int kRealtimeRenderNice = -10;
    std::unique_ptr<WorkAhead<Rendered>> ahead_;
    mutable std::mutex render_scheduling_mutex_;
    std::string render_scheduling_;  // how the rendering thread runs, or why not as asked (a run's facts)
    // Real time: the last step left a due frame for later (not rendered yet).
    bool frame_owed_ = false;
    DdsContext* dds_ = nullptr;  // the rendering thread wakes the real-time loop through it
    std::vector<TimeNs> emitted_deadlines_;
    std::uint64_t frame_count_ = 0;
    std::optional<TimeNs> keep_at_ns_;
    std::optional<rig::camera::RgbImage> kept_frame_;
    std::uint64_t kept_frame_number_ = 0;
    double kept_boom_height_m_ = 0.0;
    std::unique_ptr<Writer<msg::CameraFrame>> frame_writer_;
    std::unique_ptr<Writer<msg::CameraViewTruth>> truth_writer_;
};

}  // namespace rig::harness
