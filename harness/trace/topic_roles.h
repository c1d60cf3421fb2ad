#pragma once
// Who may read and write which topic (docs/design.md "Data flow", the `role`
// of idl/topics.json): truth/* is the rig's alone, device/* and the clock's
// tick are written by the rig only, actuator/* and controller/* are the
// controller's outputs. The recorder, the run's watchdog and the judge all
// hold a run to these.
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace rig::harness {

// What a topic is for, by its name (the `role` of idl/topics.json): `rig diff`
// tells a changed controller (its actuator commands or reports part first)
// from a changed case or rig (the devices or the plant part first).
enum class TopicRole { device, truth, actuator, controller, clock, other };
TopicRole topic_role(const std::string& topic);
// "device", "truth", "actuator", "controller", "clock", "other".
std::string_view to_string(TopicRole role);

// Topics only the rig may write (truth and device data). A sample on one of
// them from another participant is forged.
bool rig_only_topic(const std::string& topic);
// Topics the controller under test writes (actuator commands, its own reports).
bool controller_output_topic(const std::string& topic);

// Why an endpoint of a participant other than the rig's breaks its role
// ("reads truth topic truth/vehicle"), or nullopt. `endpoint`: reader | writer.
std::optional<std::string> topic_role_violation(const std::string& endpoint, const std::string& topic);
// The same for what a node declared in its hello (the topics it reads and
// writes): why the first one breaks its role, or nullopt. Checked when the
// hellos arrive, before time starts, so a node that declares a forbidden topic
// fails at the same point in every run.
std::optional<std::string> declared_role_violation(const std::vector<std::string>& subscribed,
                                                   const std::vector<std::string>& published);

}  // namespace rig::harness
