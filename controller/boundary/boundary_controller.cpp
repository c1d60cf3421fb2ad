#include "controller/boundary/boundary_controller.h"

#include <cmath>
#include <stdexcept>
#include <utility>
#include <variant>

#include <GeographicLib/Math.hpp>

#include "controller/boundary/l4_laser_parser.h"
#include "rig/nmea/nmea_parser.h"

namespace rig::controller::boundary {
namespace {

constexpr std::size_t kMaxNotices = 64;

UtmProjection checked_projection(const BoundaryControllerConfig& config) {
    validate(config);
    return UtmProjection(config.areas);
}

}  // namespace

BoundaryController::BoundaryController(BoundaryControllerConfig config)
    : config_(std::move(config)), projection_(checked_projection(config_)) {
    for (const TargetAreaConfig& area : config_.areas) areas_.push_back(UtmArea::project(area, projection_));
    const auto n = static_cast<std::size_t>(config_.nozzle_count);
    duty_pct_.assign(n, 0.0);
    nozzle_was_inside_.assign(n, false);
    status_.nozzles.assign(n, NozzleStatus{});
    status_.boom_height_m = config_.default_boom_height_m;
    status_.boom_offset_m = eq18_boom_offset_m(config_, status_.boom_height_m);
}

void BoundaryController::notice(std::string text) {
    if (notices_.size() < kMaxNotices) notices_.push_back(std::move(text));
}

std::vector<std::string> BoundaryController::take_notices() { return std::exchange(notices_, {}); }

int BoundaryController::area_of(GridPoint p) const {
    for (std::size_t i = 0; i < areas_.size(); ++i) {
        if (areas_[i].contains(p)) return static_cast<int>(i);
    }
    return -1;
}

void BoundaryController::all_off() {
    for (std::size_t i = 0; i < duty_pct_.size(); ++i) {
        duty_pct_[i] = 0.0;
        status_.nozzles[i].duty_pct = 0.0;
        status_.nozzles[i].level = 0;
        status_.nozzles[i].inside = false;
        nozzle_was_inside_[i] = false;
    }
    status_.centre_inside = false;
    centre_was_inside_ = false;
}

void BoundaryController::on_nmea_sentence(std::string_view line, TimeNs now_ns) {
    const nmea::ParseResult parsed = nmea::parse_sentence(line);
    if (!parsed.ok()) {
        ++status_.rejected_sentences;
        notice("NMEA rejected (" + std::string(nmea::to_string(parsed.error->code)) + "): " + parsed.error->message);
        return;
    }
    const auto* rmc = std::get_if<nmea::RmcData>(&parsed.sentence->data);
    if (rmc == nullptr) return;  // the paper's controller reads RMC only
    if (rmc->status != nmea::DataStatus::valid || !rmc->position) {
        // The receiver says it has no solution: nowhere to spray.
        status_.have_fix = false;
        all_off();
        return;
    }
    double convergence_deg = 0.0;
    GridPoint antenna;
    try {
        antenna = projection_.forward(rmc->position->lat_deg, rmc->position->lon_deg, convergence_deg);
    } catch (const std::invalid_argument& error) {
        ++status_.rejected_sentences;
        notice(std::string("RMC position rejected: ") + error.what());
        return;
    }
    status_.antenna = antenna;
    status_.convergence_deg = convergence_deg;
    status_.speed_m_s = rmc->speed_m_s.value_or(0.0);
    // Course over ground is noise when nearly still (and often empty): hold the last.
    if (rmc->course_true_deg && status_.speed_m_s >= config_.course_hold_speed_m_s) {
        status_.course_deg = *rmc->course_true_deg;
    }
    status_.have_fix = true;
    status_.last_fix_read_ns = now_ns;
    decide();
}

void BoundaryController::on_laser_line(std::string_view line, TimeNs /*now_ns*/) {
    const L4Reading reading = parse_l4_line(line);
    if (!reading.ok()) {
        ++status_.rejected_laser_lines;
        if (reading.device_error) {
            notice("laser reports error E=" + std::to_string(*reading.device_error) + "; boom height held");
        } else {
            notice("laser line rejected: " + reading.error.value_or("?"));
        }
        return;
    }
    // TEST-ONLY fault: a controller that never uses the laser.
    if (config_.faults.ignore_boom_height) return;
    const double h_m = *reading.distance_m - config_.laser_mount_offset_m;
    const double lo = config_.lift_hinge_height_m - config_.lift_rod_length_m;
    const double hi = config_.lift_hinge_height_m + config_.lift_rod_length_m;
    if (!(h_m >= lo && h_m <= hi)) {
        // The lift cannot be there (e.g. the beam hit the crop or a furrow): keep the last height.
        ++status_.rejected_laser_lines;
        notice("laser boom height " + std::to_string(h_m) + " m outside the lift's reach; held");
        return;
    }
    status_.boom_height_m = h_m;
    status_.boom_offset_m = eq18_boom_offset_m(config_, h_m);
}

TimeNs BoundaryController::update(TimeNs now_ns) {
    if (!status_.have_fix) return kNever;
    const TimeNs deadline = status_.last_fix_read_ns + seconds_to_ns(config_.fix_timeout_s);
    if (now_ns >= deadline) {
        status_.have_fix = false;
        all_off();
        notice("no valid RMC for " + std::to_string(config_.fix_timeout_s) + " s: all nozzles off");
        return kNever;
    }
    return deadline;
}

void BoundaryController::enable_vision(int blind_level) {
    if (blind_level < 0 || blind_level > 2) {
        throw std::invalid_argument("vision.blind_level: must be 0, 1 or 2, got " + std::to_string(blind_level));
    }
    vision_ = true;
    vision_blind_level_ = blind_level;
    vision_density_.assign(static_cast<std::size_t>(config_.nozzle_count), std::nullopt);
}

void BoundaryController::set_vision_density(int nozzle, std::optional<double> density) {
    if (!vision_) throw std::logic_error("set_vision_density before enable_vision");
    if (nozzle < 0 || nozzle >= config_.nozzle_count) {
        throw std::invalid_argument("vision density for nozzle " + std::to_string(nozzle) + ": the boom has " +
                                    std::to_string(config_.nozzle_count));
    }
    vision_density_[static_cast<std::size_t>(nozzle)] = density;
}

void BoundaryController::decide() {
    if (!status_.have_fix || !status_.course_deg) {
        all_off();
        return;
    }
    const BoundaryControllerFaults& faults = config_.faults;  // TEST-ONLY, all off in the reference
    const double bearing_deg =
        faults.no_course_rotation
            ? 0.0
            : *status_.course_deg - (config_.correct_grid_convergence ? status_.convergence_deg : 0.0);
    double sin_b = 0.0;
    double cos_b = 1.0;
    GeographicLib::Math::sincosd(bearing_deg, sin_b, cos_b);
    const double v = status_.speed_m_s;
    const double y1 = status_.boom_offset_m + faults.antenna_offset_error_m;
    const double lookahead_sign = faults.lookahead_sign_flipped ? -1.0 : 1.0;
    // A body point (x right, Y1 forward) tau seconds ahead, straight on along the course.
    const auto point = [&](double x_m, double tau_s) {
        const GridPoint ahead{status_.antenna.x_m + v * tau_s * sin_b, status_.antenna.y_m + v * tau_s * cos_b};
        return eq19_body_to_grid(ahead, bearing_deg, x_m, y1);
    };
    // Inside test of a body point with optional anticipation; `area` gets the
    // area whose density applies (the one it is in now, else the one ahead).
    const auto inside = [&](double x_m, bool was_inside, int& area) {
        const int now_area = area_of(point(x_m, 0.0));
        if (!config_.lookahead_enabled) {
            area = now_area;
            return now_area >= 0;
        }
        int ahead = area_of(point(x_m, lookahead_sign * config_.lookahead_on_s));
        if (ahead < 0 && was_inside) ahead = area_of(point(x_m, lookahead_sign * config_.lookahead_off_s));
        area = now_area >= 0 ? now_area : ahead;
        return ahead >= 0;
    };

    const double centre_x = config_.boom_centre_right_of_antenna_m;
    status_.boom_centre = point(centre_x, 0.0);
    int centre_area = -1;
    status_.centre_inside = inside(centre_x, centre_was_inside_, centre_area);
    centre_was_inside_ = status_.centre_inside;

    for (int i = 0; i < config_.nozzle_count; ++i) {
        const auto idx = static_cast<std::size_t>(i);
        const double x = centre_x + (i - 0.5 * (config_.nozzle_count - 1)) * config_.nozzle_spacing_m;
        NozzleStatus& nozzle = status_.nozzles[idx];
        nozzle.position = point(x, 0.0);
        nozzle.inside = inside(x, nozzle_was_inside_[idx], nozzle.area);
        nozzle_was_inside_[idx] = nozzle.inside;
        nozzle.level = 0;
        // Sec. 4.2: a nozzle sprays only while it and the boom centre are both inside.
        const bool centre_allows = status_.centre_inside || faults.ignore_centre_rule;
        if (centre_allows && nozzle.inside && nozzle.area >= 0) {
            if (vision_) {
                const std::optional<double>& seen = vision_density_[idx];
                nozzle.level = seen ? spray_level(config_, eq14_theoretical_duty_pct(config_, *seen, v)) : vision_blind_level_;
            } else {
                const double density = areas_[static_cast<std::size_t>(nozzle.area)].density();
                nozzle.level = spray_level(config_, eq14_theoretical_duty_pct(config_, density, v));
            }
        }
        nozzle.duty_pct = level_duty_pct(config_, nozzle.level);
        duty_pct_[idx] = nozzle.duty_pct;
    }
}

}  // namespace rig::controller::boundary
