#pragma once
// Seed 001's reference controller as a rig node on DDS: what the paper's
// Raspberry Pi does (Sec. 1.1, 4.2), with DDS topics as its wires. It reads the
// AD300's RMC lines and the L4 laser's serial lines, hands them to the logic
// (boundary_controller.h), and publishes the PWM duty of every nozzle when it
// changes. It never sees truth.
//
// Subscriptions: device/gnss/nmea, device/laser_height/serial; with
//                vision (boundary_node_config.h) device/camera_left/frame and
//                device/camera_right/frame
// Publications:  actuator/nozzle_pwm/duty; with vision controller/vision/density
//                (one VisionReport per frame processed)
// Wired (the bench path, real time only): the RMC and laser lines come from
// serial ports instead of those two topics, as the Pi's UARTs have them; the
// PWM duty still goes out on DDS.
// With a `calibration:` sweep (boundary_node_config.h) it holds the sweep's
// duties on every nozzle instead, as the paper's Table 3 measurement did.
#include <memory>
#include <string>
#include <vector>

#include "controller/boundary/boundary_controller.h"
#include "controller/boundary/boundary_node_config.h"
#include "controller/boundary/duty_command_delay.h"
#include "controller/boundary/vision/nozzle_vision.h"
#include "rig/runtime/dds_context.h"
#include "rig/runtime/node.h"
#include "rig/wire/serial_port.h"

namespace rig::controller::boundary {

// The serial lines of the wired mode; an empty path: that input comes from DDS.
struct BoundarySerialLines {
    std::string nmea_port;       // the AD300's RMC (the Pi's RXD0)
    SerialSettings nmea_line{};  // 115200 8N1 unless told
    std::string laser_port;      // the L4's lines (the Pi's RXD3)
    SerialSettings laser_line{};
    // How often the ports are read: a line waits at most this long in the
    // UART before the logic sees it (1.5 cm at 1.5 m/s).
    TimeNs poll_period_ns = 10'000'000;
};

class BoundaryControllerNode final : public Node {
public:
    BoundaryControllerNode(std::string node_name, BoundaryNodeConfig config, BoundarySerialLines serial = {});
    const std::string& name() const override { return name_; }
    void configure(DdsContext& dds) override;
    TimeNs step(TimeNs now_ns) override;
    bool has_unread_input() const override;

private:
    // Eq. 15-17 on a camera's frame (nullptr: none), the densities into the
    // logic, and its report. Returns whether any density changed.
    void process_frame(std::size_t camera, const msg::CameraFrame* frame, TimeNs now_ns);
    // Sec. 2.2.1 on a frame of the calibration window: the nozzle points
    // (Eq. 1-4) replace the camera's design points when the boards are found.
    void calibrate(std::size_t camera, const msg::CameraFrame& frame, TimeNs now_ns);
    void notice_calibration(std::size_t camera, const std::string& problem);
    // Densities older than vision.density_max_age_s are dropped (the camera
    // stopped); returns when the next one expires.
    TimeNs expire_densities(TimeNs now_ns);

    // The sweep's duty at now_ns and when it next changes.
    double sweep_duty_pct(TimeNs now_ns, TimeNs& next_change_ns) const;

    // Complete lines from a wired port (without their terminators), in arrival order.
    static std::vector<std::string> take_lines(SerialPort& port);

    std::string name_;
    BoundarySerialLines serial_;
    std::unique_ptr<SerialPort> nmea_port_;
    std::unique_ptr<SerialPort> laser_port_;
    DutySweepConfig sweep_;
    BoundaryController logic_;
    DutyCommandDelay commands_;  // what goes out on actuator/nozzle_pwm/duty, and when
    std::unique_ptr<Reader<msg::NmeaSentence>> nmea_reader_;
    std::unique_ptr<Reader<msg::SerialLine>> laser_reader_;
    std::unique_ptr<Writer<msg::NozzlePwm>> pwm_writer_;
    VisionNodeConfig vision_config_;
    std::vector<vision::CameraVision> cameras_;
    std::vector<std::unique_ptr<Reader<msg::CameraFrame>>> frame_readers_;
    std::unique_ptr<Writer<msg::VisionReport>> vision_writer_;
    std::vector<TimeNs> density_time_ns_;
    std::vector<bool> calibrated_;            // per camera: nozzle points found in a calibration frame
    std::vector<bool> calibration_noticed_;   // per camera: a refused calibration frame was told  // per nozzle, when its density was measured (-1: none)
};

}  // namespace rig::controller::boundary
