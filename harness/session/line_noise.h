#pragma once
// Noise on a Modbus RTU board wire (the case's board.line_noise,
// emulators/wire_faults.h): put on the rig's slave for the run, counted for
// results.json's board_io block (docs/wire-faults.md).
#include <cstdint>
#include <memory>

#include <nlohmann/json.hpp>

#include "emulators/wire_faults.h"
#include "harness/spec/board_spec.h"
#include "harness/spec/case_spec.h"

namespace rig::harness {

struct BenchWires;
// Puts `board.line_noise` on the case's Modbus RTU slave, seeded from the
// case seed; returns it (for its counts), or null when the case has none.
std::shared_ptr<emulators::RtuLineNoise> install_line_noise(const BoardSpec& board, const WiringSpec& wiring,
                                                            std::uint64_t seed, BenchWires& wires);
// The `line_noise` block of board_io: rates and counts.
nlohmann::json line_noise_json(const emulators::RtuLineNoise& noise);

}  // namespace rig::harness
