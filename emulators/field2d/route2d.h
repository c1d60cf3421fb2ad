#pragma once
// The sprayer's 2-D motion in the field's local east-north frame as a
// closed-form function of time (as emulators/vehicle_plant.h does in 1-D): no
// integrator and no state that advances, so state_at(t) is exact and the same
// for any t in any order of calls (lockstep runs jump in time).
//
// The route is driven by the vehicle's reference point, the centre of the rear
// axle: the one point of a car-like vehicle whose velocity is along its
// heading. Other body points (antenna, boom, nozzles) follow by rigid-body
// motion (emulators/field2d/sprayer_kinematics.h); in a turn their velocity has
// a sideways part, so the antenna's course over ground is not the heading.
//
// Segments, run in order from t = 0:
//   StraightSegment  a straight run of length_m;
//   TurnSegment      a constant-radius arc, angle_deg > 0 turning right
//                    (clockwise, the compass direction), < 0 turning left;
//   StandSegment     stand still for duration_s (the vehicle must be at rest).
// On a drive segment the speed moves from the speed the segment is entered
// with toward speed_m_s at accel_m_s2 (speeding up or slowing down), cruises,
// and with stop_at_end brakes at accel_m_s2 to stop exactly at the segment's
// end (a triangular profile when the segment is too short to reach speed_m_s).
// Speed and heading are continuous across segments (a turn's heading changes
// at a rate v / R, so the heading is continuous but the yaw rate jumps, as a
// path of lines and arcs has it). Driving backwards is not modelled.
#include <cstddef>
#include <variant>
#include <vector>

#include "emulators/field2d/vec2.h"

namespace rig::field2d {

struct StraightSegment {
    double length_m = 0.0;         // > 0
    double speed_m_s = 0.0;        // > 0; 3WP-280 max 1.5 m/s (seed 001 Table 2)
    double accel_m_s2 = 0.5;       // > 0; assumed, a self-propelled sprayer on soil
    bool stop_at_end = false;
};

struct TurnSegment {
    double radius_m = 0.0;         // > 0, of the rear-axle centre's path
    double angle_deg = 0.0;        // != 0; > 0 right (clockwise), < 0 left
    double speed_m_s = 0.0;        // > 0
    double accel_m_s2 = 0.5;       // > 0
    bool stop_at_end = false;
};

struct StandSegment {
    double duration_s = 0.0;       // >= 0
};

using RouteSegment = std::variant<StraightSegment, TurnSegment, StandSegment>;

struct RouteStart {
    Vec2 position;                 // rear-axle centre, local east/north
    double heading_deg = 0.0;      // 0 = north, clockwise
    double speed_m_s = 0.0;        // >= 0: speed at t = 0 (a run may start already moving)
};

struct VehiclePose2d {
    double time_s = 0.0;
    Vec2 position;                 // rear-axle centre
    double heading_deg = 0.0;      // [0, 360)
    double speed_m_s = 0.0;        // >= 0, along the heading
    double accel_m_s2 = 0.0;       // along the path
    double yaw_rate_deg_s = 0.0;   // > 0 turning right (clockwise)
    double distance_m = 0.0;       // path length since t = 0
    std::size_t segment = 0;       // the segment driven at time_s; segment_count() after the end
};

class Route2d {
public:
    // Throws std::invalid_argument naming the segment (by index) and the value:
    // non-positive or non-finite length, radius, speed or acceleration, a zero
    // turn angle, a negative stand, a stand entered while moving, a stop that
    // cannot be made within the segment from the speed it is entered with, or
    // a route that does not end at rest (give the last drive stop_at_end).
    Route2d(RouteStart start, std::vector<RouteSegment> segments);

    // Before t = 0 the state at t = 0; after end_time_s() the vehicle stands
    // where the route left it. time_s is the time asked for.
    VehiclePose2d state_at(double t_s) const;
    double end_time_s() const;
    double total_distance_m() const;
    std::size_t segment_count() const { return segments_.size(); }
    double segment_start_s(std::size_t segment) const;
    // The first time at which the path length driven reaches distance_m
    // (0 <= distance_m <= total_distance_m()), solved from the speed profile;
    // NaN outside that range.
    double time_at_distance(double distance_m) const;

private:
    // A stretch of constant acceleration within a segment.
    struct Piece {
        double start_s = 0.0;      // from the segment's start
        double duration_s = 0.0;
        double speed0_m_s = 0.0;
        double accel_m_s2 = 0.0;
        double distance0_m = 0.0;  // from the segment's start
    };
    struct Compiled {
        enum class Kind { straight, turn, stand } kind = Kind::stand;
        double start_s = 0.0;
        double duration_s = 0.0;
        double length_m = 0.0;
        double start_distance_m = 0.0;
        Vec2 start_position;
        double start_heading_deg = 0.0;
        double radius_m = 0.0;
        double turn_sign = 0.0;    // +1 right, -1 left
        std::vector<Piece> pieces;
    };
    struct Along {
        double distance_m = 0.0;   // within the segment
        double speed_m_s = 0.0;
        double accel_m_s2 = 0.0;
    };

    static std::vector<Piece> speed_profile(std::size_t index, double entry_speed_m_s, double length_m,
                                            double speed_m_s, double accel_m_s2, bool stop_at_end);
    static Along along(const Compiled& segment, double into_s);
    // Position and heading `distance_m` into a segment.
    static void place(const Compiled& segment, double distance_m, Vec2& position, double& heading_deg);

    RouteStart start_;
    std::vector<Compiled> segments_;
    Vec2 end_position_;
    double end_heading_deg_ = 0.0;
};

}  // namespace rig::field2d
