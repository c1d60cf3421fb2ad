#include "controller/boundary/boundary_controller_node.h"

#include <iostream>

#include "idl/topics.h"

namespace rig::controller::boundary {

BoundaryControllerNode::BoundaryControllerNode(std::string node_name, BoundaryNodeConfig config)
    : name_(std::move(node_name)), sweep_(std::move(config.calibration)), logic_(std::move(config.controller)) {}

void BoundaryControllerNode::configure(DdsContext& dds) {
    nmea_reader_ = std::make_unique<Reader<msg::NmeaSentence>>(dds, topics::kGnssNmea);
    laser_reader_ = std::make_unique<Reader<msg::SerialLine>>(dds, topics::kLaserHeightSerial);
    pwm_writer_ = std::make_unique<Writer<msg::NozzlePwm>>(dds, topics::kNozzlePwm);
}

bool BoundaryControllerNode::has_unread_input() const {
    return nmea_reader_->has_unread() || laser_reader_->has_unread();
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
    for (const auto& sample : laser_reader_->take_all()) logic_.on_laser_line(sample.text().to_string(), now_ns);
    for (const auto& sample : nmea_reader_->take_all()) logic_.on_nmea_sentence(sample.sentence().to_string(), now_ns);
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
    return next_wake;
}

}  // namespace rig::controller::boundary
