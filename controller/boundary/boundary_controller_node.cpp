#include "controller/boundary/boundary_controller_node.h"

#include <algorithm>
#include <iostream>

#include "idl/topics.h"

namespace rig::controller::boundary {

BoundaryControllerNode::BoundaryControllerNode(std::string node_name, BoundaryNodeConfig config,
                                               BoundarySerialLines serial)
    : name_(std::move(node_name)),
      serial_(std::move(serial)),
      sweep_(std::move(config.calibration)),
      logic_(std::move(config.controller)) {}

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
}

bool BoundaryControllerNode::has_unread_input() const {
    return (nmea_reader_ && nmea_reader_->has_unread()) || (laser_reader_ && laser_reader_->has_unread());
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
    TimeNs next_wake = logic_.update(now_ns);
    std::vector<double> duty = logic_.duty_pct();
    if (!sweep_.duties_pct.empty()) {
        TimeNs next_change = kNever;
        duty.assign(duty.size(), sweep_duty_pct(now_ns, next_change));
        next_wake = next_change;
    }
    for (const std::string& notice : logic_.take_notices()) std::cerr << name_ << ": " << notice << "\n";
    if (!published_once_ || duty != published_duty_pct_) {
        msg::NozzlePwm pwm;
        pwm.frequency_hz(logic_.pwm_frequency_hz());
        pwm.duty_pct(duty);
        pwm_writer_->publish(pwm);
        published_duty_pct_ = duty;
        published_once_ = true;
    }
    // A port does not wake the node when a line arrives: it is polled.
    if (nmea_port_ || laser_port_) next_wake = std::min(next_wake, now_ns + serial_.poll_period_ns);
    return next_wake;
}

}  // namespace rig::controller::boundary
