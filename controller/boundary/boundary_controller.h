#pragma once
// Seed 001's reference controller, positioning and boundary half (Sec. 3, 4.2),
// free of any wire, like controller/spray_controller.h: it is fed the serial
// lines it reads (GPRMC from the AD300, the L4 laser's distance) with the time
// they were read, and says the PWM duty of each nozzle. The DDS node and the
// bench wiring will drive this one class.
//
// On every valid RMC (Sec. 4.2.2):
//   1. project the antenna to UTM in the areas' zone (GeographicLib);
//   2. boom centre and nozzles by Eq. 18 (boom offset Y1 at the laser's boom
//      height H) and Eq. 19 (rotation by the course, which the paper takes
//      as the UTM bearing: grid convergence ignored unless configured);
//   3. the two shut-off rules: a nozzle outside every area is off
//      (environment 1); the boom centre outside every area turns all off
//      (environment 2);
//   4. the duty of each nozzle that may spray: Eq. 14's level for its area's
//      density D at the RMC speed (level 0 / 40 % / 100 %).
// Optional AgOpenGPS-style anticipation (config.lookahead_*): the inside tests
// of steps 3 use points ahead along the course instead of the points now.
// Safety (assumed, not in the paper): no course yet, an RMC with status V, or
// no valid RMC for fix_timeout_s: every nozzle off.
//
// Bad input (malformed NMEA or laser lines, a point UTM cannot project) is
// counted and reported as a notice, never thrown; bad configuration throws.
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "controller/boundary/boundary_config.h"
#include "controller/boundary/boundary_equations.h"
#include "controller/boundary/utm_area.h"
#include "rig/runtime/clock.h"

namespace rig::controller::boundary {

struct NozzleStatus {
    GridPoint position;        // at the last fix, UTM
    bool inside = false;       // the (look-ahead) inside test of rule 1 says spray
    int area = -1;             // the area whose density sets its level, -1 none
    int level = 0;             // Sec. 3.2.2: 0, 1, 2
    double duty_pct = 0.0;     // the output
};

struct BoundaryStatus {
    bool have_fix = false;     // a valid RMC within fix_timeout_s
    GridPoint antenna;         // UTM, last valid fix
    std::optional<double> course_deg;  // held course, true north clockwise
    double speed_m_s = 0.0;
    double convergence_deg = 0.0;      // at the last fix
    double boom_height_m = 0.0;        // what the controller believes (laser, else default)
    double boom_offset_m = 0.0;        // Eq. 18
    GridPoint boom_centre;
    bool centre_inside = false;        // rule 2 (look-ahead included)
    std::vector<NozzleStatus> nozzles;
    TimeNs last_fix_read_ns = 0;
    std::uint32_t rejected_sentences = 0;   // failed parsing / checksum / projection
    std::uint32_t rejected_laser_lines = 0; // malformed, device error or implausible height
};

class BoundaryController {
public:
    // Validates the configuration (std::invalid_argument "boundary.<key>: ...")
    // and projects the areas (an area that is not a simple polygon throws,
    // naming it).
    explicit BoundaryController(BoundaryControllerConfig config);

    void on_nmea_sentence(std::string_view line, TimeNs now_ns);
    void on_laser_line(std::string_view line, TimeNs now_ns);
    // The fix timeout; returns when it must run again without input (kNever
    // when nothing is pending).
    TimeNs update(TimeNs now_ns);

    // The vision half (Sec. 2, 4.1): from now on each nozzle's level comes
    // from the density set for it (Eq. 17 of its ROI), not its area's; a
    // nozzle without one (nullopt) sprays at blind_level (0, 1, 2).
    void enable_vision(int blind_level);
    void set_vision_density(int nozzle, std::optional<double> density);
    // Decide again with the last fix (a frame changed a density).
    void redecide() { decide(); }

    // Outputs: duty per nozzle, %, and the PWM frequency.
    const std::vector<double>& duty_pct() const { return duty_pct_; }
    double pwm_frequency_hz() const { return config_.pwm_frequency_hz; }
    const BoundaryStatus& status() const { return status_; }
    // Messages for the operator since the last call (at most 64 kept).
    std::vector<std::string> take_notices();

    const BoundaryControllerConfig& config() const { return config_; }
    const UtmProjection& projection() const { return projection_; }
    const std::vector<UtmArea>& areas() const { return areas_; }

private:
    void decide();
    void all_off();
    int area_of(GridPoint p) const;
    void notice(std::string text);

    BoundaryControllerConfig config_;
    UtmProjection projection_;
    std::vector<UtmArea> areas_;
    BoundaryStatus status_;
    std::vector<double> duty_pct_;
    std::vector<bool> nozzle_was_inside_;
    bool vision_ = false;
    int vision_blind_level_ = 2;
    std::vector<std::optional<double>> vision_density_;
    bool centre_was_inside_ = false;
    std::vector<std::string> notices_;
};

}  // namespace rig::controller::boundary
