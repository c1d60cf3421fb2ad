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
// Positions in the route are those of the nozzle line; the vehicle starts at
// standstill with its nozzle line at `start_nozzle_line_along_m`. Driving
// backwards is not modelled: a drive must go forward (to_along_m >= where it
// starts); the vehicle always faces the line's heading.
#include <cstddef>
#include <variant>
#include <vector>

namespace rig::emulators {

// Antenna-to-nozzle geometry of the sprayer (seed 000 Fig. 5, Eq. 6):
// L1 antenna to four-bar linkage, L2 linkage length, L3 linkage to nozzles,
// linkage_rise_m the linkage's height change h. The defaults give the paper's
// 1.63 m at 0.5 m boom height. This is the plant's physical truth, computed here
// on purpose independently of the controller's Eq. 6 function, so that a case
// can give the controller a wrong belief about the boom.
struct BoomGeometry {
    double l1_m = 0.50;
    double l2_m = 0.80;
    double l3_m = 0.45;
    double linkage_rise_m = 0.50;
    // L4 = L1 + cos(atan(h / L2)) L2 + L3 (Eq. 6): antenna to nozzle line, along the heading.
    double l4_m() const;
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
    double speed_m_s = 0.0;            // >= 0 (forward only)
    double accel_m_s2 = 0.0;
    double odometer_distance_m = 0.0;  // ground distance driven since t = 0; never decreases
};

class VehiclePlant {
public:
    // Throws std::invalid_argument naming the phase (by index) for a negative or
    // non-finite duration, a non-positive cruise speed or acceleration, or a
    // drive that would go backwards.
    VehiclePlant(std::vector<RoutePhase> route, BoomGeometry boom, double start_nozzle_line_along_m = 0.0);

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
    // The first time t >= after_s, inside a drive phase, at which the nozzle line
    // is at along_m, solved exactly from the phase's kinematics; NaN if it never
    // is. A drive that starts or ends exactly at along_m counts (its start or end
    // time); standing at along_m does not.
    double time_when_nozzle_line_reaches(double along_m, double after_s = 0.0) const;

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

    BoomGeometry boom_;
    double l4_m_;
    double start_nozzle_line_along_m_;
    std::vector<Segment> segments_;
};

}  // namespace rig::emulators
