// Actuator commands the plant refuses (emulators/malformed_command.h), without
// DDS: what is malformed on each actuator topic and how the error reads. The
// plant nodes throwing it mid-run, in every clock mode, are whole runs:
// faulty_controllers_test, seed001_cases_test, in_process_test, whole_run_test.
#include <gtest/gtest.h>

#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "emulators/malformed_command.h"
#include "idl/topics.h"
#include "rig/runtime/failure_kind.h"

namespace {

using rig::emulators::malformed_command;
using rig::emulators::nozzle_pwm_problem;
using rig::emulators::section_valves_problem;

rig::msg::SectionValves sections(std::uint16_t open_mask) {
    rig::msg::SectionValves command;
    command.open_mask(open_mask);
    return command;
}

rig::msg::NozzlePwm pwm(std::vector<double> duty_pct, double frequency_hz = 9.0) {
    rig::msg::NozzlePwm command;
    command.frequency_hz(frequency_hz);
    command.duty_pct(std::move(duty_pct));
    return command;
}

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

TEST(MalformedCommand, EverySectionMaskOfTheBoomsOwnSectionsIsACommand) {
    for (std::uint16_t mask = 0; mask < 8; ++mask) EXPECT_EQ(section_valves_problem(sections(mask), 3), std::nullopt) << mask;
    EXPECT_EQ(section_valves_problem(sections(0xFF), 8), std::nullopt);
    EXPECT_EQ(section_valves_problem(sections(1), 1), std::nullopt);
}

TEST(MalformedCommand, ASectionBitTheBoomDoesNotHaveIsNamed) {
    EXPECT_EQ(section_valves_problem(sections(15), 3), "open_mask 15 sets bit 3, but the boom has 3 sections (bits 0-2)");
    EXPECT_EQ(section_valves_problem(sections(8), 3), "open_mask 8 sets bit 3, but the boom has 3 sections (bits 0-2)");
    EXPECT_EQ(section_valves_problem(sections(0b1010'0001), 3),
              "open_mask 161 sets bits 5, 7, but the boom has 3 sections (bits 0-2)");
    EXPECT_EQ(section_valves_problem(sections(0x8000), 8),
              "open_mask 32768 sets bit 15, but the boom has 8 sections (bits 0-7)");
    EXPECT_EQ(section_valves_problem(sections(3), 1), "open_mask 3 sets bit 1, but the boom has 1 section (bit 0)");
}

TEST(MalformedCommand, OneFiniteDutyPerNozzleInZeroToHundredIsACommand) {
    EXPECT_EQ(nozzle_pwm_problem(pwm({0, 0, 0, 0, 0, 0}), 6), std::nullopt);
    EXPECT_EQ(nozzle_pwm_problem(pwm({100, 40, 0, 100, 0.001, 99.999}), 6), std::nullopt);
    // The plant runs its PWM at the case's frequency; any real frequency is one.
    EXPECT_EQ(nozzle_pwm_problem(pwm({100}, 1e-3), 1), std::nullopt);
}

TEST(MalformedCommand, ADutyMissingOrExtraIsCountedAgainstTheNozzles) {
    EXPECT_EQ(nozzle_pwm_problem(pwm({100, 100, 100, 100, 100, 100, 100}), 6), "7 duty entries for 6 nozzles");
    EXPECT_EQ(nozzle_pwm_problem(pwm({100, 100, 100, 100, 100}), 6), "5 duty entries for 6 nozzles");
    EXPECT_EQ(nozzle_pwm_problem(pwm({}), 6), "0 duty entries for 6 nozzles");
    EXPECT_EQ(nozzle_pwm_problem(pwm({50}), 2), "1 duty entry for 2 nozzles");
    EXPECT_EQ(nozzle_pwm_problem(pwm({50, 50}), 1), "2 duty entries for 1 nozzle");
}

TEST(MalformedCommand, ADutyThatIsNoShareOfThePeriodIsNamedWithItsNozzle) {
    EXPECT_EQ(nozzle_pwm_problem(pwm({0, 0, kNaN, 0, 0, 0}), 6), "duty_pct[2] = nan, not a duty in 0-100 %");
    EXPECT_EQ(nozzle_pwm_problem(pwm({0, 0, 0, 0, 0, kInf}), 6), "duty_pct[5] = inf, not a duty in 0-100 %");
    EXPECT_EQ(nozzle_pwm_problem(pwm({-0.5, 0, 0, 0, 0, 0}), 6), "duty_pct[0] = -0.5, not a duty in 0-100 %");
    EXPECT_EQ(nozzle_pwm_problem(pwm({0, 100.25, 0, 0, 0, 0}), 6), "duty_pct[1] = 100.25, not a duty in 0-100 %");
    // Never a clipped value passed off as the command: 1e300 is named as sent.
    EXPECT_EQ(nozzle_pwm_problem(pwm({0, 0, 0, 1e300, 0, 0}), 6), "duty_pct[3] = 1e+300, not a duty in 0-100 %");
}

TEST(MalformedCommand, AFrequencyThatIsNoPwmFrequencyIsNamed) {
    const std::vector<double> off(6, 0.0);
    EXPECT_EQ(nozzle_pwm_problem(pwm(off, -9.0), 6), "frequency_hz = -9, not a PWM frequency (finite, 0 Hz or above)");
    EXPECT_EQ(nozzle_pwm_problem(pwm(off, kNaN), 6), "frequency_hz = nan, not a PWM frequency (finite, 0 Hz or above)");
    EXPECT_EQ(nozzle_pwm_problem(pwm(off, kInf), 6), "frequency_hz = inf, not a PWM frequency (finite, 0 Hz or above)");
}

// 0 Hz is no PWM: every line held low or high. The bench's edge capture reads
// steady lines so (rig/wire/pwm_capture.h), and a GPIO PWM sets 0 and 100 % so.
TEST(MalformedCommand, NoPwmPeriodIsACommandOnlyForNozzlesHeldOffOrOn) {
    EXPECT_EQ(nozzle_pwm_problem(pwm({0, 0, 0, 0, 0, 0}, 0.0), 6), std::nullopt);
    EXPECT_EQ(nozzle_pwm_problem(pwm({100, 0, 100, 0, 0, 100}, 0.0), 6), std::nullopt);
    EXPECT_EQ(nozzle_pwm_problem(pwm({100, 0, 40, 0, 0, 100}, 0.0), 6),
              "frequency_hz = 0 with duty_pct[2] = 40: a duty between 0 and 100 % needs a PWM period");
    // The same duties with a period are a command.
    EXPECT_EQ(nozzle_pwm_problem(pwm({100, 0, 40, 0, 0, 100}, 9.0), 6), std::nullopt);
}

TEST(MalformedCommand, TheFailureNamesTheControllerTheTopicTheInstantAndWhatWasWrong) {
    const rig::NodeFailure failure =
        malformed_command(rig::topics::kNozzlePwm, 3'210'000'000, "7 duty entries for 6 nozzles");
    EXPECT_EQ(failure.kind(), rig::FailureKind::malformed_command);
    EXPECT_EQ(failure.node_name(), "controller");
    EXPECT_STREQ(failure.what(), "node 'controller': actuator/nozzle_pwm/duty at t=3.210 s: 7 duty entries for 6 nozzles");
    const rig::NodeFailure late = malformed_command(rig::topics::kSectionValves, 10'640'400'000, "open_mask 15 ...");
    EXPECT_STREQ(late.what(), "node 'controller': actuator/section_valves/open at t=10.640 s: open_mask 15 ...");
    // A case file can expect it by name.
    EXPECT_EQ(rig::to_string(rig::FailureKind::malformed_command), "malformed_command");
    EXPECT_EQ(rig::failure_kind_from_string("malformed_command"), rig::FailureKind::malformed_command);
}

}  // namespace
