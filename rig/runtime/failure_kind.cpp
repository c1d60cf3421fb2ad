#include "rig/runtime/failure_kind.h"

#include <utility>

namespace rig {

namespace {
constexpr std::pair<FailureKind, std::string_view> kFailureKindNames[] = {
    {FailureKind::node_exited, "node_exited"},
    {FailureKind::node_unresponsive, "node_unresponsive"},
    {FailureKind::node_fatal_error, "node_fatal_error"},
    {FailureKind::startup_timeout, "startup_timeout"},
    {FailureKind::delivery_timeout, "delivery_timeout"},
    {FailureKind::topic_role_violation, "topic_role_violation"},
    {FailureKind::malformed_command, "malformed_command"},
    {FailureKind::wire_unread, "wire_unread"},
    {FailureKind::wall_time_exceeded, "wall_time_exceeded"},
    {FailureKind::feedback_loop, "feedback_loop"},
    {FailureKind::interrupted, "interrupted"},
    {FailureKind::harness_error, "harness_error"},
    {FailureKind::board_not_attached, "board_not_attached"},
    {FailureKind::board_silent, "board_silent"},
    {FailureKind::rig_overloaded, "rig_overloaded"},
};
}  // namespace

std::string_view to_string(FailureKind kind) {
    for (const auto& [value, name] : kFailureKindNames) {
        if (value == kind) return name;
    }
    return "harness_error";
}

bool is_rigs_own_failure(FailureKind kind) {
    return kind == FailureKind::interrupted || kind == FailureKind::harness_error ||
           kind == FailureKind::rig_overloaded;
}

std::optional<FailureKind> failure_kind_from_string(std::string_view name) {
    for (const auto& [value, known] : kFailureKindNames) {
        if (known == name) return value;
    }
    return std::nullopt;
}

std::string failure_kind_names() {
    std::string names;
    for (const auto& [value, name] : kFailureKindNames) names += (names.empty() ? "" : ", ") + std::string(name);
    return names;
}

}  // namespace rig
