#include "harness/session/line_noise.h"

#include "harness/session/board_attach.h"
#include "harness/session/case_session.h"

namespace rig::harness {

std::shared_ptr<emulators::RtuLineNoise> install_line_noise(const BoardSpec& board, const WiringSpec& wiring,
                                                            std::uint64_t seed, BenchWires& wires) {
    if (!board.line_noise.any() || wiring.board_io != BoardIoWireKind::modbus_rtu) return nullptr;
    modbus::ModbusSlave* slave = modbus_slave_of(wires);
    if (slave == nullptr) return nullptr;
    auto noise = std::make_shared<emulators::RtuLineNoise>(
        emulators::RtuLineNoiseRates{board.line_noise.corrupt_response_pct, board.line_noise.noise_burst_pct},
        seed);
    // The slave holds its own reference: its thread may damage a frame until it stops.
    slave->set_response_damage([noise](std::vector<std::uint8_t> frame) { return noise->apply(std::move(frame)); });
    wires.line_noise = noise;
    return noise;
}

nlohmann::json line_noise_json(const emulators::RtuLineNoise& noise) {
    const emulators::RtuLineNoiseCounts counts = noise.counts();
    return {{"corrupt_response_pct", noise.rates().corrupt_response_pct},
            {"noise_burst_pct", noise.rates().noise_burst_pct},
            {"responses", counts.responses},
            {"responses_corrupted", counts.responses_corrupted},
            {"bits_flipped", counts.bits_flipped},
            {"noise_bursts", counts.noise_bursts},
            {"noise_bytes", counts.noise_bytes}};
}

}  // namespace rig::harness
