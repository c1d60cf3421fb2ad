#include "rig/participant_factory.h"

#include <cstdlib>
#include <mutex>
#include <stdexcept>

#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>

namespace rig {

extern const char* const kLoopbackProfileXml;  // generated from loopback_profile.xml

const std::string& embedded_loopback_profile_xml() {
    static const std::string xml{kLoopbackProfileXml};
    return xml;
}

namespace {

namespace dds = eprosima::fastdds::dds;

void load_profiles_once() {
    static std::once_flag once;
    static std::string error;
    std::call_once(once, [] {
        auto* factory = dds::DomainParticipantFactory::get_instance();
        const char* override_file = std::getenv(kProfileFileEnv);
        eprosima::fastrtps::types::ReturnCode_t rc;
        if (override_file != nullptr && *override_file != '\0') {
            rc = factory->load_XML_profiles_file(override_file);
            if (rc != eprosima::fastrtps::types::ReturnCode_t::RETCODE_OK) {
                error = std::string("cannot load DDS profile file ") + override_file + " (from " +
                        kProfileFileEnv + ")";
            }
        } else {
            const std::string& xml = embedded_loopback_profile_xml();
            rc = factory->load_XML_profiles_string(xml.data(), xml.size());
            if (rc != eprosima::fastrtps::types::ReturnCode_t::RETCODE_OK) error = "cannot load the embedded loopback DDS profile";
        }
    });
    if (!error.empty()) throw std::runtime_error(error);
}

}  // namespace

dds::DomainParticipant* create_loopback_participant(std::uint32_t domain_id,
                                                    const std::string& participant_name) {
    load_profiles_once();
    // Straight from the profile: no QoS object built in code, so the transports and
    // discovery settings are exactly those of loopback_profile.xml.
    auto* participant = dds::DomainParticipantFactory::get_instance()->create_participant_with_profile(
        static_cast<dds::DomainId_t>(domain_id), kLoopbackProfileName);
    if (participant == nullptr) {
        throw std::runtime_error("cannot create DDS participant '" + participant_name + "' on domain " +
                                 std::to_string(domain_id) + " from profile " + kLoopbackProfileName);
    }
    return participant;
}

void delete_participant(dds::DomainParticipant* participant) {
    if (participant == nullptr) return;
    participant->delete_contained_entities();
    dds::DomainParticipantFactory::get_instance()->delete_participant(participant);
}

}  // namespace rig
