// A stand-in for a team's controller board on the bench, written from the
// documentation alone (docs/modbus-register-map.md: "External boards", the
// register map and "Scalings"; docs/controller-contract.md for what is judged):
// it takes the ports from the attach.json the rig writes, reads the NMEA line,
// polls the rig's Modbus RTU slave with its own libmodbus master (addresses and
// scalings as the page gives them, none of the rig's register-map code) and does
// breakpoint continuation its own way, simpler than the reference controller:
//
//   valve reset  ball valve driven open for 5 s (the paper's reset, sec. 2.2.2:
//                the full-open end stop from any opening above 55 %), then back
//                to the calibration's opening for the target at the pump flow
//                read through Eq. 8 (pre-adjustment);
//   first pass   sections open while the wheel turns (zero-speed shut-off),
//                unloading valve closed with them; the opening trimmed from the
//                KF11 flow (Eq. 3 over the capture timer), so the continuation
//                starts on an opening the pipeline has confirmed;
//   button       the GNSS antenna's position is stored as the breakpoint
//                (holding register 0 counts up, 2 says pending); sections shut;
//   approach     after the headland the remaining distance along the RMC
//                course is the last fix's, less the receiver's latency and the
//                wheel's pulses since: the sections open a valve delay and a
//                margin before it, and "reached" (holding register 1) is
//                written at the predicted instant the antenna, and so the
//                nozzle line, is over the stored point;
//   continuation sprays on, trimming only a flow clearly out of the band.
//
//   board_player --attach OUT/cases/NAME/attach.json [--target-l-min 20]
//                [--sections 3] [--gnss-latency-s 0.1] [--stop-polling-after-s S]
//                [--wait-s 120]
//
// --gnss-latency-s: the receiver's output latency, from its datasheet (the
// G970II's 0.1 s here). --stop-polling-after-s: after S seconds of polling, the
// board goes quiet on Modbus (a hung firmware task) while it keeps reading NMEA
// and stays alive. Exit 0 when the rig closed the wires (the case ended), 1 on
// an error.
// Before libmodbus: its ON / OFF macros would break Fast DDS's headers behind realtime.h.
#include "rig/runtime/realtime.h"

#include <fcntl.h>
#include <modbus/modbus.h>
#include <unistd.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <deque>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "rig/nmea/nmea_parser.h"
#include "rig/runtime/clock.h"

namespace {

// ---- From docs/modbus-register-map.md.
constexpr int kSlaveId = 1;
constexpr int kInputRegisterCount = 9;  // registers 0-8 in one FC 04: the counters never tear
constexpr int kCoilCount = 16;          // one FC 15 of coils 0-15 sets everything
constexpr int kCoilBallValveForward = 0;
constexpr int kCoilBallValveReverse = 1;
constexpr int kCoilUnloadingValveOpen = 2;
constexpr int kCoilFirstSection = 8;
constexpr int kDiscreteBreakpointButton = 0;
constexpr int kDiscreteSpraySwitch = 1;
constexpr int kHoldingBreakpointsStored = 0;
constexpr int kHoldingBreakpointsReached = 1;
constexpr int kHoldingIndicatorFlags = 2;
constexpr std::uint16_t kFlagBreakpointPending = 1;
// Valve calibration lines (opening %, slope, intercept L/min): main = slope x pump + intercept.
struct CalibrationLine {
    double opening_pct, slope, intercept_l_min;
};
constexpr CalibrationLine kCalibration[] = {
    {87.0, 0.35, 3.315}, {90.0, 0.38, 4.182}, {93.0, 0.42, 5.938}, {94.0, 0.46, 7.694}, {95.0, 0.50, 9.95}};
// docs/controller-contract.md / seed 000 Table 1: a section valve is open 0.2 s
// after its command, the droplets land about 0.07 s later.
constexpr double kSectionOpenToLandingS = 0.27;

// ---- This board's own choices.
constexpr double kPollPeriodS = 0.02;
constexpr int kBoardPriority = 30;  // SCHED_FIFO, below the rig's master (50) and wire threads (45)
constexpr double kResetOpenS = 5.0;
constexpr double kPumpAveragingFromS = 1.0;  // the pump's pulsation averaged over the rest of the reset
// After the sections open or the valve moves, the pipeline settles before the
// flow is measured again, over a window long enough for tens of KF11 pulses.
// Table 2 gives 1.1-1.7 s to settle into the +-3 % band; 1.5 s was too short on
// the rig once its boom held air (a window that starts while the flow still
// rises reads it low, and the trim that follows overshoots the band).
constexpr double kSettleS = 2.5;
constexpr double kFlowWindowS = 1.0;
// Of target. The judged band is +-3 %: on the first pass the opening is brought
// within 1 % so the continuation's pipeline settles into the band in time;
// during the continuation only a flow clearly off is touched, since a trim
// there moves the flow while it is being judged.
constexpr double kFirstPassTrimDeadbandPct = 1.0;
constexpr double kContinuationTrimDeadbandPct = 2.0;
constexpr double kTrimGain = 0.8;         // of the calibration's correction: never overshoot
constexpr double kMaxTrimDriveS = 0.3;
// The wheel turns: the speed over the last quarter second, from the encoder.
constexpr double kSpeedWindowS = 0.25;
constexpr double kMovingMS = 0.05;
// Sections open this far before the breakpoint on top of the valves' delay, so
// that nothing after it is missed (the overlap limit is 3.3 m): the flow must
// be at half its dose by then, and a boom takes tenths of a second to fill
// (Table 2: 1.1-1.7 s to settle). 0.4 m missed 5 cm at 6 km/h once the rig's
// boom held air; 1.0 m is 0.6 s at 6 km/h.
constexpr double kOpenMarginM = 1.0;
// The approach counts only once the sprayer has been this far from the stored
// point (it stands on it when the button is pressed).
constexpr double kArmDistanceM = 2.0;
// Local east/north metres around the first fix (the field is a few tens of metres).
constexpr double kEarthRadiusM = 6371000.0;
constexpr double kPi = 3.14159265358979323846;

struct Options {
    std::filesystem::path attach_file;
    double target_l_min = 20.0;
    int sections = 3;
    double gnss_latency_s = 0.1;
    std::optional<double> stop_polling_after_s;
    double wait_s = 120.0;
};

struct Scalings {
    double adc_full_scale = 4095;
    double pump_full_scale_m3_h = 8.0;
    double pulses_per_l = 90.0;
    double capture_timer_hz = 1e6;
    double encoder_pulses_per_rev = 1000;
    double wheel_diameter_m = 1.0;
    // The ball valve: full travel, the motor's start delay, the gear play taken up on a reversal.
    double valve_travel_s = 11.0;
    double valve_start_delay_s = 0.02;
    double valve_backlash_pct = 0.3;
};

double predicted_flow(double opening_pct, double pump_l_min) {
    // Between calibrated openings linearly; the end segments extended.
    std::size_t upper = 1;
    while (upper + 1 < std::size(kCalibration) && opening_pct > kCalibration[upper].opening_pct) ++upper;
    const CalibrationLine& a = kCalibration[upper - 1];
    const CalibrationLine& b = kCalibration[upper];
    const double flow_a = a.slope * pump_l_min + a.intercept_l_min;
    const double flow_b = b.slope * pump_l_min + b.intercept_l_min;
    return flow_a + (flow_b - flow_a) * (opening_pct - a.opening_pct) / (b.opening_pct - a.opening_pct);
}

double opening_for(double flow_l_min, double pump_l_min) {
    double low = 0.0, high = 100.0;  // flow rises with opening: bisect
    for (int i = 0; i < 60; ++i) {
        const double mid = (low + high) / 2;
        (predicted_flow(mid, pump_l_min) < flow_l_min ? low : high) = mid;
    }
    return (low + high) / 2;
}

struct EastNorth {
    double east_m = 0.0, north_m = 0.0;
};

class Board {
public:
    Board(const Options& options, const nlohmann::json& attach) : options_(options) {
        for (const nlohmann::json& port : attach.at("ports")) {
            const std::string role = port.at("role");
            if (role == "gnss_nmea") nmea_path_ = port.at("path");
            if (role == "modbus_rtu") modbus_path_ = port.at("path");
        }
        if (nmea_path_.empty() || modbus_path_.empty()) throw std::runtime_error("attach.json lacks gnss_nmea or modbus_rtu");
        const nlohmann::json& scalings = attach.at("scalings");
        scalings_.adc_full_scale = scalings.at("adc_full_scale_counts");
        scalings_.pump_full_scale_m3_h = scalings.at("pump_flow_full_scale_m3_h");
        scalings_.pulses_per_l = scalings.at("main_flow_pulses_per_l");
        scalings_.capture_timer_hz = scalings.at("capture_timer_hz");
        scalings_.encoder_pulses_per_rev = scalings.at("wheel_encoder_pulses_per_rev");
        scalings_.wheel_diameter_m = scalings.at("wheel_diameter_m");
        scalings_.valve_travel_s = scalings.at("valve_travel_s");
        scalings_.valve_start_delay_s = scalings.at("valve_motor_start_delay_s");
        scalings_.valve_backlash_pct = scalings.at("valve_backlash_pct");
        metres_per_pulse_ = kPi * scalings_.wheel_diameter_m / scalings_.encoder_pulses_per_rev;

        nmea_fd_ = ::open(nmea_path_.c_str(), O_RDONLY | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
        if (nmea_fd_ < 0) throw std::runtime_error("cannot open " + nmea_path_ + ": " + std::strerror(errno));
        modbus_ = modbus_new_rtu(modbus_path_.c_str(), 115200, 'N', 8, 1);
        if (modbus_ == nullptr || modbus_set_slave(modbus_, kSlaveId) != 0 || modbus_connect(modbus_) != 0) {
            throw std::runtime_error("cannot open Modbus RTU on " + modbus_path_ + ": " + modbus_strerror(errno));
        }
        modbus_set_response_timeout(modbus_, 0, 500'000);
    }
    ~Board() {
        if (modbus_ != nullptr) {
            modbus_close(modbus_);
            modbus_free(modbus_);
        }
        if (nmea_fd_ >= 0) ::close(nmea_fd_);
    }

    // Returns when the rig has closed the wires (the case is over).
    void run() {
        // A board's firmware runs on hardware of its own: the host's other work
        // must not delay its polls, so this stand-in asks for real-time scheduling
        // as the rig does (below the rig's threads).
        std::cout << "board: scheduling " << rig::request_realtime_scheduling(kBoardPriority).detail << std::endl;
        started_s_ = now_s();
        while (!line_closed_) {
            read_nmea();
            const double t = board_time_s();
            const bool polling = !options_.stop_polling_after_s || t < *options_.stop_polling_after_s;
            if (polling) {
                poll_and_drive(t);
                end_drive_on_time();
            }
            clock_.sleep_until_ns(clock_.now_ns() + rig::seconds_to_ns(kPollPeriodS));
        }
        std::cout << "board: " << sentences_ << " NMEA sentences parsed (" << fixes_ << " GGA), " << polls_
                  << " polls, " << failed_polls_ << " failed; " << (line_closed_ ? "the rig closed the line" : "stopped")
                  << std::endl;
    }

private:
    enum class Pass { first, approach, continuation };

    struct Fix {
        EastNorth position;
        std::optional<std::uint32_t> encoder_at_arrival;  // the first poll after the sentence came
        double arrival_s = 0.0;
    };
    struct Sample {
        double t;
        std::uint32_t pulses;
        std::uint32_t edge_ticks;
    };

    double now_s() const { return rig::ns_to_seconds(clock_.now_ns()); }
    double board_time_s() const { return now_s() - started_s_; }

    EastNorth local(const rig::nmea::Position& position) {
        if (!origin_) origin_ = position;
        const double to_rad = kPi / 180.0;
        return {(position.lon_deg - origin_->lon_deg) * to_rad * kEarthRadiusM * std::cos(origin_->lat_deg * to_rad),
                (position.lat_deg - origin_->lat_deg) * to_rad * kEarthRadiusM};
    }

    void read_nmea() {
        char chunk[1024];
        for (;;) {
            const ssize_t got = ::read(nmea_fd_, chunk, sizeof chunk);
            if (got > 0) {
                pending_.append(chunk, static_cast<std::size_t>(got));
                continue;
            }
            if (got < 0 && (errno == EAGAIN || errno == EINTR)) break;
            line_closed_ = true;  // EOF / EIO: the rig ended the case and closed its end
            break;
        }
        for (std::size_t end; (end = pending_.find('\n')) != std::string::npos; pending_.erase(0, end + 1)) {
            const rig::nmea::ParseResult parsed = rig::nmea::parse_sentence(std::string_view(pending_).substr(0, end));
            if (!parsed.ok()) continue;
            ++sentences_;
            if (const auto* gga = std::get_if<rig::nmea::GgaData>(&parsed.sentence->data)) {
                ++fixes_;
                if (gga->position && gga->fix_quality.value_or(0) > 0) {
                    fix_ = Fix{local(*gga->position), std::nullopt, board_time_s()};
                }
            } else if (const auto* rmc = std::get_if<rig::nmea::RmcData>(&parsed.sentence->data)) {
                // The course over ground is noise at a standstill: kept from when the sprayer drove.
                if (rmc->course_true_deg && rmc->speed_m_s.value_or(0.0) > 0.3) course_deg_ = *rmc->course_true_deg;
            }
        }
    }

    void failed(const char* what) {
        if (++failed_polls_ <= 5) std::cout << "board: " << what << ": " << modbus_strerror(errno) << std::endl;
        // A late response still on its way must not be taken for the next request's.
        modbus_flush(modbus_);
    }

    void write_holding(int address, std::uint16_t value) {
        if (modbus_write_register(modbus_, address, value) != 1) failed("FC 06");
    }

    // A drive ending before the next poll is ended by a timer, as firmware
    // would: the relay's on-time is then not rounded to poll cycles.
    void end_drive_on_time() {
        const double until_end = drive_until_s_ - board_time_s();
        if (until_end <= 0 || until_end > kPollPeriodS + cycle_s_) return;
        clock_.sleep_until_ns(clock_.now_ns() + rig::seconds_to_ns(until_end));
        coils_[kCoilBallValveForward] = 0;
        coils_[kCoilBallValveReverse] = 0;
        if (modbus_write_bits(modbus_, 0, kCoilCount, coils_) != kCoilCount) failed("FC 15");
    }

    // The wheel's speed over the last kSpeedWindowS, from the encoder.
    double wheel_speed_m_s(double t, std::uint32_t count) {
        encoder_history_.push_back({t, count});
        while (encoder_history_.size() > 2 && t - encoder_history_[1].first >= kSpeedWindowS) encoder_history_.pop_front();
        const auto& [t0, count0] = encoder_history_.front();
        if (t - t0 <= 0.0) return 0.0;
        return static_cast<std::uint32_t>(count - count0) * metres_per_pulse_ / (t - t0);
    }

    // What is left to drive until the antenna is over the stored breakpoint,
    // along the course, now: the last fix's, less what the sprayer drove since
    // it was measured (the receiver's latency, then the wheel's pulses).
    std::optional<double> remaining_m(double speed_m_s, std::uint32_t encoder) const {
        if (!fix_ || !fix_->encoder_at_arrival || !breakpoint_ || !course_deg_) return std::nullopt;
        const double course_rad = *course_deg_ * kPi / 180.0;
        const double along_east = std::sin(course_rad), along_north = std::cos(course_rad);
        const double at_fix = (breakpoint_->east_m - fix_->position.east_m) * along_east +
                              (breakpoint_->north_m - fix_->position.north_m) * along_north;
        const double since_fix =
            speed_m_s * options_.gnss_latency_s + static_cast<std::uint32_t>(encoder - *fix_->encoder_at_arrival) * metres_per_pulse_;
        return at_fix - since_fix;
    }

    // One poll: inputs in, outputs out.
    void poll_and_drive(double t) {
        std::uint16_t registers[kInputRegisterCount];
        std::uint8_t inputs[2];
        if (modbus_read_input_registers(modbus_, 0, kInputRegisterCount, registers) != kInputRegisterCount) {
            failed("FC 04");
            return;
        }
        if (modbus_read_input_bits(modbus_, 0, 2, inputs) != 2) {
            failed("FC 02");
            return;
        }
        ++polls_;
        if (last_poll_s_) cycle_s_ = t - *last_poll_s_;
        last_poll_s_ = t;
        const std::uint32_t encoder = (std::uint32_t{registers[0]} << 16) | registers[1];
        const std::uint32_t flow_pulses = (std::uint32_t{registers[2]} << 16) | registers[3];
        const std::uint32_t edge_ticks = (std::uint32_t{registers[7]} << 16) | registers[8];
        const double pump_l_min =
            registers[4] / scalings_.adc_full_scale * scalings_.pump_full_scale_m3_h * 1000.0 / 60.0;  // Eq. 8
        const bool spray_switch = inputs[kDiscreteSpraySwitch] != 0;
        const bool button = inputs[kDiscreteBreakpointButton] != 0;
        if (fix_ && !fix_->encoder_at_arrival) fix_->encoder_at_arrival = encoder;
        const double speed = wheel_speed_m_s(t, encoder);

        const bool spraying = decide_sections(t, spray_switch, button && !button_was_, speed, encoder);
        button_was_ = button;
        decide_valve(t, spraying, pump_l_min, flow_pulses, edge_ticks);
        std::fill(std::begin(coils_), std::end(coils_), 0);
        const bool driving = t < drive_until_s_;
        coils_[kCoilBallValveForward] = driving && drive_forward_;
        coils_[kCoilBallValveReverse] = driving && !drive_forward_;
        coils_[kCoilUnloadingValveOpen] = !spraying;  // the boom line is fed only while it sprays
        for (int section = 0; section < options_.sections; ++section) coils_[kCoilFirstSection + section] = spraying;
        if (modbus_write_bits(modbus_, 0, kCoilCount, coils_) != kCoilCount) failed("FC 15");
    }

    // The breakpoint procedure; returns whether the sections spray.
    bool decide_sections(double t, bool spray_switch, bool button_pressed, double speed, std::uint32_t encoder) {
        const bool moving = speed > kMovingMS;
        if (pass_ == Pass::first && button_pressed) {
            if (!fix_) {
                std::cout << "board: t=" << t << " s breakpoint button pressed without a GNSS fix: ignored" << std::endl;
            } else {
                breakpoint_ = fix_->position;
                pass_ = Pass::approach;
                write_holding(kHoldingBreakpointsStored, ++breakpoints_stored_);
                write_holding(kHoldingIndicatorFlags, kFlagBreakpointPending);
                std::cout << "board: t=" << t << " s breakpoint stored at " << breakpoint_->east_m << " E "
                          << breakpoint_->north_m << " N (m from the first fix)" << std::endl;
            }
        }
        if (pass_ == Pass::approach) {
            const std::optional<double> remaining = remaining_m(speed, encoder);
            if (remaining && *remaining > kArmDistanceM) armed_ = true;
            if (armed_ && moving && remaining) {
                if (!approach_open_ && *remaining <= speed * kSectionOpenToLandingS + kOpenMarginM) {
                    approach_open_ = true;
                    std::cout << "board: t=" << t << " s sections open " << *remaining << " m before the breakpoint"
                              << std::endl;
                }
                // "Reached" at the instant the antenna is over the stored point:
                // now, or after a timer if that falls before the next poll.
                const double until_s = *remaining / speed;
                if (until_s <= cycle_s_ + kPollPeriodS) {
                    if (until_s > 0) clock_.sleep_until_ns(clock_.now_ns() + rig::seconds_to_ns(until_s));
                    write_holding(kHoldingBreakpointsReached, ++breakpoints_reached_);
                    write_holding(kHoldingIndicatorFlags, 0);
                    pass_ = Pass::continuation;
                    std::cout << "board: t=" << board_time_s() << " s breakpoint reached (" << until_s
                              << " s after the poll)" << std::endl;
                }
            }
        }
        const bool may_spray = pass_ != Pass::approach || approach_open_;
        return spray_switch && moving && may_spray;
    }

    // Moves the valve by `pct` of its travel (sign = direction): the motor's
    // start delay and, on a reversal, the gear play come on top.
    double drive_by(double t, double pct) {
        const bool forward = pct > 0;
        double seconds = std::abs(pct) / 100.0 * scalings_.valve_travel_s + scalings_.valve_start_delay_s;
        if (forward != drive_forward_) seconds += scalings_.valve_backlash_pct / 100.0 * scalings_.valve_travel_s;
        drive_forward_ = forward;
        drive_until_s_ = t + seconds;
        return seconds;
    }

    void decide_valve(double t, bool spraying, double pump_l_min, std::uint32_t pulses, std::uint32_t edge_ticks) {
        if (!reset_started_) {
            reset_started_ = true;
            drive_forward_ = true;
            drive_until_s_ = t + kResetOpenS;  // to the full-open end stop
            return;
        }
        if (!pre_adjusted_) {
            if (t > kPumpAveragingFromS) {
                pump_sum_l_min_ += pump_l_min;
                ++pump_samples_;
            }
            if (t < drive_until_s_) return;
            pre_adjusted_ = true;
            pump_l_min_ = pump_samples_ > 0 ? pump_sum_l_min_ / static_cast<double>(pump_samples_) : pump_l_min;
            opening_pct_ = opening_for(options_.target_l_min, pump_l_min_);
            std::cout << "board: pump " << pump_l_min_ << " L/min, pre-adjusting to " << opening_pct_ << " %" << std::endl;
            drive_by(t, opening_pct_ - 100.0);
            return;
        }
        if (!spraying || t < drive_until_s_) {
            window_start_.reset();
            settled_at_s_.reset();
            return;
        }
        if (!settled_at_s_) settled_at_s_ = t + kSettleS;  // the sections just opened
        if (t < *settled_at_s_) return;
        // Eq. 3 from edge to edge: pulses between two captured edges over the capture-time between them.
        if (!window_start_) {
            window_start_ = Sample{t, pulses, edge_ticks};
            return;
        }
        if (t - window_start_->t < kFlowWindowS || pulses == window_start_->pulses) return;
        const double edge_s = static_cast<std::uint32_t>(edge_ticks - window_start_->edge_ticks) / scalings_.capture_timer_hz;
        const double flow = static_cast<std::uint32_t>(pulses - window_start_->pulses) / scalings_.pulses_per_l / edge_s * 60.0;
        window_start_ = Sample{t, pulses, edge_ticks};
        const double error = options_.target_l_min - flow;
        std::cout << "board: t=" << t << " s flow " << flow << " L/min" << std::endl;
        const double deadband_pct = pass_ == Pass::first ? kFirstPassTrimDeadbandPct : kContinuationTrimDeadbandPct;
        if (std::abs(error) < options_.target_l_min * deadband_pct / 100.0) return;
        // The opening change the calibration says the error needs, as motor time.
        const double per_pct = predicted_flow(opening_pct_ + 0.5, pump_l_min_) - predicted_flow(opening_pct_ - 0.5, pump_l_min_);
        const double largest_pct = kMaxTrimDriveS / scalings_.valve_travel_s * 100.0;
        const double delta_pct = std::clamp(kTrimGain * error / per_pct, -largest_pct, largest_pct);
        opening_pct_ += delta_pct;
        const double drive_s = drive_by(t, delta_pct);
        window_start_.reset();
        settled_at_s_ = t + drive_s + kSettleS;
    }

    Options options_;
    Scalings scalings_;
    double metres_per_pulse_ = 0.0;
    std::string nmea_path_, modbus_path_;
    int nmea_fd_ = -1;
    modbus_t* modbus_ = nullptr;
    rig::RealtimeClock clock_;
    double started_s_ = 0.0;
    std::string pending_;
    bool line_closed_ = false;
    long sentences_ = 0, fixes_ = 0, polls_ = 0, failed_polls_ = 0;
    // Position and the breakpoint procedure.
    std::optional<rig::nmea::Position> origin_;
    std::optional<Fix> fix_;
    std::optional<double> course_deg_;
    std::deque<std::pair<double, std::uint32_t>> encoder_history_;
    Pass pass_ = Pass::first;
    std::optional<EastNorth> breakpoint_;
    bool button_was_ = false, armed_ = false, approach_open_ = false;
    std::uint16_t breakpoints_stored_ = 0, breakpoints_reached_ = 0;
    // The valve and the flow.
    bool reset_started_ = false, pre_adjusted_ = false, drive_forward_ = false;
    double drive_until_s_ = 0.0, opening_pct_ = 0.0, pump_l_min_ = 0.0;
    std::optional<Sample> window_start_;
    std::optional<double> settled_at_s_;
    std::optional<double> last_poll_s_;
    double cycle_s_ = kPollPeriodS;  // the last poll-to-poll time
    std::uint8_t coils_[kCoilCount] = {};
    double pump_sum_l_min_ = 0.0;
    long pump_samples_ = 0;
};

}  // namespace

int main(int argc, char** argv) {
    Options options;
    for (int i = 1; i < argc; ++i) {
        const std::string arg = argv[i];
        if (i + 1 >= argc) {
            std::cerr << "board_player: " << arg << " needs a value\n";
            return 1;
        }
        const std::string value = argv[++i];
        if (arg == "--attach") options.attach_file = value;
        else if (arg == "--target-l-min") options.target_l_min = std::stod(value);
        else if (arg == "--sections") options.sections = std::stoi(value);
        else if (arg == "--gnss-latency-s") options.gnss_latency_s = std::stod(value);
        else if (arg == "--stop-polling-after-s") options.stop_polling_after_s = std::stod(value);
        else if (arg == "--wait-s") options.wait_s = std::stod(value);
        else {
            std::cerr << "board_player: unknown option " << arg << "\n";
            return 1;
        }
    }
    try {
        // The rig writes attach.json before it waits for the board.
        const rig::RealtimeClock clock;
        while (!std::filesystem::exists(options.attach_file)) {
            if (rig::ns_to_seconds(clock.now_ns()) > options.wait_s) {
                std::cerr << "board_player: no " << options.attach_file << " after " << options.wait_s << " s\n";
                return 1;
            }
            clock.sleep_until_ns(clock.now_ns() + rig::seconds_to_ns(0.05));
        }
        std::ifstream in(options.attach_file);
        const nlohmann::json attach = nlohmann::json::parse(in);
        Board board(options, attach);
        board.run();
        return 0;
    } catch (const std::exception& error) {
        std::cerr << "board_player: " << error.what() << "\n";
        return 1;
    }
}
