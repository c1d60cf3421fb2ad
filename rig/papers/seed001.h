#pragma once
// Seed 001's numbers that the plant, the controller and the judge all take:
// the variable-rate sprayer of Yang et al. 2022 (../docs/seed001-boundary.md,
// seed001-vision.md). One home each, with its unit and where it comes from;
// none of the three owns them. A number only one of them uses lives with that
// one (emulators/, controller/boundary/boundary_config.h, harness/systems/boundary/).
namespace rig::papers::seed001 {

// The boom: six nozzles (Sec. 5.1, Table 3) 0.50 m apart (Table 1).
inline constexpr int kNozzleCount = 6;
inline constexpr double kNozzleSpacingM = 0.50;

// The PWM valves' frequency, Hz (Sec. 3.2.1).
inline constexpr double kPwmFrequencyHz = 9.0;

// Eq. 18's parallelogram lift, m: I, Hp, M and L. The paper gives none of
// them: assumed, so that a 0.5 m boom puts the nozzles 1.0 m behind the
// antenna (harness/systems/boundary/ and the controller believe the same).
inline constexpr double kLiftRodLengthM = 0.50;          // I
inline constexpr double kLiftHingeHeightM = 0.80;        // Hp
inline constexpr double kLiftAntennaToOM = 0.30;         // M
inline constexpr double kLiftHingeToBoomCentreM = 0.90;  // L

// Eq. 12-14: a nozzle's rate from the plant cover D it sees and the speed.
// Eq. 12's coefficient: 0.01138 L/m^2 (Eq. 9) x 60 s/min x 0.6 m, L/min per m/s.
inline constexpr double kEq12CoefficientLMinPerMS = 0.40968;
// Eq. 13's fit over Table 3 (30-80 % duty): flow = A duty + b, L/min.
inline constexpr double kEq13SlopeLMinPerPct = 0.00375;   // A
inline constexpr double kEq13InterceptLMin = 0.296;       // b
// Eq. 14's k: not given by the paper. 0.78 puts the paper's 40 % sparse /
// normal split on the level 1/2 boundary at 1.5 m/s: assumed, a fit of a kind.
inline constexpr double kEq14MaxCover = 0.78;
// Eq. 14's levels by s, %: level 0 (valve shut) up to level0_max, level 1 up
// to level1_max, level 2 above (Sec. 3.2.2). The paper prints -69 % for the
// first bound, but its own "15 % of full flow" gives -55 % by Eq. 13: -69 is
// a typo.
inline constexpr double kLevel0MaxPct = -55.0;
inline constexpr double kLevel1MaxPct = 5.0;
// The duty of level 1 and level 2, % (Sec. 3.2.2).
inline constexpr double kLevel1DutyPct = 40.0;
inline constexpr double kLevel2DutyPct = 100.0;

}  // namespace rig::papers::seed001
