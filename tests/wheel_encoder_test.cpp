// The land-wheel encoder's count and the capture time of its last edge, against
// a plant whose wheel travel is known in closed form (no DDS: sample() is what
// step() publishes).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>

#include "emulators/plant.h"
#include "emulators/wheel_encoder.h"

namespace {

using rig::TimeNs;
using rig::emulators::DrivePhase;
using rig::emulators::Plant;
using rig::emulators::PlantParams;
using rig::emulators::StandPhase;
using rig::emulators::WheelEncoder;
using rig::emulators::WheelEncoderParams;

constexpr double kSpeed_m_s = 6.0 / 3.6;
constexpr double kAccel_m_s2 = 0.5;
constexpr double kPulse_m = M_PI * 1.0 / 1000.0;  // 1 m wheel, 1000 pulses/rev
constexpr TimeNs kReadPeriodNs = 10'000'000;

// Stand for stand_s, then drive to 200 m at 6 km/h; a wheel that rolls exactly
// the ground distance (no slip, terrain or deflection).
PlantParams plant_params(double stand_s) {
    PlantParams params;
    params.route = {StandPhase{stand_s}, DrivePhase{200.0, kSpeed_m_s, kAccel_m_s2}};
    params.wheel.terrain_sd_m_per_sqrt_m = 0.0;
    return params;
}

// When the wheel has rolled distance_m while cruising: after the ramp up
// (v / a seconds covering v^2 / 2a), at constant speed.
double cruise_time_s(double stand_s, double distance_m) {
    const double ramp_s = kSpeed_m_s / kAccel_m_s2;
    const double ramp_m = kSpeed_m_s * kSpeed_m_s / (2.0 * kAccel_m_s2);
    return stand_s + ramp_s + (distance_m - ramp_m) / kSpeed_m_s;
}

TEST(WheelEncoder, CaptureIsTheMicrosecondOfTheLastEdgeAtAKnownSpeed) {
    const Plant plant(plant_params(1.0));
    WheelEncoder encoder(plant, WheelEncoderParams{});
    const double cruise_from_s = 1.0 + kSpeed_m_s / kAccel_m_s2 + 0.02;
    int checked = 0;
    std::uint32_t previous_count = 0;
    for (TimeNs t = 0; t <= 30'000'000'000LL; t += kReadPeriodNs) {
        encoder.sample(t);
        ASSERT_EQ(encoder.count(), encoder.count_at(t));
        if (t < rig::seconds_to_ns(cruise_from_s)) {
            previous_count = encoder.count();
            continue;
        }
        // 6 km/h is 5.3 pulses per 10 ms read: the count moves on every read.
        ASSERT_GT(encoder.count(), previous_count) << t;
        previous_count = encoder.count();
        const double edge_s = cruise_time_s(1.0, encoder.count() * kPulse_m);
        // The edge to the nanosecond (float rounding of the plant's position aside)...
        EXPECT_NEAR(static_cast<double>(encoder.last_edge_ns()), edge_s * 1e9, 2.0) << t;
        // ...before or at the read, within the read period.
        EXPECT_LE(encoder.last_edge_ns(), t);
        EXPECT_GT(encoder.last_edge_ns(), t - kReadPeriodNs);
        // The capture: the timer's tick in which it came.
        EXPECT_EQ(encoder.last_edge_capture_us(), static_cast<std::uint32_t>(encoder.last_edge_ns() / 1000));
        EXPECT_NEAR(static_cast<double>(encoder.last_edge_capture_us()), std::floor(edge_s * 1e6), 1.0) << t;
        ++checked;
    }
    EXPECT_GT(checked, 2500);
}

TEST(WheelEncoder, CaptureHoldsWhileStandingAndStartsAtZero) {
    const Plant plant(plant_params(2.0));
    WheelEncoder encoder(plant, WheelEncoderParams{});
    for (TimeNs t = 0; t <= 2'000'000'000LL; t += kReadPeriodNs) {
        encoder.sample(t);
        EXPECT_EQ(encoder.count(), 0u);
        EXPECT_EQ(encoder.last_edge_capture_us(), 0u);
    }
    // Rolling: the first edge after 1 pulse from rest, t = 2 + sqrt(2 P / a).
    for (TimeNs t = 2'010'000'000LL; encoder.count() == 0; t += kReadPeriodNs) encoder.sample(t);
    const double first_edge_s = 2.0 + std::sqrt(2.0 * kPulse_m / kAccel_m_s2);
    if (encoder.count() == 1) {
        EXPECT_NEAR(static_cast<double>(encoder.last_edge_ns()), first_edge_s * 1e9, 2.0);
    }
    // Sampled again at the same instant: nothing moves.
    const TimeNs edge_ns = encoder.last_edge_ns();
    const TimeNs again_ns = (edge_ns / kReadPeriodNs + 1) * kReadPeriodNs;
    encoder.sample(again_ns);
    const std::uint32_t count = encoder.count();
    const TimeNs edge_again_ns = encoder.last_edge_ns();
    encoder.sample(again_ns);
    EXPECT_EQ(encoder.count(), count);
    EXPECT_EQ(encoder.last_edge_ns(), edge_again_ns);
}

TEST(WheelEncoder, CaptureWrapsAfter2To32Microseconds) {
    // Stand 4291 s, then drive (cruising from 4294.35 s): the edges around
    // t = 2^32 us (4294.967296 s) wrap.
    const double stand_s = 4291.0;
    const Plant plant(plant_params(stand_s));
    WheelEncoder encoder(plant, WheelEncoderParams{});
    encoder.sample(0);
    const TimeNs cruise_from_ns = rig::seconds_to_ns(stand_s + kSpeed_m_s / kAccel_m_s2 + 0.02);
    bool seen_before_wrap = false;
    bool seen_after_wrap = false;
    for (TimeNs t = cruise_from_ns; t < cruise_from_ns + 2'000'000'000LL; t += kReadPeriodNs) {
        encoder.sample(t);
        const double edge_us = std::floor(cruise_time_s(stand_s, encoder.count() * kPulse_m) * 1e6);
        const auto expected = static_cast<std::uint32_t>(static_cast<std::uint64_t>(edge_us) & 0xffffffffULL);
        EXPECT_LE(static_cast<std::uint32_t>(encoder.last_edge_capture_us() - expected) + 1u, 2u) << t;
        (edge_us < 4294967296.0 ? seen_before_wrap : seen_after_wrap) = true;
    }
    EXPECT_TRUE(seen_before_wrap);
    EXPECT_TRUE(seen_after_wrap);
}

TEST(WheelEncoder, RefusesTimeGoingBackwards) {
    const Plant plant(plant_params(1.0));
    WheelEncoder encoder(plant, WheelEncoderParams{});
    encoder.sample(50'000'000);
    EXPECT_THROW(encoder.sample(40'000'000), std::logic_error);
}

}  // namespace
