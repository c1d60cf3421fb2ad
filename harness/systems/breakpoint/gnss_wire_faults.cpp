#include "harness/systems/breakpoint/gnss_wire_faults.h"

#include <stdexcept>

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
    for (const RecordedSample& sample : trace.samples(topics::kGnssNmea)) {
        ++sentences;
        if (!nmea::parse_sentence(sample.json.at("sentence").get<std::string>()).ok()) ++bad;
    }
    metrics.values["gnss_sentences_count"] = static_cast<double>(sentences);
    metrics.values["gnss_bad_sentences_count"] = static_cast<double>(bad);
    if (const std::vector<RecordedSample>& status = trace.samples(topics::kControllerStatus); !status.empty()) {
        metrics.values["controller_nmea_rejected_count"] = status.back().json.at("nmea_rejected_count").get<double>();
    }
    return metrics;
}

}  // namespace rig::harness
