// The reference controller's breakpoint identification logic (no DDS): RTK-only
// and RTK + odometer fusion against hand-built fix and encoder sequences.
#include <gtest/gtest.h>

#include <cmath>

#include "controller/breakpoint_equations.h"
#include "controller/breakpoint_locator.h"
#include "emulators/field_frame.h"

namespace {

using rig::TimeNs;
using rig::controller::BreakpointLocator;
using rig::controller::EncoderReading;
using rig::controller::ControllerConfig;
using rig::controller::FixInput;
using rig::controller::LocatorEvent;
using rig::controller::Positioning;

// Field at the paper's site, A-B line due east; the breakpoint (nozzle line on the
// ground) at along 0.
struct Field {
    rig::emulators::FieldFrame frame{40.18, 116.44, 50.0, 90.0};
    rig::controller::StoredBreakpoint breakpoint() const {
        const auto p = frame.to_geodetic(0.0, 0.0);
        return {1, p.lat_deg, p.lon_deg, 90.0};
    }
    FixInput fix_at(double antenna_along_m) const {
        const auto p = frame.to_geodetic(antenna_along_m, 0.0);
        return FixInput{p.lat_deg, p.lon_deg, 90.0, 4};
    }
};

// An encoder read from a wire without capture times (the count at the read only).
EncoderReading read(std::uint32_t count) { return EncoderReading{count, std::nullopt}; }

ControllerConfig config_for(Positioning positioning) {
    ControllerConfig config;
    config.positioning = positioning;
    return config;  // L1 0.50, L2 0.80, L3 0.45, h 0.50 -> L4 = 1.628 m (Eq. 6)
}

TEST(BreakpointLocator, RtkOnlyFiresOnFirstFixWithNozzleLinePastTheBreakpoint) {
    const Field field;
    BreakpointLocator locator(config_for(Positioning::rtk_only));
    locator.set_target(field.breakpoint());
    const double l4_m = locator.l4_m();
    ASSERT_NEAR(l4_m, 1.628, 0.001);
    // 6 km/h, 5 Hz: fixes every 0.3333 m of antenna travel, nozzle line starting at -10 m.
    const double step_m = (6.0 / 3.6) * 0.2;
    int fired_at = -1;
    for (int i = 0; i < 60 && fired_at < 0; ++i) {
        const double nozzle_along_m = -10.0 + i * step_m;
        if (locator.on_fix(field.fix_at(nozzle_along_m + l4_m), std::nullopt, 6.0 / 3.6, 0) == LocatorEvent::reached) {
            fired_at = i;
        }
    }
    // First i with -10 + i*0.3333 >= 0 is i = 30 (exactly 0.0 m: allow the boundary
    // to fall either side by rounding in Eq. 4).
    ASSERT_TRUE(fired_at == 30 || fired_at == 31) << fired_at;
}

TEST(BreakpointLocator, FusionTakesMileageBaseInsideThresholdThenCountsPulses) {
    const Field field;
    ControllerConfig config = config_for(Positioning::fusion);
    BreakpointLocator locator(config);
    locator.set_target(field.breakpoint());
    const double l4_m = locator.l4_m();

    // Antenna 8 m ahead of the breakpoint: armed, outside the 5 m threshold.
    EXPECT_EQ(locator.on_fix(field.fix_at(-8.0), read(1000u), 1.0, 0), LocatorEvent::none);
    EXPECT_FALSE(locator.odometer_active());
    // Antenna 4.8 m before: s_b = 4.8, odometer takes over from count 5000.
    EXPECT_EQ(locator.on_fix(field.fix_at(-4.8), read(5000u), 1.0, 0), LocatorEvent::none);
    EXPECT_TRUE(locator.odometer_active());
    // Needs s_b + L4 of wheel, s_b being Eq. 4's S for that fix (on the sphere an
    // east-west 4.8 m reads 0.25 % short at 40.18 N): 1 m wheel, 1000 p/rev -> 3.14159 mm/pulse.
    const auto bp = field.breakpoint();
    const auto fix = field.fix_at(-4.8);
    const double s_b = rig::controller::haversine_distance_m(fix.lat_deg, fix.lon_deg, bp.lat_deg, bp.lon_deg);
    ASSERT_NEAR(s_b, 4.8, 0.02);
    const double per_pulse_m = M_PI * 1.0 / 1000.0;
    const auto pulses_needed = static_cast<std::uint32_t>(std::ceil((s_b + l4_m) / per_pulse_m));
    EXPECT_EQ(locator.on_encoder(read(5000u + pulses_needed - 1), 1.0, 0), LocatorEvent::none);
    EXPECT_EQ(locator.on_encoder(read(5000u + pulses_needed), 1.0, 0), LocatorEvent::reached);
    // Later fixes do not move the estimate once the odometer has taken over.
    EXPECT_EQ(locator.on_fix(field.fix_at(10.0), read(9000u), 1.0, 0), LocatorEvent::none);
}

TEST(BreakpointLocator, FusionSurvivesEncoderCounterWrap) {
    const Field field;
    BreakpointLocator locator(config_for(Positioning::fusion));
    locator.set_target(field.breakpoint());
    const std::uint32_t base = 0xffffff00u;
    locator.on_fix(field.fix_at(-8.0), read(base), 1.0, 0);
    locator.on_fix(field.fix_at(-4.0), read(base), 1.0, 0);
    ASSERT_TRUE(locator.odometer_active());
    const std::uint32_t wrapped = base + 10000u;  // wraps past 2^32
    ASSERT_LT(wrapped, base);
    EXPECT_EQ(locator.on_encoder(read(wrapped), 1.0, 0), LocatorEvent::reached);  // 31.4 m > 5.63 m
}

TEST(BreakpointLocator, DoesNotArmWhileStandingOnTheBreakpointJustStored) {
    const Field field;
    BreakpointLocator locator(config_for(Positioning::fusion));
    locator.set_target(field.breakpoint());
    // Standing with the nozzle line on the breakpoint (button just pressed), 1 cm noise.
    for (int i = 0; i < 10; ++i) {
        EXPECT_EQ(locator.on_fix(field.fix_at(locator.l4_m() + 0.01 * (i % 3 - 1)), read(100u), 0.0, 0), LocatorEvent::none);
    }
    EXPECT_FALSE(locator.odometer_active());
    // After the headland turn it approaches from 8 m: arms, and fires only after travelling.
    EXPECT_EQ(locator.on_fix(field.fix_at(-8.0 + locator.l4_m()), read(100u), 1.0, 0), LocatorEvent::none);
    EXPECT_EQ(locator.on_fix(field.fix_at(-4.0 + locator.l4_m()), read(200u), 1.0, 0), LocatorEvent::none);
    EXPECT_EQ(locator.on_encoder(read(201u), 1.0, 0), LocatorEvent::none);
}

TEST(BreakpointLocator, DoesNotFireForABreakpointAlreadyBehind) {
    const Field field;
    BreakpointLocator locator(config_for(Positioning::rtk_only));
    locator.set_target(field.breakpoint());
    // Starting with the nozzle line 3 m past the breakpoint: never armed.
    for (int i = 0; i < 20; ++i) {
        EXPECT_EQ(locator.on_fix(field.fix_at(3.0 + locator.l4_m() + i * 0.3), std::nullopt, 1.5, 0),
                  LocatorEvent::none);
    }
}

TEST(BreakpointLocator, IgnoresFixesBelowTheRequiredQuality) {
    const Field field;
    ControllerConfig config = config_for(Positioning::rtk_only);
    config.rtk_fixed_only = true;
    BreakpointLocator locator(config);
    locator.set_target(field.breakpoint());
    FixInput approaching = field.fix_at(-5.0);
    EXPECT_EQ(locator.on_fix(approaching, std::nullopt, 1.0, 0), LocatorEvent::none);
    FixInput float_fix = field.fix_at(2.0 + locator.l4_m());
    float_fix.quality = 5;
    EXPECT_EQ(locator.on_fix(float_fix, std::nullopt, 1.0, 0), LocatorEvent::none);
    EXPECT_EQ(locator.on_fix(field.fix_at(2.1 + locator.l4_m()), std::nullopt, 1.0, 0), LocatorEvent::reached);
}

// A sprayer at constant speed, the breakpoint at along 0, the encoder read on the
// rig's 10 ms grid, one fix inside the threshold at t = 0. Returns the nozzle
// line's position, relative to where the locator's own s_b + L4 put the
// breakpoint, at the instant it declared it reached (acting on reads, or on the
// compare instant when the reads carry capture times).
double declared_error_m(double start_offset_m, bool with_capture) {
    const Field field;
    ControllerConfig config = config_for(Positioning::fusion);
    BreakpointLocator locator(config);
    locator.set_target(field.breakpoint());
    const double speed_m_s = 6.0 / 3.6;
    const double pulse_m = M_PI * config.wheel_diameter_m / config.pulses_per_rev;
    constexpr TimeNs kReadPeriodNs = 10'000'000;
    // The wheel has rolled speed x t since t = 0, from start_offset_m of a pulse
    // (where in a pulse it starts); the count and the last edge follow.
    auto read_at = [&](TimeNs t) {
        const double rolled_m = start_offset_m + speed_m_s * rig::ns_to_seconds(t);
        const auto count = static_cast<std::uint32_t>(std::floor(rolled_m / pulse_m));
        EncoderReading reading{count, std::nullopt};
        if (with_capture) {
            // The capture timer's tick of the edge: floor(edge / 1 us), as the board's.
            const double edge_s = (count * pulse_m - start_offset_m) / speed_m_s;
            reading.last_edge_ns = static_cast<TimeNs>(std::floor(edge_s * 1e6)) * 1000;
        }
        return reading;
    };
    // Antenna 4.5 m before the breakpoint at t = 0: armed by an earlier fix, then the base.
    locator.on_fix(field.fix_at(-8.0), read_at(0), speed_m_s, 0);
    EXPECT_EQ(locator.on_fix(field.fix_at(-4.5), read_at(0), speed_m_s, 0), LocatorEvent::none);
    EXPECT_TRUE(locator.odometer_active());
    const double to_go_at_base_m = *locator.nozzle_to_breakpoint_m();
    for (TimeNs t = kReadPeriodNs; t < 10 * 1'000'000'000LL; t += kReadPeriodNs) {
        // Between the previous read and this one the compare may fire.
        const TimeNs compare_ns = locator.next_compare_ns();
        if (compare_ns < t && locator.on_time(compare_ns) == LocatorEvent::reached) {
            return speed_m_s * rig::ns_to_seconds(compare_ns) - to_go_at_base_m;
        }
        if (locator.on_encoder(read_at(t), speed_m_s, t) == LocatorEvent::reached) {
            return speed_m_s * rig::ns_to_seconds(t) - to_go_at_base_m;
        }
    }
    ADD_FAILURE() << "never reached";
    return 0.0;
}

TEST(BreakpointLocator, WithCaptureTimesTheErrorIsNotQuantisedByTheReadGrid) {
    const double step_m = 6.0 / 3.6 * 0.010;  // v x read period, 1.67 cm
    double worst_on_reads_m = 0.0;
    for (int phase = 0; phase < 20; ++phase) {
        const double start_offset_m = phase * 0.00015;  // 0 - 2.9 mm: under a pulse (3.14 mm)
        const double on_reads_m = declared_error_m(start_offset_m, false);
        // Acting on reads: late by up to a read period, plus up to a pulse of count truncation.
        EXPECT_GE(on_reads_m, -1e-9) << phase;
        EXPECT_LE(on_reads_m, step_m + 0.0032) << phase;
        worst_on_reads_m = std::max(worst_on_reads_m, on_reads_m);
        // With the last edge's capture time: at the breakpoint to the timer's
        // microsecond (1.7 um at this speed) plus float rounding.
        const double with_capture_m = declared_error_m(start_offset_m, true);
        EXPECT_NEAR(with_capture_m, 0.0, 1e-5) << phase;
    }
    // The grid's quantisation is real without them (the test can fail).
    EXPECT_GT(worst_on_reads_m, 0.25 * step_m);
}

TEST(BreakpointLocator, CaptureTimeCarriesTheBaseToTheFixInstant) {
    // The fix completes 7 ms after the last read: the base is where the wheel is
    // then, so the distance still to go right after the base is s_b + L4 and the
    // prediction counts the 7 ms of travel already done.
    const Field field;
    BreakpointLocator locator(config_for(Positioning::fusion));
    locator.set_target(field.breakpoint());
    const double speed_m_s = 2.0;
    locator.on_fix(field.fix_at(-8.0), EncoderReading{100u, 0}, speed_m_s, 0);
    locator.on_fix(field.fix_at(-4.0), EncoderReading{100u, 0}, speed_m_s, 7'000'000);
    ASSERT_TRUE(locator.odometer_active());
    const double to_go_m = *locator.nozzle_to_breakpoint_m();
    // Read again at the fix instant: unchanged; 0.1 s later: 0.2 m less.
    EXPECT_NEAR(*locator.nozzle_to_breakpoint_m_at(7'000'000), to_go_m, 1e-12);
    EXPECT_NEAR(*locator.nozzle_to_breakpoint_m_at(107'000'000), to_go_m - 0.2, 1e-9);
    // Beyond the speed window (0.2 s) after the last edge nothing more is extrapolated.
    EXPECT_NEAR(*locator.nozzle_to_breakpoint_m_at(900'000'000), to_go_m - 2.0 * (0.2 - 0.007), 1e-9);
    // 4 + L4 m at 2 m/s is 2.8 s away, beyond the 0.2 s the speed is trusted for: no compare yet.
    EXPECT_EQ(locator.next_compare_ns(), rig::kNever);
    // 0.1 s before the breakpoint (an edge just read), the compare is set at it.
    const std::uint32_t near_count = 100u + static_cast<std::uint32_t>(std::floor((to_go_m - 0.2) / (M_PI / 1000.0)));
    const TimeNs read_ns = 3'000'000'000LL;
    EXPECT_EQ(locator.on_encoder(EncoderReading{near_count, read_ns}, speed_m_s, read_ns), LocatorEvent::none);
    const double left_m = *locator.nozzle_to_breakpoint_m();
    ASSERT_GT(left_m, 0.0);
    EXPECT_NEAR(static_cast<double>(locator.next_compare_ns() - read_ns), left_m / speed_m_s * 1e9, 1.0);
    EXPECT_EQ(locator.on_time(locator.next_compare_ns() - 1), LocatorEvent::none);
    EXPECT_EQ(locator.on_time(locator.next_compare_ns()), LocatorEvent::reached);
    EXPECT_EQ(locator.next_compare_ns(), rig::kNever);  // fired once
}

}  // namespace
