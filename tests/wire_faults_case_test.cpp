// A GNSS wire-fault case run whole through `bin/rig` (cases/wire-faults/):
//  * the reference controller passes it, rejects exactly the sentences the
//    rig's parser calls bad, and the counts are in results.json;
//  * the faults change only the receiver's bytes: the truth and every
//    undamaged sentence are those of the same case with the faults off, and a
//    case with its rates written as 0 has the digest of one without the key.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>

#include <nlohmann/json.hpp>

#include "harness/trace/trace_reader.h"
#include "idl/topics.h"
#include "run_support.h"

namespace {

namespace fs = std::filesystem;
using rig::testing::read_all;

const fs::path kCase = fs::path(RIG_SOURCE_DIR) / "cases" / "wire-faults" / "gnss-corrupt-checksum-fusion-6kmh.yaml";
const std::string kFaultLine = "wire_faults: { corrupt_checksum_pct: 15 }";

// `rig run FILE --out DIR`; the case's results.json entry (null when none).
nlohmann::json run_case(const fs::path& file, const fs::path& out) {
    const std::string command = "timeout -k 10 300 '" RIG_BINARY_DIR "/bin/rig' run '" + file.string() + "' --out '" +
                                out.string() + "' > '" + out.string() + ".log' 2>&1";
    std::system(command.c_str());
    if (!fs::exists(out / "results.json")) return nullptr;
    return nlohmann::json::parse(read_all(out / "results.json")).at("cases").at(0);
}

// The case file with its fault line replaced.
fs::path variant(const fs::path& dir, const std::string& name, const std::string& fault_line) {
    std::string text = read_all(kCase);
    const std::size_t at = text.find(kFaultLine);
    EXPECT_NE(at, std::string::npos) << kCase << " no longer has '" << kFaultLine << "'";
    if (at != std::string::npos) text.replace(at, kFaultLine.size(), fault_line);
    const fs::path file = dir / (name + ".yaml");
    std::ofstream(file) << text;
    return file;
}

const std::vector<rig::harness::RecordedSample>& samples(const rig::harness::RecordedTrace& trace, const char* topic) {
    return trace.samples(topic);
}

TEST(WireFaultsCase, ReferenceControllerRejectsEveryCorruptSentenceAndOnlyTheBytesChange) {
    const fs::path dir = rig::testing::fresh_dir("wire-faults-case");
    const nlohmann::json faulty = run_case(kCase, dir / "faulty");
    const nlohmann::json off = run_case(variant(dir, "off", "wire_faults: { corrupt_checksum_pct: 0 }"), dir / "off");
    const nlohmann::json absent = run_case(variant(dir, "absent", "# no wire faults"), dir / "absent");
    ASSERT_FALSE(faulty.is_null()) << read_all(dir / "faulty.log");
    ASSERT_FALSE(off.is_null()) << read_all(dir / "off.log");
    ASSERT_FALSE(absent.is_null()) << read_all(dir / "absent.log");

    // The verdict, and the counts: injected, seen bad by the rig's parser,
    // rejected by the controller, all equal (none of them passes the parser).
    EXPECT_TRUE(faulty.at("passed").get<bool>()) << faulty.dump(2);
    const nlohmann::json& metrics = faulty.at("metrics");
    const double corrupted = metrics.at("gnss_corrupt_checksums_count");
    EXPECT_GT(corrupted, 20.0);
    EXPECT_EQ(metrics.at("gnss_damaged_sentences_count").get<double>(), corrupted);
    EXPECT_EQ(metrics.at("gnss_bad_sentences_count").get<double>(), corrupted);
    EXPECT_EQ(metrics.at("controller_nmea_rejected_count").get<double>(), corrupted);
    EXPECT_EQ(metrics.at("gnss_damaged_sentences_parsed_count").get<double>(), 0.0);
    // Faults off: no wire-fault metrics, and 0 written is the same run as nothing written.
    EXPECT_FALSE(off.at("metrics").contains("gnss_bad_sentences_count"));
    EXPECT_EQ(off.at("trace_sha256"), absent.at("trace_sha256"));
    EXPECT_NE(faulty.at("trace_sha256"), off.at("trace_sha256"));

    // trace_path is relative to the run's --out folder (docs/design.md "Results").
    const auto faulty_trace = rig::harness::read_trace(dir / "faulty" / faulty.at("trace_path").get<std::string>());
    const auto off_trace = rig::harness::read_trace(dir / "off" / off.at("trace_path").get<std::string>());
    // The truth is the route's, whatever the wire did: equal at every instant
    // both traces sampled it (the 20 Hz grid; the extra samples at the
    // controller's own events fall where its decisions did).
    std::map<rig::TimeNs, nlohmann::json> off_truth;
    for (const auto& sample : samples(off_trace, rig::topics::kVehicleTruth)) off_truth[sample.t_ns] = sample.json;
    const auto& truth = samples(faulty_trace, rig::topics::kVehicleTruth);
    std::size_t shared = 0;
    for (const auto& sample : truth) {
        const auto it = off_truth.find(sample.t_ns);
        if (it == off_truth.end()) continue;
        ++shared;
        ASSERT_EQ(sample.json, it->second) << "truth at t_ns " << sample.t_ns;
    }
    EXPECT_GT(shared, 500u);
    EXPECT_GE(shared + 10, truth.size());
    // The same sentences at the same instants, each either whole or with only
    // its two checksum digits changed.
    const auto& nmea = samples(faulty_trace, rig::topics::kGnssNmea);
    const auto& off_nmea = samples(off_trace, rig::topics::kGnssNmea);
    ASSERT_EQ(nmea.size(), off_nmea.size());
    std::size_t changed = 0;
    for (std::size_t i = 0; i < nmea.size(); ++i) {
        ASSERT_EQ(nmea[i].t_ns, off_nmea[i].t_ns);
        const std::string sentence = nmea[i].json.at("sentence");
        const std::string clean = off_nmea[i].json.at("sentence");
        if (sentence == clean) continue;
        ++changed;
        ASSERT_EQ(sentence.size(), clean.size());
        EXPECT_EQ(sentence.substr(0, sentence.size() - 2), clean.substr(0, clean.size() - 2)) << sentence;
    }
    EXPECT_EQ(static_cast<double>(changed), corrupted);
}

}  // namespace
