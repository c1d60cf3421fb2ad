#include "harness/spec/board_spec.h"

namespace rig::harness {

namespace {
constexpr EnumChoice<modbus::FailsafeMode> kFailsafeModes[] = {
    {"safe", modbus::FailsafeMode::safe},
    {"hold", modbus::FailsafeMode::hold},
};
}  // namespace

BoardSpec read_board_spec(const YamlSection& section) {
    BoardSpec board;
    board.attach_timeout_s =
        section.optional_in_range<double>("attach_timeout_s", board.attach_timeout_s, Bounds::closed(0.5, 3600));
    board.silence_timeout_s =
        section.optional_in_range<double>("silence_timeout_s", board.silence_timeout_s, Bounds::closed(0.05, 600));
    board.failsafe_timeout_s =
        section.optional_in_range<double>("failsafe_timeout_s", board.failsafe_timeout_s, Bounds::closed(0, 600));
    if (board.failsafe_timeout_s > 0 && board.failsafe_timeout_s < 0.05) {
        section.fail("failsafe_timeout_s", "must be 0 (off) or at least 0.05 s (a request round trip on a 9600-baud "
                                           "line takes tens of ms)");
    }
    board.failsafe = section.optional_enum<modbus::FailsafeMode>("failsafe", kFailsafeModes, board.failsafe);
    // Percentages of responses: at 100 every response is damaged.
    const YamlSection noise = section.section("line_noise");
    board.line_noise.corrupt_response_pct =
        noise.optional_in_range<double>("corrupt_response_pct", 0.0, Bounds::closed(0, 100));
    board.line_noise.noise_burst_pct = noise.optional_in_range<double>("noise_burst_pct", 0.0, Bounds::closed(0, 100));
    return board;
}

}  // namespace rig::harness
