#pragma once
// The sprayer on the A-B line as a closed-form function of time: no integrator
// and no state that advances, so state_at(t) is exact and the same for any t in
// any order of calls (lockstep runs jump in time; real-time runs sample at odd
// instants; both must see the same vehicle).
//
// A route is a list of phases, run in order from t = 0:
//   StandPhase{duration_s}           stand still where the vehicle is;
//   RepositionPhase{to_along_m}      jump there instantly: a headland turn or a
//                                    drive back to the start, which the rig does
//                                    not model (no time, no odometer distance);
//   DrivePhase{to_along_m, cruise_speed_m_s, accel_m_s2}
//                                    from standstill accelerate at accel_m_s2 to
//                                    the cruise speed, cruise, and brake at
//                                    accel_m_s2 to stop exactly at to_along_m
//                                    (a triangular profile when the distance is
//                                    too short to reach cruise speed).
// Positions in the route are those of the nozzle line with the boom at its
// initial height; the vehicle starts at standstill with its nozzle line at
// `start_nozzle_line_along_m`. Driving backwards is not modelled: a drive must
// go forward (to_along_m >= where it starts); the vehicle always faces the
// line's heading.
//
// The boom can move during the run (BoomLift: the electric push rod changes the
// four-bar linkage's rise h at a constant rate, piecewise linear in time, so h(t)
// is closed form like the route). It is the vehicle (the antenna) that follows
// the route: antenna(t) = route(t) + L4(h0), and the nozzle line sits L4(h(t))
// behind it, nozzle(t) = antenna(t) - L4(h(t)) (Eq. 6). Without lifts, or while
// h is back at h0, the nozzle line is the route position itself (bit for bit).
// Lifting (h up) swings the nozzles towards the antenna, lowering swings them
// back, relative to the antenna, at most 2 / (3 sqrt 3) = 0.385 x the push rod's
// rate (the largest |dL4/dh| of Eq. 6, at h = L2 / sqrt 2): lowered faster than
// that outruns the vehicle, the nozzle line moves backwards over the ground.
#include <cstddef>
#include <variant>
#include <vector>
#include "rig/papers/seed000.h"

namespace rig::emulators {

// Antenna-to-nozzle geometry of the sprayer (seed 000 Fig. 5, Eq. 6):
// L1 antenna to four-bar linkage, L2 linkage length, L3 linkage to nozzles,
// linkage_rise_m the linkage's height change h. The defaults give the paper's
// 1.63 m at 0.5 m boom height. This is the plant's physical truth, computed here
// on purpose independently of the controller's Eq. 6 function, so that a case
// can give the controller a wrong belief about the boom.
struct BoomGeometry {
    double l1_m = papers::seed000::kL1M;
    double l2_m = papers::seed000::kL2M;
    double l3_m = papers::seed000::kL3M;
    double linkage_rise_m = papers::seed000::kLinkageRiseM;
    // L4 = L1 + cos(atan(h / L2)) L2 + L3 (Eq. 6): antenna to nozzle line, along the heading.
    double l4_m() const;
};

// From at_s the push rod moves h towards to_m at rate_m_s and stops there. The
// lifts of a plant run in order: each starts when (or after) the previous one has
// arrived. h stays >= 0 (Eq. 6's L4 falls monotonically as h rises from 0).
struct BoomLift {
    double at_s = 0.0;      // when the push rod starts
    double to_m = 0.0;      // the linkage rise it moves to
    double rate_m_s = 0.0;  // the push rod's speed, > 0
};

struct StandPhase {
    double duration_s = 0.0;
};

struct RepositionPhase {
    double to_along_m = 0.0;  // nozzle line
};

struct DrivePhase {
    double to_along_m = 0.0;  // nozzle line, where the vehicle comes to rest
    double cruise_speed_m_s = 0.0;
    double accel_m_s2 = 0.5;  // both accelerating and braking
};

using RoutePhase = std::variant<StandPhase, RepositionPhase, DrivePhase>;

struct VehicleState {
    double time_s = 0.0;
    double antenna_along_m = 0.0;      // RTK-GNSS antenna on the cab roof
    double nozzle_line_along_m = 0.0;  // L4 behind the antenna
    double linkage_rise_m = 0.0;       // h of Eq. 6 at this instant
    double l4_m = 0.0;                 // antenna to nozzle line at this instant (Eq. 6 at h)
    double speed_m_s = 0.0;            // >= 0 (forward only)
    double accel_m_s2 = 0.0;
    double odometer_distance_m = 0.0;  // ground distance driven since t = 0; never decreases
};

class VehiclePlant {
public:
    // Throws std::invalid_argument naming the phase (by index) for a negative or
    // non-finite duration, a non-positive cruise speed or acceleration, or a
    // drive that would go backwards; naming the lift (by index) for a negative or
    // non-finite start, target or rate, or a lift that starts before the previous
    // one has arrived. The boom starts at boom.linkage_rise_m (>= 0 when it lifts).
    VehiclePlant(std::vector<RoutePhase> route, BoomGeometry boom, double start_nozzle_line_along_m = 0.0,
                 std::vector<BoomLift> lifts = {});

    // State at t_s. Before 0 the vehicle stands at the start; after end_time_s()
    // it stands where the route left it. At the instant of a reposition the new
    // position already holds.
    VehicleState state_at(double t_s) const;
    // When the last phase ends.
    double end_time_s() const;
    // Which pass the vehicle is on at t_s: 0 until the first reposition (headland
    // turn), then 1, and so on. Spray on the ground is booked per pass.
    int pass_index_at(double t_s) const;
    // Start time of pass `pass` (0 for the first), NaN if the route has no such pass.
    double pass_start_s(int pass) const;
    // The first time t >= after_s at which the nozzle line, moving, is at along_m;
    // NaN if it never is. Moving: inside a drive phase or while the boom moves. A
    // drive or boom move that starts or ends exactly at along_m counts (its start
    // or end time); standing still at along_m does not. With the boom still, it
    // is solved exactly from the phase's kinematics. While the boom moves it is
    // solved by bisection: lifting, the nozzle line only goes forward (monotone);
    // lowering, it can go back, so the move is first sampled every
    // kLoweringSampleS for a sign change, which misses a crossing only when the
    // nozzle line goes past along_m and back within one sample: by less than
    // 0.385 x rate x kLoweringSampleS (0.04 mm at 0.1 m/s).
    double time_when_nozzle_line_reaches(double along_m, double after_s = 0.0) const;
    static constexpr double kLoweringSampleS = 1e-3;
    // Bounds that keep that sampling finite (at most 10^7 samples per move): a
    // push rod slower than 1 mm/s is not moving; no linkage rises 10 m.
    static constexpr double kMinLiftRateMS = 1e-3;
    static constexpr double kMaxLinkageRiseM = 10.0;
    // h of Eq. 6 at t_s (closed form: the lifts are piecewise linear).
    double linkage_rise_m_at(double t_s) const;

    const BoomGeometry& boom() const { return boom_; }

private:
    // One phase with its start time, positions and, for drives, its speed profile.
    struct Segment {
        enum class Kind { stand, reposition, drive } kind = Kind::stand;
        double start_s = 0.0;
        double duration_s = 0.0;
        double start_along_m = 0.0;  // nozzle line
        double end_along_m = 0.0;
        double odometer_start_m = 0.0;
        // Drive profile: accelerate for ramp_s over ramp_m, cruise at peak speed
        // for cruise_s, brake for ramp_s over ramp_m.
        double accel_m_s2 = 0.0;
        double peak_speed_m_s = 0.0;
        double ramp_s = 0.0;
        double ramp_m = 0.0;
        double cruise_s = 0.0;
    };

    static Segment make_drive(const DrivePhase& drive, double start_s, double start_along_m);
    // Nozzle line position, speed and acceleration `into_s` seconds into a drive.
    struct Kinematics {
        double along_m = 0.0;
        double speed_m_s = 0.0;
        double accel_m_s2 = 0.0;
    };
    static Kinematics drive_kinematics(const Segment& drive, double into_s);
    // Seconds into a drive at which it has covered `covered_m` (0 <= covered_m <= length).
    static double drive_time_for(const Segment& drive, double covered_m);

    // One push-rod move: h goes linearly from from_m to to_m over [start_s, end_s].
    struct LiftSegment {
        double start_s = 0.0;
        double end_s = 0.0;
        double from_m = 0.0;
        double to_m = 0.0;
    };
    // Route position (nozzle line at h0) `t_s` into `segment`, which holds then.
    static double route_along_m(const Segment& segment, double t_s);
    // The nozzle line at t_s for the route position there (see the header's top).
    double nozzle_line_from_route_m(double route_along_m, double t_s) const;
    // The first root of nozzle - along_m in [from_s, to_s] inside `segment`, with the boom moving.
    double first_crossing_while_boom_moves(const Segment& segment, double along_m, double from_s, double to_s,
                                           bool lowering) const;

    BoomGeometry boom_;
    double l4_m_;  // at the initial h
    std::vector<LiftSegment> lift_segments_;
    double start_nozzle_line_along_m_;
    std::vector<Segment> segments_;
};

}  // namespace rig::emulators
