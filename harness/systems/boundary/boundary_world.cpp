#include "harness/systems/boundary/boundary_world.h"

#include <algorithm>
#include <cmath>
#include <mutex>
#include <stdexcept>

#include "emulators/malformed_command.h"
#include "harness/trace/sha256.h"
#include "idl/topics.h"
#include "rig/camera/png_file.h"
#include "rig/host/cpu_lease.h"
#include "rig/runtime/realtime.h"

namespace rig::harness {

BoundaryWorld::BoundaryWorld(const BoundarySections& spec, std::uint64_t seed)
    : kinematics(spec.frame(), field2d::Route2d(spec.route_start, spec.route_segments), spec.mounting,
                 field2d::BoomHeightProfile(spec.boom_height), spec.guidance, seed),
      valves(spec.valves),
      ad300(spec.ad300),
      laser(spec.laser) {
    // One seed, three devices: each draws from its own named streams
    // (emulators/seeded_random.h), so they do not share a sequence.
    valves.seed = seed;
    ad300.seed = seed;
    laser.seed = seed;
    end_ns = seconds_to_ns(kinematics.route().end_time_s() + spec.end_after_route_s);
    if (spec.vision) {
        vision = spec.vision;
        crop.emplace(spec.vision->crop, seed);
    }
}

// ---------------------------------------------------------------- plant

BoundaryPlantNode::BoundaryPlantNode(const field2d::SprayerKinematics& kinematics, emulators::PwmNozzleValves valves,
                                     emulators::SprayDepositionParams spray, double idle_truth_rate_hz)
    : kinematics_(kinematics),
      valves_(std::move(valves)),
      spray_(spray),
      step_ns_(seconds_to_ns(spray.step_s)),
      idle_period_ns_(seconds_to_ns(1.0 / idle_truth_rate_hz)),
      commanded_pct_(static_cast<std::size_t>(valves_.nozzle_count()), 0.0) {}

void BoundaryPlantNode::configure(DdsContext& dds) {
    duty_reader_ = std::make_unique<Reader<msg::NozzlePwm>>(dds, topics::kNozzlePwm);
    vehicle_writer_ = std::make_unique<Writer<msg::Vehicle2dTruth>>(dds, topics::kVehicle2dTruth);
    nozzles_writer_ = std::make_unique<Writer<msg::NozzlesTruth>>(dds, topics::kNozzlesTruth);
}

bool BoundaryPlantNode::may_flow() const {
    for (int n = 0; n < valves_.nozzle_count(); ++n) {
        if (commanded_pct_[static_cast<std::size_t>(n)] > 0.0 || valves_.opening(n) > 0.0 ||
            valves_.active_duty_pct(n) > 0.0) {
            return true;
        }
    }
    return false;
}

void BoundaryPlantNode::publish_truth(TimeNs mid_ns) {
    const field2d::SprayerTruth truth = kinematics_.truth_at(ns_to_seconds(mid_ns));
    msg::Vehicle2dTruth vehicle;
    vehicle.time_ns(mid_ns);
    vehicle.east_m(truth.pose.position.east_m);
    vehicle.north_m(truth.pose.position.north_m);
    vehicle.heading_deg(truth.pose.heading_deg);
    vehicle.speed_m_s(truth.pose.speed_m_s);
    vehicle.yaw_rate_deg_s(truth.pose.yaw_rate_deg_s);
    vehicle.antenna_east_m(truth.antenna.east_m);
    vehicle.antenna_north_m(truth.antenna.north_m);
    vehicle.antenna_lat_deg(truth.antenna_geodetic.lat_deg);
    vehicle.antenna_lon_deg(truth.antenna_geodetic.lon_deg);
    vehicle.antenna_height_m(truth.antenna_geodetic.height_m);
    vehicle.antenna_velocity_east_m_s(truth.antenna_velocity_m_s.east_m);
    vehicle.antenna_velocity_north_m_s(truth.antenna_velocity_m_s.north_m);
    vehicle.boom_height_m(truth.boom_height_m);
    vehicle.boom_offset_m(truth.boom_offset_m);
    vehicle.boom_centre_east_m(truth.boom_centre.east_m);
    vehicle.boom_centre_north_m(truth.boom_centre.north_m);
    vehicle_writer_->publish(vehicle);

    msg::NozzlesTruth nozzles;
    nozzles.time_ns(mid_ns);
    for (int n = 0; n < valves_.nozzle_count(); ++n) {
        msg::NozzleTruth nozzle;
        nozzle.east_m(truth.nozzles[static_cast<std::size_t>(n)].east_m);
        nozzle.north_m(truth.nozzles[static_cast<std::size_t>(n)].north_m);
        nozzle.duty_pct(valves_.active_duty_pct(n));
        nozzle.opening(valves_.opening(n));
        nozzle.flow_l_min(valves_.flow_ml_min(n) / 1000.0);
        nozzle.delivered_l(valves_.delivered_l(n));
        nozzles.nozzles().push_back(nozzle);
    }
    nozzles_writer_->publish(nozzles);
}

TimeNs BoundaryPlantNode::step(TimeNs now_ns) {
    // Whole steps up to now first: a duty that arrives at now acts from now on.
    while (valves_.now_ns() + step_ns_ <= now_ns) {
        const TimeNs from = valves_.now_ns();
        const std::vector<double> litres = valves_.advance(from + step_ns_);
        const bool delivered = std::any_of(litres.begin(), litres.end(), [](double l) { return l > 0.0; });
        const TimeNs mid = from + step_ns_ / 2;
        if (delivered || mid >= next_idle_truth_ns_) {
            publish_truth(mid);
            next_idle_truth_ns_ = mid + idle_period_ns_;
        }
    }
    for (const msg::NozzlePwm& pwm : duty_reader_->take_all()) {
        // A duty missing or extra, NaN or outside 0-100 % is no command the
        // valves can carry out: the run ends on it, never on a clamped guess.
        if (const auto problem = emulators::nozzle_pwm_problem(pwm, valves_.nozzle_count())) {
            throw emulators::malformed_command(topics::kNozzlePwm, now_ns, *problem);
        }
        const std::vector<double>& duty = pwm.duty_pct();
        for (std::size_t n = 0; n < commanded_pct_.size(); ++n) {
            if (duty[n] != commanded_pct_[n]) {
                valves_.command(static_cast<int>(n), duty[n], now_ns);
                commanded_pct_[n] = duty[n];
            }
        }
    }
    const TimeNs next_step = valves_.now_ns() + step_ns_;
    if (may_flow()) return next_step;
    // Idle: wake at the end of the first step whose middle is due for truth.
    const TimeNs first_due_step = std::max<TimeNs>(0, (next_idle_truth_ns_ - step_ns_ / 2 + step_ns_ - 1) / step_ns_);
    return std::max(next_step, (first_due_step + 1) * step_ns_);
}

// ---------------------------------------------------------------- serial devices

Ad300Node::Ad300Node(const field2d::SprayerKinematics& kinematics, emulators::Ad300Params params)
    : receiver_(kinematics, std::move(params)) {}

void Ad300Node::configure(DdsContext& dds) { writer_ = std::make_unique<Writer<msg::NmeaSentence>>(dds, topics::kGnssNmea); }

TimeNs Ad300Node::step(TimeNs now_ns) {
    for (const emulators::TimedLine& line : receiver_.poll(now_ns)) {
        msg::NmeaSentence sample;
        sample.sentence(line.text);
        writer_->publish(sample);
    }
    return receiver_.next_due_ns();
}

L4LaserNode::L4LaserNode(const field2d::SprayerKinematics& kinematics, emulators::L4LaserParams params)
    : sensor_(kinematics, std::move(params)) {}

void L4LaserNode::configure(DdsContext& dds) {
    writer_ = std::make_unique<Writer<msg::SerialLine>>(dds, topics::kLaserHeightSerial);
}

TimeNs L4LaserNode::step(TimeNs now_ns) {
    for (const emulators::TimedLine& line : sensor_.poll(now_ns)) {
        msg::SerialLine sample;
        sample.text(line.text);
        writer_->publish(sample);
    }
    return sensor_.next_due_ns();
}

// ---------------------------------------------------------------- cameras

namespace {

std::string sha256_hex(const std::vector<std::uint8_t>& bytes) {
    Sha256 digest;
    digest.add(bytes.data(), bytes.size());
    return digest.hex();
}

}  // namespace

CameraNode::CameraNode(const field2d::SprayerKinematics& kinematics, const field2d::CropCoverMap& crop,
                       emulators::vision::CameraEmulatorParams params, std::uint64_t seed, int camera_index,
                       std::vector<int> nozzles, std::vector<double> nozzle_right_m, TimeNs calibration_until_ns,
                       ClockMode clock)
    : name_(camera_index == 0 ? "camera_left" : "camera_right"),
      kinematics_(kinematics),
      emulator_(params, seed, static_cast<std::uint64_t>(camera_index), name_),
      camera_index_(camera_index),
      nozzles_(std::move(nozzles)),
      nozzle_right_m_(std::move(nozzle_right_m)),
      frame_rate_hz_(params.frame_rate_hz),
      calibration_until_ns_(calibration_until_ns),
      render_crop_(crop.sharing_tiles()),
      clock_(clock) {
    // The operator lays the green board in front of the camera (where it was
    // designed to sit: a turned camera sees it turned) and a red board over
    // each nozzle.
    boards_.boom_board_right_m = params.camera.mounting.right_m;
    boards_.nozzle_right_m = nozzle_right_m_;
}

CameraNode::~CameraNode() { shutdown(); }

void CameraNode::configure(DdsContext& dds) {
    dds_ = &dds;
    frame_writer_ = std::make_unique<Writer<msg::CameraFrame>>(
        dds, camera_index_ == 0 ? topics::kCameraLeftFrame : topics::kCameraRightFrame);
    truth_writer_ = std::make_unique<Writer<msg::CameraViewTruth>>(dds, topics::kCameraViewTruth);
    const auto depth = static_cast<std::size_t>(std::max(2.0, std::ceil(kRenderAheadS * frame_rate_hz_)));
    ahead_ = std::make_unique<WorkAhead<Rendered>>(
        [this](std::uint64_t k) { return render(k); }, depth,
        [this] {
            // Started by the loop's thread: at the real-time loop's SCHED_FIFO
            // priority, or on a lockstep case's leased CPU (rig/host/cpu_lease.h).
            // Rendering runs beside the loop, on any CPU, below it: it must not
            // take the loop's core. In real time its frames have deadlines, so
            // it goes before the run's other time-sharing threads.
            const std::string refused =
                drop_to_time_sharing(clock_ == ClockMode::realtime ? std::optional<int>(kRealtimeRenderNice) : std::nullopt);
            leave_leased_cpu();
            const std::lock_guard lock(render_scheduling_mutex_);
            render_scheduling_ = refused.empty() ? describe_thread_placement() : refused;
        },
        [this] {
            // Real time: a frame left for later is due as soon as it is rendered.
            if (clock_ == ClockMode::realtime) dds_->notify_data_arrived();
        });
    // Frame 0 is due at t = 0, before any wake of the loop could wait for it:
    // rendered before time starts (the first frame also builds the crop
    // truth's tiles in view).
    ahead_->wait_until_next_ready();
}

TimeNs CameraNode::frame_time_ns(std::uint64_t k) const {
    // Exact on the nanosecond grid for every rate (no drift from adding a rounded period).
    return static_cast<TimeNs>(std::llround(static_cast<double>(k) * 1e9 / frame_rate_hz_));
}

CameraNode::Rendered CameraNode::render(std::uint64_t k) const {
    Rendered out;
    const TimeNs t_ns = frame_time_ns(k);
    out.truth = kinematics_.truth_at(ns_to_seconds(t_ns));
    const emulators::vision::BoomPose pose = emulators::vision::boom_pose_of(out.truth);
    out.image = t_ns < calibration_until_ns_ ? emulator_.render_calibration(render_crop_, pose, boards_, k)
                                             : emulator_.render(render_crop_, pose, k);
    if (out.image) out.sha256 = sha256_hex(out.image->bytes);
    msg::CameraViewTruth& view = out.view;
    view.time_ns(t_ns);
    view.camera(static_cast<std::uint16_t>(camera_index_));
    view.frame_number(static_cast<std::uint32_t>(k));
    view.delivered(out.image.has_value());
    view.rgb_sha256(out.sha256);
    view.speed_m_s(out.truth.pose.speed_m_s);
    view.boom_height_m(out.truth.boom_height_m);
    for (std::size_t i = 0; i < nozzles_.size(); ++i) {
        const std::array<field2d::Vec2, 4> roi =
            field2d::nozzle_roi_ground(pose.boom_centre_ground, pose.heading_deg, nozzle_right_m_[i]);
        msg::NozzleRoiTruth nozzle;
        nozzle.nozzle(static_cast<std::uint16_t>(nozzles_[i]));
        nozzle.density(render_crop_.cover_fraction(roi));
        nozzle.roi_centre_east_m((roi[0].east_m + roi[1].east_m + roi[2].east_m + roi[3].east_m) / 4.0);
        nozzle.roi_centre_north_m((roi[0].north_m + roi[1].north_m + roi[2].north_m + roi[3].north_m) / 4.0);
        view.nozzles().push_back(nozzle);
    }
    return out;
}

std::string CameraNode::render_scheduling() const {
    const std::lock_guard lock(render_scheduling_mutex_);
    return render_scheduling_;
}

bool CameraNode::has_unread_input() const { return frame_owed_ && ahead_ && ahead_->next_ready(); }

TimeNs CameraNode::step(TimeNs now_ns) {
    frame_owed_ = false;
    while (frame_time_ns(frame_count_) <= now_ns) {
        const TimeNs t_ns = frame_time_ns(frame_count_);
        if (clock_ == ClockMode::realtime && !ahead_->next_ready()) {
            // Late on its own: the rendering thread wakes the loop when the
            // frame is done (has_unread_input), and nothing else waits for it.
            frame_owed_ = true;
            return kNever;
        }
        if (ahead_->next_index() != frame_count_) throw std::logic_error(name_ + ": frames rendered out of order");
        Rendered rendered = ahead_->take();  // an exception of the rendering comes out here

        const field2d::SprayerTruth& truth = rendered.truth;
        const std::optional<rig::camera::RgbImage>& image = rendered.image;
        if (image && keep_at_ns_ && !kept_frame_ && t_ns >= *keep_at_ns_) {
            kept_frame_ = *image;
            kept_frame_number_ = frame_count_;
            kept_boom_height_m_ = truth.boom_height_m;
        }
        if (image) {
            msg::CameraFrame frame;
            frame.frame_number(static_cast<std::uint32_t>(frame_count_));
            frame.width_px(static_cast<std::uint16_t>(image->width));
            frame.height_px(static_cast<std::uint16_t>(image->height));
            frame.rgb(std::move(rendered.image->bytes));  // the frame's last use: no 2.8 MB copy
            frame_writer_->publish(frame);
        }
        truth_writer_->publish(rendered.view);
        if (reports_own_emissions()) emitted_deadlines_.push_back(t_ns);
        ++frame_count_;
    }
    return frame_time_ns(frame_count_);
}

void CameraNode::shutdown() {
    // Stops the rendering thread before anything it uses (the DDS context it
    // wakes, this node's members) goes away.
    ahead_.reset();
}

std::optional<std::uint64_t> CameraNode::write_report_frame(const std::filesystem::path& file) const {
    if (!kept_frame_) return std::nullopt;
    rig::camera::RgbImage frame = *kept_frame_;
    // Sec. 2.1's ROI of each nozzle in the boom frame (x right, y ahead, the
    // ground at z = -h), as field2d::nozzle_roi_ground lays it on the field.
    const double h = kept_boom_height_m_;
    const rig::camera::Rgb yellow{255, 230, 0};
    for (const double right_m : nozzle_right_m_) {
        std::array<Eigen::Vector2d, 4> corners;
        const double xs[4] = {right_m - 0.3, right_m + 0.3, right_m + 0.3, right_m - 0.3};
        const double ys[4] = {0.2, 0.2, 0.6, 0.6};
        bool seen = true;
        for (int i = 0; i < 4; ++i) {
            const std::optional<Eigen::Vector2d> px = emulator_.true_camera().project(Eigen::Vector3d(xs[i], ys[i], -h));
            if (!px) seen = false;
            corners[static_cast<std::size_t>(i)] = px.value_or(Eigen::Vector2d::Zero());
        }
        if (seen) rig::camera::draw_quad(frame, corners, yellow, 2);
    }
    rig::camera::write_png(file.string(), frame);
    return kept_frame_number_;
}

}  // namespace rig::harness
