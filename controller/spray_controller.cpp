#include "controller/spray_controller.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>

#include "controller/breakpoint_equations.h"
#include "controller/flow_equations.h"
#include "rig/nmea/nmea_parser.h"

namespace rig::controller {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

}  // namespace

SprayController::SprayController(ControllerConfig config, const std::filesystem::path& state_dir)
    : config_(std::move(config)),
      state_dir_(state_dir),
      store_(state_dir / config_.breakpoint_store_file),
      locator_(config_),
      calibration_(config_.calibration),
      valve_(config_.valve),
      pid_(config_.pid, config_.pid_integral_limit_l_min),
      flow_meter_(config_.flow_meter_pulses_per_l, config_.flow_window_s),
      linkage_rise_m_(config_.linkage_rise_m) {
    store_.load();  // a corrupt store is an error here, before time starts
    if (config_.calibration_run.enabled) calibration_run_.emplace(config_.calibration_run);
}

void SprayController::start(TimeNs now_ns) {
    started_ = true;
    select_target();
    // A breakpoint left in the store by an earlier run still waits for its continuation.
    halted_ = !store_.list().empty();
    actuators_.unloading_valve_open = true;
    actuators_.section_valves_open = 0;
    valve_.start_reset(now_ns);
    actuators_.ball_valve_forward = valve_.drive() == RelayDrive::forward;
    actuators_.ball_valve_reverse = valve_.drive() == RelayDrive::reverse;
    enter(msg::SPRAY_VALVE_RESET, now_ns);
    next_pid_ns_ = now_ns;
}

// ------------------------------------------------------------------ inputs

void SprayController::on_nmea_sentence(const std::string& line, TimeNs now_ns) {
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
        last_fix_utc_ = gga->utc_time;
        return;
    }
    if (const auto* rmc = std::get_if<nmea::RmcData>(&sentence.data)) {
        if (rmc->course_true_deg) last_course_deg_ = *rmc->course_true_deg;
        // The G970II sends GGA then RMC for one epoch: the epoch is complete
        // here, if this RMC is the GGA's own. When the epoch's GGA was lost on
        // the wire (rejected), the GGA before it is an epoch old: acting on it
        // now would take an old position for a new one, so the epoch is skipped.
        if (last_fix_ && rmc->status == nmea::DataStatus::valid && rmc->utc_time == last_fix_utc_) {
            handle_fix_complete(now_ns);
        }
    }
}

void SprayController::handle_fix_complete(TimeNs now_ns) {
    last_fix_->course_deg = last_course_deg_;
    last_fix_complete_ns_ = now_ns;
    // TEST-ONLY fault: every fix re-anchors the odometer, stale or not.
    if (config_.faults.stale_fix_reanchor) locator_.release_odometer();
    on_locator_event(locator_.on_fix(*last_fix_, latest_encoder_, speed_m_s(), now_ns), now_ns);
}

TimeNs SprayController::refeed_stale_fix(TimeNs now_ns) {
    // TEST-ONLY fault: the last fix is used again as if new while sentences are
    // missing (a parser whose "valid" flag is never cleared). 0.3 s of silence at
    // 5 Hz is one missed epoch and a half.
    constexpr TimeNs kEpochNs = 200'000'000;
    if (!config_.faults.stale_fix_reanchor || !last_fix_) return kNever;
    if (now_ns - last_fix_complete_ns_ < kEpochNs + kEpochNs / 2) return last_fix_complete_ns_ + kEpochNs + kEpochNs / 2;
    if (now_ns >= next_stale_fix_ns_) {
        const TimeNs real_fix_ns = last_fix_complete_ns_;
        handle_fix_complete(now_ns);
        last_fix_complete_ns_ = real_fix_ns;  // still stale: keep counting from the real one
        next_stale_fix_ns_ = now_ns + kEpochNs;
    }
    return next_stale_fix_ns_;
}

void SprayController::on_encoder_count(std::uint32_t count_pulses, std::optional<std::uint32_t> last_edge_capture_us,
                                       TimeNs now_ns) {
    EncoderReading reading{count_pulses, std::nullopt};
    if (last_edge_capture_us) {
        // The capture timer runs on the board's clock, whose microseconds now_ns
        // counts: the edge's age is an unsigned difference, right across the
        // timer's 32-bit wrap. An edge "after" the read (the top half of the wrap)
        // is a wire out of step with this clock: taken as read now.
        const TimeNs now_us = now_ns / 1000;
        const std::uint32_t age_us = static_cast<std::uint32_t>(static_cast<std::uint32_t>(now_us) - *last_edge_capture_us);
        reading.last_edge_ns = (age_us < 0x80000000u ? now_us - static_cast<TimeNs>(age_us) : now_us) * 1000;
    }
    // Read times and capture times are two time lines: a wire that switches
    // between them starts the speed window over rather than mixing them.
    if (latest_encoder_ && latest_encoder_->last_edge_ns.has_value() != reading.last_edge_ns.has_value()) {
        encoder_window_.clear();
    }
    latest_encoder_ = reading;
    encoder_window_.push_back(EncoderRead{now_ns, reading.last_edge_ns.value_or(now_ns), count_pulses});
    const TimeNs window_ns = seconds_to_ns(config_.speed_window_s);
    while (encoder_window_.size() > 2 && encoder_window_.front().read_ns < now_ns - window_ns) {
        encoder_window_.pop_front();
    }
    on_locator_event(locator_.on_encoder(reading, speed_m_s(), now_ns), now_ns);
}

void SprayController::on_flow_meter_count(std::uint32_t count_pulses,
                                          std::optional<std::uint32_t> last_edge_capture_us, TimeNs now_ns) {
    flow_meter_.add_count(count_pulses, last_edge_capture_us, now_ns);
}

void SprayController::on_pump_sensor_voltage(double voltage_v, TimeNs now_ns) {
    const double sample_l_min =
        pump_flow_l_min_from_voltage(voltage_v, config_.pump_sensor_span_v, config_.pump_sensor_full_scale_m3_h);
    if (!std::isfinite(sample_l_min)) return;
    if (!pump_flow_l_min_ || config_.pump_flow_smoothing_s <= 0.0) {
        pump_flow_l_min_ = sample_l_min;
    } else {
        // First-order smoothing: the plunger pump pulsates, the pre-adjustment wants the mean.
        const double dt_s = ns_to_seconds(now_ns - last_pump_sample_ns_);
        const double weight = 1.0 - std::exp(-std::max(dt_s, 0.0) / config_.pump_flow_smoothing_s);
        *pump_flow_l_min_ += weight * (sample_l_min - *pump_flow_l_min_);
    }
    last_pump_sample_ns_ = now_ns;
}

void SprayController::on_boom_height_voltage(double voltage_v, TimeNs /*now_ns*/) {
    const double rise_m = linkage_rise_m_from_voltage(voltage_v, config_.boom_height_span_v, config_.boom_height_range_m);
    if (!std::isfinite(rise_m)) return;
    if (config_.faults.boom_height_read_once && boom_height_read_) return;
    boom_height_read_ = true;
    if (rise_m == linkage_rise_m_) return;
    linkage_rise_m_ = rise_m;
    locator_.set_linkage_rise_m(rise_m);
}

void SprayController::on_breakpoint_button(bool closed, TimeNs now_ns) {
    if (closed && !button_closed_) store_breakpoint_here(now_ns);
    button_closed_ = closed;
}

void SprayController::on_spray_switch(bool closed, TimeNs /*now_ns*/) { spray_switch_on_ = closed; }

// ------------------------------------------------------------------ breakpoints

void SprayController::on_locator_event(LocatorEvent event, TimeNs now_ns) {
    // The locator keeps saying "reached" while the nozzle line is past the target;
    // it is one event per breakpoint.
    if (event != LocatorEvent::reached || !locator_.target() || reached_) return;
    reached_ = true;
    ++reached_count_;
    publish_event(msg::BREAKPOINT_REACHED, *locator_.target(), now_ns);
    // Identification only (not spraying its continuation): done with it. A
    // continuation clears it once the flow is on target (update()).
    if (!continuing_ || continuation_on_target_) clear_breakpoint(now_ns);
}

void SprayController::store_breakpoint_here(TimeNs now_ns) {
    if (!last_fix_ || !last_course_deg_) {
        notices_.push_back("breakpoint button pressed without a GNSS fix and course; ignored");
        return;
    }
    // The breakpoint is where the spray stopped on the ground: the nozzle line,
    // L4 (Eq. 6) behind the antenna along the course.
    const auto [lat_deg, lon_deg] =
        offset_position_deg(last_fix_->lat_deg, last_fix_->lon_deg, *last_course_deg_ + 180.0, locator_.l4_m());
    const StoredBreakpoint stored = store_.add(lat_deg, lon_deg, *last_course_deg_);
    store_.save();
    ++stored_count_;
    publish_event(msg::BREAKPOINT_STORED, stored, now_ns);
    select_target();
    halted_ = true;
    if (started_) {
        close_sections(now_ns);
        if (phase_ != msg::SPRAY_VALVE_RESET) enter(msg::SPRAY_HALTED, now_ns);
    }
}

void SprayController::clear_breakpoint(TimeNs now_ns) {
    if (!locator_.target()) return;
    const StoredBreakpoint done = *locator_.target();
    store_.remove(done.id);
    store_.save();
    publish_event(msg::BREAKPOINT_CLEARED, done, now_ns);
    reached_ = false;
    continuing_ = false;
    continuation_on_target_ = false;
    halted_ = !store_.list().empty();
    select_target();
    if (phase_ == msg::SPRAY_HALTED || phase_ == msg::SPRAY_APPROACH) {
        enter(halted_ ? msg::SPRAY_HALTED : msg::SPRAY_IDLE, now_ns);
    }
}

void SprayController::select_target() {
    // One breakpoint per row: the oldest stored one.
    const auto& all = store_.list();
    if (all.empty()) {
        if (locator_.target()) locator_.set_target(std::nullopt);
        return;
    }
    if (!locator_.target() || locator_.target()->id != all.front().id) {
        locator_.set_target(all.front());
        reached_ = false;
    }
}

void SprayController::publish_event(msg::BreakpointEventKind kind, const StoredBreakpoint& breakpoint,
                                    TimeNs now_ns) {
    msg::BreakpointEvent event;
    event.time_ns(now_ns);
    event.breakpoint_id(breakpoint.id);
    event.kind(kind);
    event.lat_deg(breakpoint.lat_deg);
    event.lon_deg(breakpoint.lon_deg);
    events_.push_back(event);
}

// ------------------------------------------------------------------ spray sequence

double SprayController::speed_m_s() const {
    if (encoder_window_.size() < 2) return 0.0;
    const EncoderRead& first = encoder_window_.front();
    const EncoderRead& last = encoder_window_.back();
    // Standing (no edge within the window, so both reads hold the same edge): 0.
    if (last.timed_ns <= first.timed_ns) return 0.0;
    // Eq. 5 gives km/h; the controller works in m/s internally.
    return speed_km_h_from_pulses(config_.wheel_diameter_m, last.count - first.count, config_.pulses_per_rev,
                                  ns_to_seconds(last.timed_ns - first.timed_ns)) /
           3.6;
}

bool SprayController::moving_fast_enough(bool spraying) const {
    if (config_.min_spray_speed_km_h <= 0.0) return true;
    // Hysteresis: Eq. 5 over 0.2 s is noisy at walking pace, and a shutoff that
    // chatters would click the section valves open and shut. Sections open at the
    // minimum speed and close below 80 % of it.
    const double threshold_km_h = config_.min_spray_speed_km_h * (spraying ? 0.8 : 1.0);
    return speed_m_s() * 3.6 >= threshold_km_h;
}

std::uint16_t SprayController::all_sections_mask() const {
    return static_cast<std::uint16_t>((1u << config_.section_count) - 1u);
}

void SprayController::enter(msg::SprayPhase phase, TimeNs /*now_ns*/) { phase_ = phase; }

void SprayController::open_sections(TimeNs now_ns) {
    actuators_.unloading_valve_open = false;
    // TEST-ONLY fault: the section outputs are never switched on.
    if (!config_.faults.never_spray) actuators_.section_valves_open = static_cast<std::uint8_t>(all_sections_mask());
    sections_opened_ns_ = now_ns;
    flow_meter_.reset();
    flow_established_ = false;
    previous_measurement_l_min_.reset();
    earlier_measurement_l_min_.reset();
    on_target_since_ns_.reset();
}

void SprayController::close_sections(TimeNs /*now_ns*/) {
    actuators_.section_valves_open = 0;
    actuators_.unloading_valve_open = true;
    flow_established_ = false;
}

void SprayController::start_pre_adjust(TimeNs now_ns) {
    if (!pump_flow_l_min_) return;  // no pump flow reading yet: wait
    valve_command_pct_ = calibration_.opening_for(config_.target_flow_l_min, *pump_flow_l_min_);
    pre_adjusted_pct_ = valve_command_pct_;
    command_valve(valve_command_pct_, now_ns);
    pid_.reset();
    enter(msg::SPRAY_PRE_ADJUST, now_ns);
}

void SprayController::command_valve(double opening_pct, TimeNs now_ns) {
    if (!config_.faults.valve_held) valve_.move_to(opening_pct, now_ns);
}

void SprayController::reset_valve(TimeNs now_ns) {
    if (!config_.faults.valve_held) valve_.start_reset(now_ns);
}

TimeNs SprayController::apply_section_chatter(TimeNs now_ns) {
    // TEST-ONLY fault: while the sections should be open, the output drops them
    // for closed_s at the start of every period after the first.
    const ControllerFaults& faults = config_.faults;
    if (faults.section_chatter_period_s <= 0.0 || phase_ != msg::SPRAY_REGULATING || config_.faults.never_spray) {
        return kNever;
    }
    const TimeNs period_ns = seconds_to_ns(faults.section_chatter_period_s);
    const TimeNs closed_ns = seconds_to_ns(faults.section_chatter_closed_s);
    const TimeNs since_ns = now_ns - sections_opened_ns_;
    const TimeNs into_ns = since_ns % period_ns;
    const bool dropped = since_ns >= period_ns && into_ns < closed_ns;
    actuators_.section_valves_open = dropped ? 0 : static_cast<std::uint8_t>(all_sections_mask());
    return now_ns - into_ns + (dropped ? closed_ns : period_ns);  // the next edge of the chatter
}

double SprayController::continuation_lead_m() const {
    // Eq. 7: s = s_b + L4 - v (t2 + t3); with the odometer's s, the nozzle line's
    // distance still to go (s_b + L4 - s) must have come down to v (t2 + t3).
    const double lead_m = config_.hysteresis_compensation
                              ? speed_m_s() * (config_.assumed_flow_adjust_s + config_.assumed_spray_delay_s)
                              : 0.0;
    // TEST-ONLY faults: a wrong lead, and a lead table's bad entry (a bump in speed).
    const ControllerFaults& faults = config_.faults;
    const double off_bump_km_h = std::fabs(speed_m_s() * 3.6 - faults.lead_bump_at_km_h);
    const double bump_s =
        faults.lead_bump_s * std::max(0.0, 1.0 - off_bump_km_h / faults.lead_bump_half_width_km_h);
    return lead_m * faults.lead_scale + speed_m_s() * bump_s;
}

bool SprayController::continuation_open_point_reached(TimeNs now_ns) const {
    // TEST-ONLY fault: no continuation at all.
    if (config_.faults.never_resume) return false;
    const std::optional<double> to_go_m = locator_.nozzle_to_breakpoint_m_at(now_ns);
    if (!to_go_m) return false;
    const double lead_m = continuation_lead_m();
    // Or the instant predicted from the last edge has come (update() woke for it).
    const std::optional<TimeNs> open_ns = locator_.instant_nozzle_to_go_m(lead_m);
    return *to_go_m <= lead_m || (open_ns && *open_ns <= now_ns);
}

void SprayController::regulate(TimeNs now_ns) {
    const std::optional<double> measured = flow_meter_.flow_l_min();
    // The flow counts as established once a whole measurement window lies after the
    // first pulse and three successive measurements (two PID periods) agree: until
    // then the pipeline is still filling, and a PID acting on the rising reading
    // would wind up. Two were not enough over a wire whose reads can stall: one
    // stalled read repeats the last value and "agrees" with it (seen as the wired
    // case overshooting the band on a loaded machine).
    const double agree_l_min = config_.flow_established_change_pct / 100.0 * config_.target_flow_l_min;
    if (!flow_established_ && measured && flow_meter_.first_pulse_ns() &&
        now_ns - *flow_meter_.first_pulse_ns() >= seconds_to_ns(config_.flow_window_s) && previous_measurement_l_min_ &&
        earlier_measurement_l_min_ && std::abs(*measured - *previous_measurement_l_min_) <= agree_l_min &&
        std::abs(*previous_measurement_l_min_ - *earlier_measurement_l_min_) <= agree_l_min) {
        flow_established_ = true;
    }
    earlier_measurement_l_min_ = previous_measurement_l_min_;
    previous_measurement_l_min_ = measured;
    if (!flow_established_ || !measured || !pump_flow_l_min_) return;

    const double error_l_min = config_.target_flow_l_min - *measured;
    const double correction_l_min = pid_.update(error_l_min);
    if (config_.pid_output == PidOutput::opening_pct) {
        valve_command_pct_ = std::clamp(pre_adjusted_pct_ + correction_l_min, 0.0, 100.0);
    } else if (config_.pid_output == PidOutput::opening_step_pct) {
        valve_command_pct_ = std::clamp(valve_command_pct_ + correction_l_min, 0.0, 100.0);
    } else {
        valve_command_pct_ = calibration_.opening_for(config_.target_flow_l_min + correction_l_min, *pump_flow_l_min_);
    }
    command_valve(valve_command_pct_, now_ns);

    if (std::abs(error_l_min) <= config_.on_target_band_pct / 100.0 * config_.target_flow_l_min) {
        if (!on_target_since_ns_) on_target_since_ns_ = now_ns;
    } else {
        on_target_since_ns_.reset();
    }
    if (continuing_ && !continuation_on_target_ && on_target_since_ns_ &&
        now_ns - *on_target_since_ns_ >= seconds_to_ns(config_.on_target_hold_s)) {
        continuation_on_target_ = true;
        // "Once the target flow rate is reached, normal operation resumes, and the
        // current breakpoint information is cleared" (sec. 2.2.1) - once reached, too.
        if (reached_) clear_breakpoint(now_ns);
    }
}

void SprayController::calibrate(TimeNs now_ns) {
    const double opening = calibration_run_->update(now_ns, valve_.idle(), pump_flow_l_min_, flow_meter_.flow_l_min());
    valve_command_pct_ = opening;
    command_valve(opening, now_ns);
}

void SprayController::write_calibration_file() {
    // Written whole to a temporary name, then renamed: a run stopped mid-write
    // leaves the last complete calibration, never half of one.
    const std::filesystem::path file = state_dir_ / config_.calibration_run.output_file;
    const std::filesystem::path partial = state_dir_ / (config_.calibration_run.output_file + ".partial");
    {
        std::ofstream out(partial, std::ios::trunc);
        out << calibration_run_->yaml();
        if (!out.flush()) {
            notices_.push_back("valve calibration: cannot write " + partial.string());
            return;
        }
    }
    std::error_code error;
    std::filesystem::rename(partial, file, error);
    if (error) {
        notices_.push_back("valve calibration: cannot rename " + partial.string() + ": " + error.message());
        return;
    }
    notices_.push_back("valve calibration: " + std::to_string(calibration_run_->fit().size()) + " line(s) from " +
                       std::to_string(calibration_run_->points().size()) + " point(s) written to " + file.string());
}

TimeNs SprayController::update(TimeNs now_ns) {
    // The odometer's predicted instant at the breakpoint (a timer compare).
    on_locator_event(locator_.on_time(now_ns), now_ns);
    valve_.update(now_ns);
    const bool pid_due = now_ns >= next_pid_ns_;
    if (pid_due) next_pid_ns_ = next_period_boundary(now_ns, seconds_to_ns(config_.pid_period_s));

    switch (phase_) {
        case msg::SPRAY_VALVE_RESET:
            if (!valve_.resetting()) enter(halted_ ? msg::SPRAY_HALTED : msg::SPRAY_IDLE, now_ns);
            break;
        case msg::SPRAY_IDLE:
            if (calibration_run_) {
                // Calibrating: the sections open and the procedure, not the PID, drives the valve.
                if (spray_switch_on_) {
                    open_sections(now_ns);
                    enter(msg::SPRAY_REGULATING, now_ns);
                }
                break;
            }
            // TEST-ONLY fault never_resume: once a breakpoint was stored, it never sprays again.
            if (spray_switch_on_ && !halted_ && !(config_.faults.never_resume && stored_count_ > 0)) {
                start_pre_adjust(now_ns);
            }
            break;
        case msg::SPRAY_PRE_ADJUST:
            if (!spray_switch_on_) {
                enter(msg::SPRAY_IDLE, now_ns);
            } else if (valve_.idle() && moving_fast_enough(false)) {
                open_sections(now_ns);
                enter(msg::SPRAY_REGULATING, now_ns);
            }
            break;
        case msg::SPRAY_REGULATING:
            if (calibration_run_) {
                if (!spray_switch_on_) {
                    close_sections(now_ns);
                    calibration_run_->pause();
                    write_calibration_file();
                    enter(msg::SPRAY_IDLE, now_ns);
                } else if (pid_due) {
                    calibrate(now_ns);
                }
                break;
            }
            if (!spray_switch_on_ || !moving_fast_enough(true)) {
                // Zero-speed shutoff (or switch off): the valve stays where the PID left it.
                close_sections(now_ns);
                enter(spray_switch_on_ ? msg::SPRAY_PRE_ADJUST : msg::SPRAY_IDLE, now_ns);
            } else if (pid_due) {
                regulate(now_ns);
            }
            break;
        case msg::SPRAY_HALTED:
            if (spray_switch_on_ && locator_.target() && locator_.armed()) {
                // "When the nearest breakpoint is detected, the proportional control
                // valve is automatically adjusted to the initial position" (sec. 2.2.1).
                reset_valve(now_ns);
                enter(msg::SPRAY_APPROACH, now_ns);
            }
            break;
        case msg::SPRAY_APPROACH:
            if (!valve_.resetting() && !valve_.target_pct() && pump_flow_l_min_) {
                valve_command_pct_ = calibration_.opening_for(config_.target_flow_l_min, *pump_flow_l_min_);
                pre_adjusted_pct_ = valve_command_pct_;
                command_valve(valve_command_pct_, now_ns);
                pid_.reset();
            }
            if (continuation_open_point_reached(now_ns)) {
                // Open even if the valve is not there yet: late is better than never.
                continuing_ = true;
                continuation_on_target_ = false;
                if (locator_.target()) publish_event(msg::SPRAY_RESUMED, *locator_.target(), now_ns);
                open_sections(now_ns);
                enter(msg::SPRAY_REGULATING, now_ns);
            }
            break;
    }
    valve_.update(now_ns);
    actuators_.ball_valve_forward = valve_.drive() == RelayDrive::forward;
    actuators_.ball_valve_reverse = valve_.drive() == RelayDrive::reverse;

    TimeNs next = next_pid_ns_;
    next = std::min(next, valve_.next_event_ns());
    next = std::min(next, apply_section_chatter(now_ns));
    next = std::min(next, refeed_stale_fix(now_ns));
    // Act at the instants the odometer predicts from its last edge, not at the
    // next read: the breakpoint, and the continuation's open point.
    next = std::min(next, locator_.next_compare_ns());
    if (phase_ == msg::SPRAY_APPROACH && !config_.faults.never_resume) {
        const std::optional<TimeNs> open_ns = locator_.instant_nozzle_to_go_m(continuation_lead_m());
        if (open_ns && *open_ns > now_ns) next = std::min(next, *open_ns);
    }
    return next;
}

// ------------------------------------------------------------------ outputs

io::ControllerIndicators SprayController::indicators() const {
    io::ControllerIndicators indicators;
    indicators.breakpoints_stored = stored_count_;
    indicators.breakpoints_reached = reached_count_;
    indicators.breakpoint_pending = locator_.target().has_value();
    indicators.odometer_active = locator_.odometer_active();
    return indicators;
}

std::vector<msg::BreakpointEvent> SprayController::take_events() {
    std::vector<msg::BreakpointEvent> out;
    out.swap(events_);
    return out;
}

std::vector<std::string> SprayController::take_notices() {
    std::vector<std::string> out;
    out.swap(notices_);
    return out;
}

msg::ControllerStatus SprayController::status(TimeNs now_ns) const {
    msg::ControllerStatus status;
    status.time_ns(now_ns);
    status.positioning_mode(config_.positioning == Positioning::fusion ? msg::RTK_ODOMETER_FUSION : msg::RTK_ONLY);
    status.breakpoint_pending(locator_.target().has_value());
    status.odometer_active(locator_.odometer_active());
    status.nozzle_to_breakpoint_m(locator_.nozzle_to_breakpoint_m_at(now_ns).value_or(kNaN));
    status.speed_km_h(speed_m_s() * 3.6);
    status.l4_m(locator_.l4_m());
    status.gnss_fix_quality(static_cast<std::uint16_t>(last_quality_));
    status.nmea_rejected_count(rejected_sentences_);
    status.spray_phase(phase_);
    status.target_flow_l_min(config_.target_flow_l_min);
    status.measured_flow_l_min(flow_meter_.flow_l_min().value_or(kNaN));
    status.pump_flow_l_min(pump_flow_l_min_.value_or(kNaN));
    status.valve_opening_estimate_pct(valve_.believed_opening_pct());
    status.valve_opening_command_pct(valve_command_pct_);
    status.boom_height_m(linkage_rise_m_);
    return status;
}

}  // namespace rig::controller
