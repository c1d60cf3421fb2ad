#include "emulators/field2d/route2d.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace rig::field2d {
namespace {

constexpr double kRadPerDeg = M_PI / 180.0;

std::string where(std::size_t index) { return "route segment " + std::to_string(index) + ": "; }

void require_positive(std::size_t index, const char* what, double value) {
    if (!std::isfinite(value) || value <= 0.0) {
        throw std::invalid_argument(where(index) + what + " must be finite and > 0, got " + std::to_string(value));
    }
}

}  // namespace

std::vector<Route2d::Piece> Route2d::speed_profile(std::size_t index, double entry_speed_m_s, double length_m,
                                                   double speed_m_s, double accel_m_s2, bool stop_at_end) {
    std::vector<Piece> pieces;
    double t = 0.0;
    double s = 0.0;
    const auto add = [&](double duration_s, double v0, double a) {
        if (!(duration_s > 0.0)) return;
        pieces.push_back(Piece{t, duration_s, v0, a, s});
        t += duration_s;
        s += v0 * duration_s + 0.5 * a * duration_s * duration_s;
    };
    const double v_in = entry_speed_m_s;
    const double v = speed_m_s;
    const double a = accel_m_s2;
    if (!stop_at_end) {
        const double ramp_m = std::abs(v * v - v_in * v_in) / (2.0 * a);
        const double sign = v >= v_in ? 1.0 : -1.0;
        if (ramp_m >= length_m) {
            // The whole segment is a ramp that does not reach the target speed.
            const double v_out = std::sqrt(std::max(0.0, v_in * v_in + sign * 2.0 * a * length_m));
            add((v_out - v_in) / (sign * a), v_in, sign * a);
        } else {
            add(std::abs(v - v_in) / a, v_in, sign * a);
            add((length_m - ramp_m) / v, v, 0.0);
        }
        return pieces;
    }
    const double stopping_m = v_in * v_in / (2.0 * a);
    if (stopping_m > length_m * (1.0 + 1e-12)) {
        throw std::invalid_argument(where(index) + "cannot stop within " + std::to_string(length_m) + " m from " +
                                    std::to_string(v_in) + " m/s at " + std::to_string(a) + " m/s^2 (needs " +
                                    std::to_string(stopping_m) + " m)");
    }
    if (v >= v_in) {
        const double up_m = (v * v - v_in * v_in) / (2.0 * a);
        const double down_m = v * v / (2.0 * a);
        if (up_m + down_m <= length_m) {
            add((v - v_in) / a, v_in, a);
            add((length_m - up_m - down_m) / v, v, 0.0);
            add(v / a, v, -a);
        } else {
            // Triangular: the peak where speeding up and braking meet.
            const double peak = std::sqrt((2.0 * a * length_m + v_in * v_in) / 2.0);
            add((peak - v_in) / a, v_in, a);
            add(peak / a, peak, -a);
        }
    } else {
        const double slow_m = (v_in * v_in - v * v) / (2.0 * a);
        const double down_m = v * v / (2.0 * a);
        add((v_in - v) / a, v_in, -a);
        add(std::max(0.0, length_m - slow_m - down_m) / v, v, 0.0);
        add(v / a, v, -a);
    }
    return pieces;
}

Route2d::Route2d(RouteStart start, std::vector<RouteSegment> segments) : start_(start) {
    if (!std::isfinite(start.position.east_m) || !std::isfinite(start.position.north_m) ||
        !std::isfinite(start.heading_deg)) {
        throw std::invalid_argument("route start: position and heading must be finite");
    }
    if (!std::isfinite(start.speed_m_s) || start.speed_m_s < 0.0) {
        throw std::invalid_argument("route start: speed_m_s must be finite and >= 0, got " +
                                    std::to_string(start.speed_m_s));
    }
    double t = 0.0;
    double distance = 0.0;
    double speed = start.speed_m_s;
    Vec2 position = start.position;
    double heading = heading_0_360_deg(start.heading_deg);
    for (std::size_t i = 0; i < segments.size(); ++i) {
        Compiled c;
        c.start_s = t;
        c.start_distance_m = distance;
        c.start_position = position;
        c.start_heading_deg = heading;
        if (const auto* stand = std::get_if<StandSegment>(&segments[i])) {
            if (!std::isfinite(stand->duration_s) || stand->duration_s < 0.0) {
                throw std::invalid_argument(where(i) + "stand duration_s must be finite and >= 0, got " +
                                            std::to_string(stand->duration_s));
            }
            if (speed != 0.0) {
                throw std::invalid_argument(where(i) + "a stand needs the vehicle at rest, it arrives at " +
                                            std::to_string(speed) + " m/s (give the drive before it stop_at_end)");
            }
            c.kind = Compiled::Kind::stand;
            c.duration_s = stand->duration_s;
        } else {
            double v = 0.0;
            double a = 0.0;
            bool stop = false;
            if (const auto* straight = std::get_if<StraightSegment>(&segments[i])) {
                require_positive(i, "length_m", straight->length_m);
                c.kind = Compiled::Kind::straight;
                c.length_m = straight->length_m;
                v = straight->speed_m_s;
                a = straight->accel_m_s2;
                stop = straight->stop_at_end;
            } else {
                const auto& turn = std::get<TurnSegment>(segments[i]);
                require_positive(i, "radius_m", turn.radius_m);
                if (!std::isfinite(turn.angle_deg) || turn.angle_deg == 0.0) {
                    throw std::invalid_argument(where(i) + "turn angle_deg must be finite and != 0, got " +
                                                std::to_string(turn.angle_deg));
                }
                c.kind = Compiled::Kind::turn;
                c.radius_m = turn.radius_m;
                c.turn_sign = turn.angle_deg > 0.0 ? 1.0 : -1.0;
                c.length_m = turn.radius_m * std::abs(turn.angle_deg) * kRadPerDeg;
                v = turn.speed_m_s;
                a = turn.accel_m_s2;
                stop = turn.stop_at_end;
            }
            require_positive(i, "speed_m_s", v);
            require_positive(i, "accel_m_s2", a);
            c.pieces = speed_profile(i, speed, c.length_m, v, a, stop);
            c.duration_s = 0.0;
            for (const Piece& piece : c.pieces) c.duration_s = piece.start_s + piece.duration_s;
            if (c.pieces.empty()) {
                throw std::invalid_argument(where(i) + "a drive of zero duration");
            }
            const Piece& last = c.pieces.back();
            speed = stop ? 0.0 : last.speed0_m_s + last.accel_m_s2 * last.duration_s;
            place(c, c.length_m, position, heading);
            distance += c.length_m;
        }
        t += c.duration_s;
        segments_.push_back(std::move(c));
    }
    if (speed != 0.0) {
        throw std::invalid_argument("route: must end at rest, the last segment leaves the vehicle at " +
                                    std::to_string(speed) + " m/s (give the last drive stop_at_end)");
    }
    end_position_ = position;
    end_heading_deg_ = heading;
}

void Route2d::place(const Compiled& segment, double distance_m, Vec2& position, double& heading_deg) {
    const double h0 = segment.start_heading_deg;
    if (segment.kind != Compiled::Kind::turn) {
        position = segment.start_position + distance_m * forward_of(h0);
        heading_deg = h0;
        return;
    }
    // Centre of the arc to the right (right turn) or left of the start; the
    // point is R from it, perpendicular to the current heading.
    const double sign = segment.turn_sign;
    const double radius = segment.radius_m;
    const Vec2 centre = segment.start_position + (sign * radius) * right_of(h0);
    const double h = h0 + sign * (distance_m / radius) / kRadPerDeg;
    position = centre - (sign * radius) * right_of(h);
    heading_deg = heading_0_360_deg(h);
}

Route2d::Along Route2d::along(const Compiled& segment, double into_s) {
    if (segment.pieces.empty()) return {};
    // The last piece that has started by into_s.
    auto piece = std::upper_bound(segment.pieces.begin(), segment.pieces.end(), into_s,
                                  [](double t, const Piece& p) { return t < p.start_s; });
    if (piece != segment.pieces.begin()) --piece;
    const double tau = std::clamp(into_s - piece->start_s, 0.0, piece->duration_s);
    Along result;
    result.distance_m = std::min(segment.length_m, piece->distance0_m + piece->speed0_m_s * tau +
                                                       0.5 * piece->accel_m_s2 * tau * tau);
    result.speed_m_s = std::max(0.0, piece->speed0_m_s + piece->accel_m_s2 * tau);
    result.accel_m_s2 = piece->accel_m_s2;
    return result;
}

VehiclePose2d Route2d::state_at(double t_s) const {
    VehiclePose2d pose;
    pose.time_s = t_s;
    const double t = std::max(0.0, t_s);
    const double end_s = end_time_s();
    if (segments_.empty() || t >= end_s) {
        pose.position = segments_.empty() ? start_.position : end_position_;
        pose.heading_deg = segments_.empty() ? heading_0_360_deg(start_.heading_deg) : end_heading_deg_;
        pose.speed_m_s = 0.0;
        pose.distance_m = total_distance_m();
        pose.segment = segments_.size();
        return pose;
    }
    // The last segment that has started by t (zero-length stands are skipped over).
    auto it = std::upper_bound(segments_.begin(), segments_.end(), t,
                               [](double time, const Compiled& c) { return time < c.start_s; });
    --it;
    while (it != segments_.begin() && it->duration_s <= 0.0) --it;
    const Compiled& segment = *it;
    pose.segment = static_cast<std::size_t>(it - segments_.begin());
    if (segment.kind == Compiled::Kind::stand) {
        pose.position = segment.start_position;
        pose.heading_deg = segment.start_heading_deg;
        pose.distance_m = segment.start_distance_m;
        return pose;
    }
    const Along a = along(segment, t - segment.start_s);
    place(segment, a.distance_m, pose.position, pose.heading_deg);
    pose.speed_m_s = a.speed_m_s;
    pose.accel_m_s2 = a.accel_m_s2;
    pose.distance_m = segment.start_distance_m + a.distance_m;
    if (segment.kind == Compiled::Kind::turn) {
        pose.yaw_rate_deg_s = segment.turn_sign * a.speed_m_s / segment.radius_m / kRadPerDeg;
    }
    return pose;
}

double Route2d::end_time_s() const {
    if (segments_.empty()) return 0.0;
    return segments_.back().start_s + segments_.back().duration_s;
}

double Route2d::total_distance_m() const {
    if (segments_.empty()) return 0.0;
    return segments_.back().start_distance_m + segments_.back().length_m;
}

double Route2d::segment_start_s(std::size_t segment) const {
    if (segment >= segments_.size()) {
        throw std::out_of_range("route: no segment " + std::to_string(segment) + " (" +
                                std::to_string(segments_.size()) + " segments)");
    }
    return segments_[segment].start_s;
}

double Route2d::time_at_distance(double distance_m) const {
    if (!(distance_m >= 0.0) || distance_m > total_distance_m()) return std::numeric_limits<double>::quiet_NaN();
    if (distance_m == 0.0) return 0.0;
    for (const Compiled& segment : segments_) {
        if (segment.kind == Compiled::Kind::stand) continue;
        const double into_m = distance_m - segment.start_distance_m;
        if (into_m > segment.length_m) continue;
        for (const Piece& piece : segment.pieces) {
            const double v0 = piece.speed0_m_s;
            const double a = piece.accel_m_s2;
            const double end_m = piece.distance0_m + v0 * piece.duration_s + 0.5 * a * piece.duration_s * piece.duration_s;
            if (into_m > end_m && &piece != &segment.pieces.back()) continue;
            const double d = std::max(0.0, into_m - piece.distance0_m);
            double tau = 0.0;
            if (d == 0.0) {
                tau = 0.0;
            } else if (a == 0.0) {
                tau = d / v0;
            } else {
                // d = v0 tau + a tau^2 / 2, the smaller positive root, in the
                // form that does not cancel when a is small.
                const double disc = std::max(0.0, v0 * v0 + 2.0 * a * d);
                tau = 2.0 * d / (v0 + std::sqrt(disc));
            }
            return segment.start_s + piece.start_s + std::min(tau, piece.duration_s);
        }
    }
    return end_time_s();
}

}  // namespace rig::field2d
