#include "harness/trace/topic_roles.h"

#include "idl/topics.h"

namespace rig::harness {

namespace {

bool starts_with(const std::string& text, const char* prefix) { return text.rfind(prefix, 0) == 0; }

}  // namespace

TopicRole topic_role(const std::string& topic) {
    if (starts_with(topic, "device/")) return TopicRole::device;
    if (starts_with(topic, "truth/")) return TopicRole::truth;
    if (starts_with(topic, "actuator/")) return TopicRole::actuator;
    if (starts_with(topic, "controller/")) return TopicRole::controller;
    if (starts_with(topic, "rig/clock/")) return TopicRole::clock;
    return TopicRole::other;
}

std::string_view to_string(TopicRole role) {
    switch (role) {
        case TopicRole::device: return "device";
        case TopicRole::truth: return "truth";
        case TopicRole::actuator: return "actuator";
        case TopicRole::controller: return "controller";
        case TopicRole::clock: return "clock";
        case TopicRole::other: break;
    }
    return "other";
}

bool rig_only_topic(const std::string& topic) {
    const TopicRole role = topic_role(topic);
    return role == TopicRole::truth || role == TopicRole::device;
}

bool controller_output_topic(const std::string& topic) {
    const TopicRole role = topic_role(topic);
    return role == TopicRole::actuator || role == TopicRole::controller;
}

std::optional<std::string> topic_role_violation(const std::string& endpoint, const std::string& topic) {
    const bool writer = endpoint == "writer";
    if (starts_with(topic, "truth/")) return std::string(writer ? "writes" : "reads") + " truth topic " + topic;
    if (writer && starts_with(topic, "device/")) return "writes device topic " + topic;
    if (writer && topic == topics::kClockTick) return "writes the clock's tick topic " + topic;
    return std::nullopt;
}

std::optional<std::string> declared_role_violation(const std::vector<std::string>& subscribed,
                                                   const std::vector<std::string>& published) {
    for (const std::string& topic : subscribed) {
        if (auto why = topic_role_violation("reader", topic)) return *why + " (declared in its hello)";
    }
    for (const std::string& topic : published) {
        if (auto why = topic_role_violation("writer", topic)) return *why + " (declared in its hello)";
    }
    return std::nullopt;
}

}  // namespace rig::harness
