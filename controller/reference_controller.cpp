#include "controller/reference_controller.h"

#include <cmath>
#include <iostream>
#include <limits>

#include "controller/breakpoint_equations.h"
#include "idl/topics.h"

namespace rig::controller {

ReferenceController::ReferenceController(std::string node_name, ControllerConfig config,
                                         const std::filesystem::path& state_dir)
    : name_(std::move(node_name)),
      config_(std::move(config)),
      store_(state_dir / config_.breakpoint_store_file),
      locator_(config_),
      status_period_ns_(seconds_to_ns(1.0 / config_.status_rate_hz)) {}

void ReferenceController::configure(DdsContext& dds) {
    nmea_reader_ = std::make_unique<Reader<msg::NmeaSentence>>(dds, topics::kGnssNmea);
    encoder_reader_ = std::make_unique<Reader<msg::EncoderCount>>(dds, topics::kWheelEncoder);
    button_reader_ = std::make_unique<Reader<msg::ButtonLevel>>(dds, topics::kBreakpointButton);
    status_writer_ = std::make_unique<Writer<msg::ControllerStatus>>(dds, topics::kControllerStatus);
    event_writer_ = std::make_unique<Writer<msg::BreakpointEvent>>(dds, topics::kBreakpointEvent);
    store_.load();  // a corrupt store is an error here, before time starts
}

void ReferenceController::activate(TimeNs now_ns) {
    select_target();
    next_status_ns_ = now_ns;
}

bool ReferenceController::has_unread_input() const {
    return nmea_reader_->has_unread() || encoder_reader_->has_unread() || button_reader_->has_unread();
}

TimeNs ReferenceController::step(TimeNs now_ns) {
    // Fixed order (encoder, GNSS, button) keeps runs identical whatever the arrival order.
    for (const auto& sample : encoder_reader_->take_all()) handle_encoder(sample.count_pulses(), now_ns);
    for (const auto& sample : nmea_reader_->take_all()) handle_sentence(sample.sentence().to_string(), now_ns);
    for (const auto& sample : button_reader_->take_all()) handle_button(sample.pressed(), now_ns);
    if (now_ns >= next_status_ns_) {
        publish_status(now_ns);
        next_status_ns_ = (now_ns / status_period_ns_ + 1) * status_period_ns_;
    }
    return next_status_ns_;
}

void ReferenceController::handle_sentence(const std::string& line, TimeNs now_ns) {
    const nmea::ParseResult result = nmea::parse_sentence(line);
    if (!result.ok()) {
        ++rejected_sentences_;
        return;
    }
    const nmea::Sentence& sentence = *result.sentence;
    if (const auto* gga = std::get_if<nmea::GgaData>(&sentence.data)) {
        last_quality_ = gga->fix_quality.value_or(0);
        if (last_quality_ > 0 && gga->position) {
            last_fix_ = FixInput{gga->position->lat_deg, gga->position->lon_deg, last_course_deg_, last_quality_};
        } else {
            last_fix_.reset();
        }
        return;
    }
    if (const auto* rmc = std::get_if<nmea::RmcData>(&sentence.data)) {
        if (rmc->course_true_deg) last_course_deg_ = *rmc->course_true_deg;
        // The G970II sends GGA then RMC for one epoch: the epoch is complete here.
        if (last_fix_ && rmc->status == nmea::DataStatus::valid) {
            last_fix_->course_deg = last_course_deg_;
            if (locator_.on_fix(*last_fix_, latest_count_, speed_m_s()) == LocatorEvent::reached) {
                on_breakpoint_reached(now_ns);
            }
        }
    }
}

void ReferenceController::handle_encoder(std::uint32_t count, TimeNs now_ns) {
    latest_count_ = count;
    encoder_window_.emplace_back(now_ns, count);
    const TimeNs window_ns = seconds_to_ns(config_.speed_window_s);
    while (encoder_window_.size() > 2 && encoder_window_.front().first < now_ns - window_ns) {
        encoder_window_.pop_front();
    }
    if (locator_.on_encoder(count) == LocatorEvent::reached) on_breakpoint_reached(now_ns);
}

void ReferenceController::on_breakpoint_reached(TimeNs now_ns) {
    const StoredBreakpoint reached = *locator_.target();
    publish_event(msg::BREAKPOINT_REACHED, reached, now_ns);
    // Identification only in this slice: the breakpoint is done with once reached.
    store_.remove(reached.id);
    store_.save();
    publish_event(msg::BREAKPOINT_CLEARED, reached, now_ns);
    select_target();
}

void ReferenceController::handle_button(bool pressed, TimeNs now_ns) {
    if (pressed && !button_pressed_) store_breakpoint_here(now_ns);
    button_pressed_ = pressed;
}

void ReferenceController::store_breakpoint_here(TimeNs now_ns) {
    if (!last_fix_ || !last_course_deg_) {
        std::cerr << name_ << ": breakpoint button pressed without a GNSS fix and course; ignored\n";
        return;
    }
    // The breakpoint is where the spray stopped on the ground: the nozzle line,
    // L4 (Eq. 6) behind the antenna along the course.
    const auto [lat_deg, lon_deg] =
        offset_position_deg(last_fix_->lat_deg, last_fix_->lon_deg, *last_course_deg_ + 180.0, locator_.l4_m());
    const StoredBreakpoint stored = store_.add(lat_deg, lon_deg, *last_course_deg_);
    store_.save();
    publish_event(msg::BREAKPOINT_STORED, stored, now_ns);
    select_target();
}

void ReferenceController::select_target() {
    // One breakpoint per row in this slice: the oldest stored one.
    const auto& all = store_.list();
    if (all.empty()) {
        if (locator_.target()) locator_.set_target(std::nullopt);
        return;
    }
    if (!locator_.target() || locator_.target()->id != all.front().id) locator_.set_target(all.front());
}

void ReferenceController::publish_event(msg::BreakpointEventKind kind, const StoredBreakpoint& breakpoint,
                                        TimeNs now_ns) {
    msg::BreakpointEvent event;
    event.time_ns(now_ns);
    event.breakpoint_id(breakpoint.id);
    event.kind(kind);
    event.lat_deg(breakpoint.lat_deg);
    event.lon_deg(breakpoint.lon_deg);
    event_writer_->publish(event);
}

double ReferenceController::speed_m_s() const {
    if (encoder_window_.size() < 2) return 0.0;
    const auto& [t0, c0] = encoder_window_.front();
    const auto& [t1, c1] = encoder_window_.back();
    if (t1 <= t0) return 0.0;
    // Eq. 5 gives km/h; the controller works in m/s internally.
    return speed_km_h_from_pulses(config_.wheel_diameter_m, c1 - c0, config_.pulses_per_rev, ns_to_seconds(t1 - t0)) /
           3.6;
}

void ReferenceController::publish_status(TimeNs now_ns) {
    msg::ControllerStatus status;
    status.time_ns(now_ns);
    status.positioning_mode(config_.positioning == Positioning::fusion ? msg::RTK_ODOMETER_FUSION : msg::RTK_ONLY);
    status.breakpoint_pending(locator_.target().has_value());
    status.odometer_active(locator_.odometer_active());
    status.nozzle_to_breakpoint_m(locator_.nozzle_to_breakpoint_m().value_or(std::numeric_limits<double>::quiet_NaN()));
    status.speed_km_h(speed_m_s() * 3.6);
    status.l4_m(locator_.l4_m());
    status.gnss_fix_quality(static_cast<std::uint16_t>(last_quality_));
    status.nmea_rejected_count(rejected_sentences_);
    status_writer_->publish(status);
}

}  // namespace rig::controller
