#include "harness/report/board_io_report.h"

namespace rig::harness {

namespace {

std::string count_of(const nlohmann::json& block, const char* key) {
    return block.contains(key) ? block.at(key).dump() : std::string("?");
}

// "bad_crc 0, wrong_address 2, ..." over every key of a count object.
std::string counts_text(const nlohmann::json& counts) {
    std::string text;
    if (!counts.is_object()) return text;
    for (const auto& [kind, value] : counts.items()) text += (text.empty() ? "" : ", ") + kind + " " + value.dump();
    return text;
}

std::string failsafe_text(const nlohmann::json& board_io) {
    if (!board_io.contains("failsafe")) return "?";
    const nlohmann::json& failsafe = board_io.at("failsafe");
    const double timeout_s = failsafe.value("timeout_s", 0.0);
    if (timeout_s <= 0.0) return "off";
    char text[96];
    std::snprintf(text, sizeof text, "%s after %g s, %s trips", failsafe.value("mode", std::string("?")).c_str(),
                  timeout_s, count_of(failsafe, "trips").c_str());
    return text;
}

// "159 of 8286 responses corrupted, 91 noise bursts (390 bytes)": what the case's line noise did.
std::string line_noise_counts(const nlohmann::json& noise) {
    return count_of(noise, "responses_corrupted") + " of " + count_of(noise, "responses") +
           " responses corrupted, " + count_of(noise, "noise_bursts") + " noise bursts (" +
           count_of(noise, "noise_bytes") + " bytes)";
}

}  // namespace

std::string board_io_summary(const nlohmann::json& board_io) {
    if (!board_io.is_object()) return {};
    return count_of(board_io, "valid_requests") + " valid requests (" + count_of(board_io, "answered") + " answered, " +
           count_of(board_io, "broadcast") + " broadcast, " + count_of(board_io, "master_writes") +
           " writes); refused: " + counts_text(board_io.value("refused", nlohmann::json::object())) +
           "; dropped: " + counts_text(board_io.value("dropped", nlohmann::json::object())) +
           "; fail-safe: " + failsafe_text(board_io) +
           (board_io.contains("line_noise") ? "; line noise: " + line_noise_counts(board_io.at("line_noise")) : "");
}

std::vector<std::pair<std::string, std::string>> board_io_rows(const nlohmann::json& board_io) {
    std::vector<std::pair<std::string, std::string>> rows;
    if (!board_io.is_object()) return rows;
    rows.emplace_back("slave", board_io.value("slave", std::string()));
    rows.emplace_back("valid requests", count_of(board_io, "valid_requests"));
    rows.emplace_back("answered", count_of(board_io, "answered"));
    rows.emplace_back("master writes", count_of(board_io, "master_writes"));
    for (const char* block : {"refused", "dropped"}) {
        const nlohmann::json counts = board_io.value(block, nlohmann::json::object());
        for (const auto& [kind, value] : counts.items()) rows.emplace_back(std::string(block) + ": " + kind, value.dump());
    }
    rows.emplace_back("fail-safe", failsafe_text(board_io));
    if (board_io.contains("line_noise")) rows.emplace_back("line noise (injected)", line_noise_counts(board_io.at("line_noise")));
    if (board_io.contains("attach")) {
        const nlohmann::json& attach = board_io.at("attach");
        std::string seen;
        for (const nlohmann::json& line : attach.value("seen", nlohmann::json::array())) {
            seen += (seen.empty() ? "" : "; ") + line.get<std::string>();
        }
        rows.emplace_back("attached", seen.empty() ? std::string("at once") : seen);
    }
    return rows;
}

}  // namespace rig::harness
