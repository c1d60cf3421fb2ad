#include "controller/boundary/boundary_controller_node.h"

#include <algorithm>
#include <iostream>
#include <optional>

#include "controller/boundary/vision/nozzle_calibration.h"
#include "idl/topics.h"

namespace rig::controller::boundary {

BoundaryControllerNode::BoundaryControllerNode(std::string node_name, BoundaryNodeConfig config,
                                               BoundarySerialLines serial)
    : name_(std::move(node_name)),
      serial_(std::move(serial)),
      sweep_(std::move(config.calibration)),
      logic_(config.controller),
      commands_(seconds_to_ns(config.controller.faults.command_delay_s)),
      vision_config_(config.vision) {
    if (vision_config_.enabled) {
        std::size_t index = 0;
        for (vision::VisionCameraConfig& camera : vision::seed001_vision_cameras(config.controller)) {
            cameras_.emplace_back(std::move(camera), vision_config_.params, index++);
        }
        logic_.enable_vision(vision_config_.blind_level);
        calibrated_.assign(cameras_.size(), false);
        calibration_noticed_.assign(cameras_.size(), false);
        density_time_ns_.assign(static_cast<std::size_t>(config.controller.nozzle_count), -1);
    }
}

void BoundaryControllerNode::configure(DdsContext& dds) {
    // A wired input is a port, not a subscription: the node then never reads that topic.
    if (serial_.nmea_port.empty()) {
        nmea_reader_ = std::make_unique<Reader<msg::NmeaSentence>>(dds, topics::kGnssNmea);
    } else {
        nmea_port_ = std::make_unique<SerialPort>(serial_.nmea_port, serial_.nmea_line);
    }
    if (serial_.laser_port.empty()) {
        laser_reader_ = std::make_unique<Reader<msg::SerialLine>>(dds, topics::kLaserHeightSerial);
    } else {
        laser_port_ = std::make_unique<SerialPort>(serial_.laser_port, serial_.laser_line);
    }
    pwm_writer_ = std::make_unique<Writer<msg::NozzlePwm>>(dds, topics::kNozzlePwm);
    if (vision_config_.enabled) {
        if (cameras_.size() != 2) throw std::runtime_error("vision: expected the two cameras of Sec. 1.1");
        frame_readers_.push_back(std::make_unique<Reader<msg::CameraFrame>>(dds, topics::kCameraLeftFrame));
        frame_readers_.push_back(std::make_unique<Reader<msg::CameraFrame>>(dds, topics::kCameraRightFrame));
        vision_writer_ = std::make_unique<Writer<msg::VisionReport>>(dds, topics::kVisionReport);
    }
}

bool BoundaryControllerNode::has_unread_input() const {
    if ((nmea_reader_ && nmea_reader_->has_unread()) || (laser_reader_ && laser_reader_->has_unread())) return true;
    for (const auto& reader : frame_readers_) {
        if (reader->has_unread()) return true;
    }
    return false;
}

void BoundaryControllerNode::calibrate(std::size_t camera, const msg::CameraFrame& frame, TimeNs now_ns) {
    msg::VisionReport report;
    report.time_ns(now_ns);
    report.camera(static_cast<std::uint16_t>(camera));
    report.frame_number(frame.frame_number());
    report.threshold(-1);
    report.speed_m_s(logic_.status().speed_m_s);
    report.boom_height_m(logic_.status().boom_height_m);
    rig::camera::RgbImage image;
    image.width = frame.width_px();
    image.height = frame.height_px();
    image.bytes = frame.rgb();
    vision::VisionCameraConfig config = cameras_[camera].camera();
    if (image.bytes.size() != static_cast<std::size_t>(image.width) * static_cast<std::size_t>(image.height) * 3U) {
        report.status("calibration_bad");
        notice_calibration(camera, "a calibration frame whose pixels do not fill its size");
    } else {
        const vision::NozzleCalibration found =
            vision::find_nozzle_points(image, cameras_[camera].model(), config.nozzles.size());
        if (found.ok) {
            config.nozzle_pixels = found.nozzle_pixels;
            // The nozzle points move Eq. 5-8's ROIs; nothing else of the camera changes.
            cameras_[camera] = vision::CameraVision(config, vision_config_.params, camera);
            calibrated_[camera] = true;
            report.status("calibrated");
        } else {
            report.status("calibration_bad");
            notice_calibration(camera, found.problem);
        }
    }
    vision_writer_->publish(report);
}

void BoundaryControllerNode::notice_calibration(std::size_t camera, const std::string& problem) {
    // Once per camera: a calibration scene shows for many frames.
    if (calibration_noticed_[camera]) return;
    calibration_noticed_[camera] = true;
    std::cerr << name_ << ": " << cameras_[camera].camera().name << ": calibration frame refused (" << problem
              << "); the " << (calibrated_[camera] ? "points found before" : "design nozzle points") << " stay\n";
}

void BoundaryControllerNode::process_frame(std::size_t camera, const msg::CameraFrame* frame, TimeNs now_ns) {
    if (frame != nullptr && now_ns < seconds_to_ns(vision_config_.calibration_until_s)) {
        calibrate(camera, *frame, now_ns);
        return;
    }
    const BoundaryStatus& status = logic_.status();
    std::optional<rig::camera::RgbImage> image;
    if (frame != nullptr) {
        image.emplace();
        image->width = frame->width_px();
        image->height = frame->height_px();
        image->bytes = frame->rgb();
        // A frame whose pixels do not fill its size is a broken frame: measured as the wrong size.
        if (image->bytes.size() != static_cast<std::size_t>(image->width) * static_cast<std::size_t>(image->height) * 3U) {
            image->width = 0;
            image->height = 0;
            image->bytes.clear();
        }
    }
    const vision::FrameDensities densities =
        cameras_[camera].measure(image ? &*image : nullptr, status.boom_height_m);
    msg::VisionReport report;
    report.time_ns(now_ns);
    report.camera(static_cast<std::uint16_t>(camera));
    report.frame_number(frame != nullptr ? frame->frame_number() : 0);
    report.status(vision::frame_status_name(densities.status));
    report.threshold(static_cast<std::int16_t>(densities.status == vision::FrameStatus::ok ? densities.threshold : -1));
    report.speed_m_s(status.speed_m_s);
    report.boom_height_m(status.boom_height_m);
    const BoundaryControllerConfig& config = logic_.config();
    for (const int nozzle : cameras_[camera].camera().nozzles) {
        msg::NozzleDensityReport entry;
        entry.nozzle(static_cast<std::uint16_t>(nozzle));
        entry.measured(false);
        entry.density(0.0);
        entry.level(-1);
        for (const vision::NozzleDensity& measured : densities.nozzles) {
            if (measured.nozzle != nozzle || !measured.measured) continue;
            entry.measured(true);
            entry.density(measured.density);
            entry.level(static_cast<std::int16_t>(vision::vision_spray_level(config, measured, status.speed_m_s).value_or(-1)));
        }
        // A frame without a density for this nozzle leaves it blind now, not at its old density.
        logic_.set_vision_density(nozzle, entry.measured() ? std::optional<double>(entry.density()) : std::nullopt);
        density_time_ns_[static_cast<std::size_t>(nozzle)] = entry.measured() ? now_ns : -1;
        report.nozzles().push_back(entry);
    }
    vision_writer_->publish(report);
}

TimeNs BoundaryControllerNode::expire_densities(TimeNs now_ns) {
    const TimeNs max_age = seconds_to_ns(vision_config_.density_max_age_s);
    TimeNs next = kNever;
    bool expired = false;
    for (std::size_t n = 0; n < density_time_ns_.size(); ++n) {
        if (density_time_ns_[n] < 0) continue;
        if (now_ns >= density_time_ns_[n] + max_age) {
            logic_.set_vision_density(static_cast<int>(n), std::nullopt);
            density_time_ns_[n] = -1;
            expired = true;
        } else {
            next = std::min(next, density_time_ns_[n] + max_age);
        }
    }
    if (expired) logic_.redecide();
    return next;
}

std::vector<std::string> BoundaryControllerNode::take_lines(SerialPort& port) {
    std::vector<std::string> lines;
    // read_line keeps a partial line buffered for the next poll; a hung-up peer throws, naming the port.
    while (std::optional<std::string> line = port.read_line(std::chrono::milliseconds(0))) {
        lines.push_back(std::move(*line));
    }
    return lines;
}

double BoundaryControllerNode::sweep_duty_pct(TimeNs now_ns, TimeNs& next_change_ns) const {
    const TimeNs start = seconds_to_ns(sweep_.start_s);
    const TimeNs hold = seconds_to_ns(sweep_.hold_s);
    const auto count = static_cast<TimeNs>(sweep_.duties_pct.size());
    if (now_ns < start) {
        next_change_ns = start;
        return 0.0;
    }
    const TimeNs index = (now_ns - start) / hold;
    if (index >= count) {
        next_change_ns = kNever;
        return 0.0;
    }
    next_change_ns = start + (index + 1) * hold;
    return sweep_.duties_pct[static_cast<std::size_t>(index)];
}

TimeNs BoundaryControllerNode::step(TimeNs now_ns) {
    // Fixed order (laser, then GNSS) keeps runs identical whatever the arrival
    // order across the two topics: the height is known before the fix uses it.
    if (laser_reader_) {
        for (const auto& sample : laser_reader_->take_all()) logic_.on_laser_line(sample.text().to_string(), now_ns);
    } else {
        for (const std::string& line : take_lines(*laser_port_)) logic_.on_laser_line(line, now_ns);
    }
    if (nmea_reader_) {
        for (const auto& sample : nmea_reader_->take_all()) logic_.on_nmea_sentence(sample.sentence().to_string(), now_ns);
    } else {
        for (const std::string& line : take_lines(*nmea_port_)) logic_.on_nmea_sentence(line, now_ns);
    }
    // Frames after the fix and the height they are measured at: left, then right.
    bool frames = false;
    for (std::size_t camera = 0; camera < frame_readers_.size(); ++camera) {
        for (const msg::CameraFrame& frame : frame_readers_[camera]->take_all()) {
            process_frame(camera, &frame, now_ns);
            frames = true;
        }
    }
    if (frames) logic_.redecide();
    TimeNs next_wake = logic_.update(now_ns);
    if (vision_config_.enabled) next_wake = std::min(next_wake, expire_densities(now_ns));
    std::vector<double> duty = logic_.duty_pct();
    if (!sweep_.duties_pct.empty()) {
        TimeNs next_change = kNever;
        duty.assign(duty.size(), sweep_duty_pct(now_ns, next_change));
        next_wake = next_change;
    }
    for (const std::string& notice : logic_.take_notices()) std::cerr << name_ << ": " << notice << "\n";
    commands_.decide(duty, now_ns);
    for (std::vector<double>& due : commands_.take_due(now_ns)) {
        msg::NozzlePwm pwm;
        pwm.frequency_hz(logic_.pwm_frequency_hz());
        // TEST-ONLY fault: a message that sprays has a duty for a nozzle the boom does not have.
        const bool spraying = std::any_of(due.begin(), due.end(), [](double pct) { return pct > 0.0; });
        if (logic_.config().faults.extra_duty_entry && spraying) due.push_back(due.back());
        pwm.duty_pct(std::move(due));
        pwm_writer_->publish(pwm);
    }
    next_wake = std::min(next_wake, commands_.next_due_ns());
    // A port does not wake the node when a line arrives: it is polled.
    if (nmea_port_ || laser_port_) next_wake = std::min(next_wake, now_ns + serial_.poll_period_ns);
    return next_wake;
}

}  // namespace rig::controller::boundary
