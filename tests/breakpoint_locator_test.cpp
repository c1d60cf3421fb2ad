// The reference controller's breakpoint identification logic (no DDS): RTK-only
// and RTK + odometer fusion against hand-built fix and encoder sequences.
#include <gtest/gtest.h>

#include <cmath>

#include "controller/breakpoint_equations.h"
#include "controller/breakpoint_locator.h"
#include "emulators/field_frame.h"

namespace {

using rig::controller::BreakpointLocator;
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
        if (locator.on_fix(field.fix_at(nozzle_along_m + l4_m), std::nullopt, 6.0 / 3.6) == LocatorEvent::reached) {
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
    EXPECT_EQ(locator.on_fix(field.fix_at(-8.0), 1000u, 1.0), LocatorEvent::none);
    EXPECT_FALSE(locator.odometer_active());
    // Antenna 4.8 m before: s_b = 4.8, odometer takes over from count 5000.
    EXPECT_EQ(locator.on_fix(field.fix_at(-4.8), 5000u, 1.0), LocatorEvent::none);
    EXPECT_TRUE(locator.odometer_active());
    // Needs s_b + L4 of wheel, s_b being Eq. 4's S for that fix (on the sphere an
    // east-west 4.8 m reads 0.25 % short at 40.18 N): 1 m wheel, 1000 p/rev -> 3.14159 mm/pulse.
    const auto bp = field.breakpoint();
    const auto fix = field.fix_at(-4.8);
    const double s_b = rig::controller::haversine_distance_m(fix.lat_deg, fix.lon_deg, bp.lat_deg, bp.lon_deg);
    ASSERT_NEAR(s_b, 4.8, 0.02);
    const double per_pulse_m = M_PI * 1.0 / 1000.0;
    const auto pulses_needed = static_cast<std::uint32_t>(std::ceil((s_b + l4_m) / per_pulse_m));
    EXPECT_EQ(locator.on_encoder(5000u + pulses_needed - 1), LocatorEvent::none);
    EXPECT_EQ(locator.on_encoder(5000u + pulses_needed), LocatorEvent::reached);
    // Later fixes do not move the estimate once the odometer has taken over.
    EXPECT_EQ(locator.on_fix(field.fix_at(10.0), 9000u, 1.0), LocatorEvent::none);
}

TEST(BreakpointLocator, FusionSurvivesEncoderCounterWrap) {
    const Field field;
    BreakpointLocator locator(config_for(Positioning::fusion));
    locator.set_target(field.breakpoint());
    const std::uint32_t base = 0xffffff00u;
    locator.on_fix(field.fix_at(-8.0), base, 1.0);
    locator.on_fix(field.fix_at(-4.0), base, 1.0);
    ASSERT_TRUE(locator.odometer_active());
    const std::uint32_t wrapped = base + 10000u;  // wraps past 2^32
    ASSERT_LT(wrapped, base);
    EXPECT_EQ(locator.on_encoder(wrapped), LocatorEvent::reached);  // 31.4 m > 5.63 m
}

TEST(BreakpointLocator, DoesNotArmWhileStandingOnTheBreakpointJustStored) {
    const Field field;
    BreakpointLocator locator(config_for(Positioning::fusion));
    locator.set_target(field.breakpoint());
    // Standing with the nozzle line on the breakpoint (button just pressed), 1 cm noise.
    for (int i = 0; i < 10; ++i) {
        EXPECT_EQ(locator.on_fix(field.fix_at(locator.l4_m() + 0.01 * (i % 3 - 1)), 100u, 0.0), LocatorEvent::none);
    }
    EXPECT_FALSE(locator.odometer_active());
    // After the headland turn it approaches from 8 m: arms, and fires only after travelling.
    EXPECT_EQ(locator.on_fix(field.fix_at(-8.0 + locator.l4_m()), 100u, 1.0), LocatorEvent::none);
    EXPECT_EQ(locator.on_fix(field.fix_at(-4.0 + locator.l4_m()), 200u, 1.0), LocatorEvent::none);
    EXPECT_EQ(locator.on_encoder(201u), LocatorEvent::none);
}

TEST(BreakpointLocator, DoesNotFireForABreakpointAlreadyBehind) {
    const Field field;
    BreakpointLocator locator(config_for(Positioning::rtk_only));
    locator.set_target(field.breakpoint());
    // Starting with the nozzle line 3 m past the breakpoint: never armed.
    for (int i = 0; i < 20; ++i) {
        EXPECT_EQ(locator.on_fix(field.fix_at(3.0 + locator.l4_m() + i * 0.3), std::nullopt, 1.5),
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
    EXPECT_EQ(locator.on_fix(approaching, std::nullopt, 1.0), LocatorEvent::none);
    FixInput float_fix = field.fix_at(2.0 + locator.l4_m());
    float_fix.quality = 5;
    EXPECT_EQ(locator.on_fix(float_fix, std::nullopt, 1.0), LocatorEvent::none);
    EXPECT_EQ(locator.on_fix(field.fix_at(2.1 + locator.l4_m()), std::nullopt, 1.0), LocatorEvent::reached);
}

}  // namespace
