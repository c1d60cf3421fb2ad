#include "harness/wire_fault_report.h"

#include <stdexcept>

#include "harness/board_attach.h"
#include "harness/case_session.h"
#include "idl/topics.h"
#include "rig/nmea/nmea_parser.h"

namespace rig::harness {

emulators::NmeaWireFaultRates nmea_wire_fault_rates(const GnssWireFaultsSpec& spec) {
    return emulators::NmeaWireFaultRates{spec.byte_loss_pct, spec.corrupt_checksum_pct, spec.truncate_pct};
}

nlohmann::json gnss_wire_fault_json(const GnssWireFaultsSpec& spec, const emulators::NmeaWireFaultCounts& counts) {
    return {{"rates",
             {{"byte_loss_pct", spec.byte_loss_pct},
              {"corrupt_checksum_pct", spec.corrupt_checksum_pct},
              {"truncate_pct", spec.truncate_pct}}},
            {"injected",
             {{"sentences", counts.sentences},
              {"sentences_damaged", counts.sentences_damaged},
              {"sentences_lost", counts.sentences_lost},
              {"sentences_damaged_parsed", counts.sentences_damaged_parsed},
              {"bytes_lost", counts.bytes_lost},
              {"checksums_corrupted", counts.checksums_corrupted},
              {"sentences_truncated", counts.sentences_truncated}}}};
}

MetricSet gnss_wire_fault_metrics(const RecordedTrace& trace) {
    MetricSet metrics;
    const auto meta = trace.meta.find(kGnssWireFaultsMeta);
    if (meta == trace.meta.end()) return metrics;
    try {
        const nlohmann::json injected = nlohmann::json::parse(meta->second).at("injected");
        auto count = [&](const char* key) { return static_cast<double>(injected.at(key).get<std::uint64_t>()); };
        metrics.values["gnss_damaged_sentences_count"] = count("sentences_damaged");
        metrics.values["gnss_lost_sentences_count"] = count("sentences_lost");
        metrics.values["gnss_damaged_sentences_parsed_count"] = count("sentences_damaged_parsed");
        metrics.values["gnss_bytes_lost_count"] = count("bytes_lost");
        metrics.values["gnss_corrupt_checksums_count"] = count("checksums_corrupted");
        metrics.values["gnss_truncated_sentences_count"] = count("sentences_truncated");
    } catch (const nlohmann::json::exception& error) {
        throw std::runtime_error(std::string("meta ") + kGnssWireFaultsMeta + ": " + error.what());
    }
    // What the wire carried, judged by the rig's own parser (the one the
    // reference controller uses, rig/nmea/nmea_parser.h).
    std::uint64_t sentences = 0;
    std::uint64_t bad = 0;
    if (const auto it = trace.samples.find(topics::kGnssNmea); it != trace.samples.end()) {
        for (const RecordedSample& sample : it->second) {
            ++sentences;
            if (!nmea::parse_sentence(sample.json.at("sentence").get<std::string>()).ok()) ++bad;
        }
    }
    metrics.values["gnss_sentences_count"] = static_cast<double>(sentences);
    metrics.values["gnss_bad_sentences_count"] = static_cast<double>(bad);
    if (const auto it = trace.samples.find(topics::kControllerStatus); it != trace.samples.end() && !it->second.empty()) {
        metrics.values["controller_nmea_rejected_count"] = it->second.back().json.at("nmea_rejected_count").get<double>();
    }
    return metrics;
}

std::shared_ptr<emulators::RtuLineNoise> install_line_noise(const CaseSpec& spec, std::uint64_t seed,
                                                            BenchWires& wires) {
    if (!spec.board.line_noise.any() || spec.wiring.board_io != BoardIoWireKind::modbus_rtu) return nullptr;
    modbus::ModbusSlave* slave = modbus_slave_of(wires);
    if (slave == nullptr) return nullptr;
    auto noise = std::make_shared<emulators::RtuLineNoise>(
        emulators::RtuLineNoiseRates{spec.board.line_noise.corrupt_response_pct, spec.board.line_noise.noise_burst_pct},
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
