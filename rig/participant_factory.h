#pragma once
// The only way this project creates a DDS participant: from the loopback-only
// profile in rig/loopback_profile.xml (SHM + UDPv4 on 127.0.0.1, unicast initial
// peers, no multicast). Never create a participant with default QoS: it would send
// multicast discovery out of every interface.
#include <cstdint>
#include <string>

namespace eprosima::fastdds::dds {
class DomainParticipant;
}

namespace rig {

inline constexpr const char* kLoopbackProfileName = "rig_loopback";
// Environment variable naming an alternative profile file (e.g. two hosts); it must
// define a participant profile named kLoopbackProfileName.
inline constexpr const char* kProfileFileEnv = "RIG_DDS_PROFILE_FILE";

// The profile XML compiled into the binary (rig/loopback_profile.xml).
const std::string& embedded_loopback_profile_xml();

// Creates a participant on `domain_id` named `participant_name` from the profile.
// Throws std::runtime_error (naming the domain and the profile) on failure.
eprosima::fastdds::dds::DomainParticipant* create_loopback_participant(std::uint32_t domain_id,
                                                                      const std::string& participant_name);

// Deletes the participant and every entity it contains.
void delete_participant(eprosima::fastdds::dds::DomainParticipant* participant);

}  // namespace rig
