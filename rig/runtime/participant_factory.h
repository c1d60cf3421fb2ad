#pragma once
// The only way this project creates a DDS participant: from the loopback-only
// profile in rig/runtime/loopback_profile.xml (SHM + UDPv4 on 127.0.0.1, unicast initial
// peers, no multicast). Never create a participant with default QoS: it would send
// multicast discovery out of every interface.
#include <cstdint>
#include <string>

namespace eprosima::fastdds::dds {
class DomainParticipant;
class DomainParticipantListener;
}

namespace rig {

inline constexpr const char* kLoopbackProfileName = "rig_loopback";
// Environment variable naming an alternative profile file (e.g. two hosts); it must
// define a participant profile named kLoopbackProfileName.
inline constexpr const char* kProfileFileEnv = "RIG_DDS_PROFILE_FILE";

// The profile XML compiled into the binary (rig/runtime/loopback_profile.xml).
const std::string& embedded_loopback_profile_xml();

// Creates a participant on `domain_id` named `participant_name` from the profile
// (the name is the only QoS set in code: discovery announces it, so the harness
// can say which participant did what). `discovery_listener`, when given, gets
// the discovery callbacks of every participant and endpoint on the domain, from
// the first moment (it is installed at creation, with no status mask: it never
// takes over the endpoints' own listeners). Throws std::runtime_error (naming
// the domain and the profile) on failure.
//
// Participant ids: the factory gives each participant the lowest id no other
// live participant of this process holds (participant ids are per process in
// Fast DDS, whatever the domain). Fast DDS's own numbering never reuses one: a
// process that creates a participant per case counts on, and from id 120 up a
// participant's well-known ports (7400 + 250 domain + 10 + 2 id) are those of
// the next domain's first participants, so two cases' traffic crossed (seen as a
// controller taking another case's clock tick, 126 cases into a demo).
eprosima::fastdds::dds::DomainParticipant* create_loopback_participant(
    std::uint32_t domain_id, const std::string& participant_name,
    eprosima::fastdds::dds::DomainParticipantListener* discovery_listener = nullptr);

// Deletes the participant and every entity it contains.
void delete_participant(eprosima::fastdds::dds::DomainParticipant* participant);

}  // namespace rig
