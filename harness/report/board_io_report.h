#pragma once
// The board I/O block of results.json (`realtime.board_io`, made by
// harness/session/board_attach.h board_io_report()) as text for report.txt and as
// labelled rows for report.html. Pure functions of the JSON.
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

namespace rig::harness {

// "412 valid requests (410 answered, 0 broadcast, 120 writes); refused: ...; dropped: ...; fail-safe safe after 1 s: 0 trips"
std::string board_io_summary(const nlohmann::json& board_io);
// (what, value) rows: one per count kind, the fail-safe, the attachment.
std::vector<std::pair<std::string, std::string>> board_io_rows(const nlohmann::json& board_io);

}  // namespace rig::harness
