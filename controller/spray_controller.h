#pragma once
// The reference controller's firmware logic (seed 000 sec. 2.2, Fig. 2), free of
// any wire: it is fed the board's inputs with the time they were read, and says
// what the outputs are. The DDS node (controller/reference_controller.h) and the
// wired bench mode (serial NMEA + Modbus) both drive this one class, so the
// controller under test does not change with the wire (ros2_control's idea).
//
// Inputs                         Conversions
//   NMEA sentences (RS232)         GGA/RMC -> fix, course            (nmea_parser.h)
//   land-wheel encoder count       Eq. 5 speed, odometer            (breakpoint_equations.h)
//   KF11 pulse count               Eq. 3 main flow                  (flow_rate_meter.h)
//   pump-outlet sensor voltage     Eq. 8 pump flow                  (flow_equations.h)
//   boom-height sensor voltage     h -> Eq. 6 L4                    (flow_equations.h)
//   breakpoint button, spray switch
// Outputs: ball-valve relays, section valves, unloading valve; breakpoint events;
// status.
//
// The spray sequence (SprayPhase in idl/controller.idl):
//   VALVE_RESET  at start: valve open 5 s, back 2 s (a known position);
//   IDLE         spray switch off: sections closed, unloading open;
//   PRE_ADJUST   valve to the opening the calibration predicts for the target
//                (ValveCalibration::opening_for), sections closed until the
//                valve is there and the sprayer moves (zero-speed shutoff);
//   REGULATING   sections open, unloading closed; once the measured flow has
//                settled, the PID of Eq. 2 every period trims the opening
//                (with `calibration_run`, the valve calibration of sec. 2.4.2
//                drives the valve instead: valve_calibration_procedure.h);
//   HALTED       the breakpoint button stored a breakpoint: spraying stops
//                until the continuation;
//   APPROACH     the sprayer approaches the stored breakpoint: valve reset,
//                pre-adjustment, and the sections open when the odometer says
//                the nozzle line is v (t2 + t3) short of it (Eq. 7; at it when
//                hysteresis_compensation is off); then REGULATING, and the
//                breakpoint is cleared once the flow is on target (and reached).
#include <cstdint>
#include <deque>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "controller/breakpoint_locator.h"
#include "controller/breakpoint_store.h"
#include "controller/controller_config.h"
#include "controller/flow_pid.h"
#include "controller/flow_rate_meter.h"
#include "controller/valve_calibration.h"
#include "controller/valve_calibration_procedure.h"
#include "controller/valve_driver.h"
#include "controllerPubSubTypes.h"
#include "rig/runtime/clock.h"
#include "rig/nmea/nmea_parser.h"
#include "rig/runtime/io_image.h"

namespace rig::controller {

class SprayController {
public:
    // Loads the breakpoint store from state_dir (a corrupt store throws, before time starts).
    SprayController(ControllerConfig config, const std::filesystem::path& state_dir);

    // Time starts: begins the valve reset.
    void start(TimeNs now_ns);

    // ---- inputs, each with the instant it was read
    void on_nmea_sentence(const std::string& line, TimeNs now_ns);
    // The encoder's capture timer value at the last counted edge (1 MHz, 32 bit,
    // the board's clock: now_ns's microseconds) when the wire carries it.
    void on_encoder_count(std::uint32_t count_pulses, std::optional<std::uint32_t> last_edge_capture_us,
                          TimeNs now_ns);
    // The capture timer value at the last edge (1 MHz) when the wire carries it.
    void on_flow_meter_count(std::uint32_t count_pulses, std::optional<std::uint32_t> last_edge_capture_us,
                             TimeNs now_ns);
    void on_pump_sensor_voltage(double voltage_v, TimeNs now_ns);
    void on_boom_height_voltage(double voltage_v, TimeNs now_ns);
    void on_breakpoint_button(bool closed, TimeNs now_ns);
    void on_spray_switch(bool closed, TimeNs now_ns);

    // Does the work due at now (the sequence, the PID, the valve relays) and
    // returns when it must run again even without input.
    TimeNs update(TimeNs now_ns);

    // ---- outputs
    const io::ActuatorCommands& actuators() const { return actuators_; }
    io::ControllerIndicators indicators() const;
    // Breakpoint events since the last call, in order.
    std::vector<msg::BreakpointEvent> take_events();
    msg::ControllerStatus status(TimeNs now_ns) const;
    msg::SprayPhase phase() const { return phase_; }
    // Sentences that failed parsing or their checksum.
    std::uint32_t rejected_sentences() const { return rejected_sentences_; }
    // Messages for the operator (e.g. "button pressed without a fix"), since the last call.
    std::vector<std::string> take_notices();

private:
    void handle_fix_complete(TimeNs now_ns);
    void on_locator_event(LocatorEvent event, TimeNs now_ns);
    void store_breakpoint_here(TimeNs now_ns);
    void clear_breakpoint(TimeNs now_ns);
    void select_target();
    void publish_event(msg::BreakpointEventKind kind, const StoredBreakpoint& breakpoint, TimeNs now_ns);
    double speed_m_s() const;
    // Above the zero-speed shutoff (with hysteresis: `spraying` = the sections are open).
    bool moving_fast_enough(bool spraying) const;
    std::uint16_t all_sections_mask() const;

    void enter(msg::SprayPhase phase, TimeNs now_ns);
    void open_sections(TimeNs now_ns);
    void close_sections(TimeNs now_ns);
    void start_pre_adjust(TimeNs now_ns);
    // The valve driver's commands, through the TEST-ONLY valve_held fault.
    void command_valve(double opening_pct, TimeNs now_ns);
    void reset_valve(TimeNs now_ns);
    // TEST-ONLY faults acting each update: the section chatter and the stale fix.
    // Return when they next need to run.
    TimeNs apply_section_chatter(TimeNs now_ns);
    TimeNs refeed_stale_fix(TimeNs now_ns);
    void regulate(TimeNs now_ns);
    // The valve calibration run (config_.calibration_run): one period of it, and
    // its file written when the switch goes off.
    void calibrate(TimeNs now_ns);
    void write_calibration_file();
    bool continuation_open_point_reached(TimeNs now_ns) const;
    // The lead of Eq. 7, v (t2 + t3), at which the continuation opens.
    double continuation_lead_m() const;

    ControllerConfig config_;
    std::filesystem::path state_dir_;
    BreakpointStore store_;
    BreakpointLocator locator_;
    ValveCalibration calibration_;
    ValveDriver valve_;
    FlowPid pid_;
    FlowRateMeter flow_meter_;
    std::optional<ValveCalibrationProcedure> calibration_run_;  // set when config_.calibration_run.enabled

    // GNSS, assembled from GGA (position, quality) and RMC (course).
    std::optional<FixInput> last_fix_;
    // The UTC time of the GGA that gave last_fix_: an RMC completes the epoch
    // only when it carries the same time (a lost GGA must not leave the one
    // before it to be taken as this epoch's fix).
    std::optional<nmea::UtcTime> last_fix_utc_;
    std::optional<double> last_course_deg_;  // kept while standing (RMC course is empty then)
    TimeNs last_fix_complete_ns_ = 0;        // when the last GGA+RMC epoch completed
    TimeNs next_stale_fix_ns_ = 0;           // the stale-fix fault's next re-feed
    int last_quality_ = 0;
    std::uint32_t rejected_sentences_ = 0;

    // Encoder reads within the Eq. 5 speed window, by read time. With a capture
    // time Eq. 5 is timed edge to edge (t1 between the edges' captures), as the
    // flow meter's Eq. 3; without, from read to read.
    struct EncoderRead {
        TimeNs read_ns;
        TimeNs timed_ns;   // the last edge's capture, or the read time without one
        std::uint32_t count;
    };
    std::deque<EncoderRead> encoder_window_;
    std::optional<EncoderReading> latest_encoder_;
    bool button_closed_ = false;
    bool spray_switch_on_ = false;
    std::optional<double> pump_flow_l_min_;
    TimeNs last_pump_sample_ns_ = 0;
    double linkage_rise_m_;
    bool boom_height_read_ = false;  // a pull-wire sample has been taken (faults.boom_height_read_once)

    msg::SprayPhase phase_ = msg::SPRAY_VALVE_RESET;
    io::ActuatorCommands actuators_{};
    bool halted_ = false;                 // a stored breakpoint waits for its continuation
    bool continuing_ = false;             // this regulating episode is a continuation
    bool reached_ = false;                // the locator said the nozzle line is at the breakpoint
    TimeNs sections_opened_ns_ = 0;
    bool flow_established_ = false;
    std::optional<double> previous_measurement_l_min_;
    std::optional<double> earlier_measurement_l_min_;  // the one before it
    std::optional<TimeNs> on_target_since_ns_;
    bool continuation_on_target_ = false;
    double valve_command_pct_ = 0.0;
    double pre_adjusted_pct_ = 0.0;       // the opening the calibration gave for the target
    TimeNs next_pid_ns_ = 0;
    bool started_ = false;

    std::vector<msg::BreakpointEvent> events_;
    std::vector<std::string> notices_;
    std::uint16_t stored_count_ = 0;
    std::uint16_t reached_count_ = 0;
};

}  // namespace rig::controller
