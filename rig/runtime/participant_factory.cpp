#include "rig/runtime/participant_factory.h"

#include <cstdlib>
#include <map>
#include <mutex>
#include <set>
#include <stdexcept>

#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/domain/qos/DomainParticipantQos.hpp>

#include "rig/runtime/dds_security.h"

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

// The participant ids this process's live participants hold.
std::mutex ids_mutex;
std::map<dds::DomainParticipant*, int> ids_in_use;

int lowest_free_id() {
    std::set<int> used;
    for (const auto& [participant, id] : ids_in_use) used.insert(id);
    int id = 0;
    while (used.count(id)) ++id;
    return id;
}

}  // namespace

dds::DomainParticipant* create_loopback_participant(std::uint32_t domain_id, const std::string& participant_name,
                                                    dds::DomainParticipantListener* discovery_listener) {
    load_profiles_once();
    // The QoS comes from the profile, so the transports and discovery settings are
    // exactly those of loopback_profile.xml; only the name is set here.
    auto* factory = dds::DomainParticipantFactory::get_instance();
    dds::DomainParticipantQos qos;
    if (factory->get_participant_qos_from_profile(kLoopbackProfileName, qos) !=
        eprosima::fastrtps::types::ReturnCode_t::RETCODE_OK) {
        throw std::runtime_error(std::string("cannot read DDS participant profile ") + kLoopbackProfileName);
    }
    qos.name(participant_name);
    // DDS-Security, when this process has an identity (rig/runtime/dds_security.h):
    // the plugins go on top of the profile; its transports and discovery stay as they are.
    if (const std::filesystem::path identity = dds_security_identity(); !identity.empty()) {
        add_dds_security_properties(identity, qos.properties());
    }
    std::lock_guard lock(ids_mutex);
    const int participant_id = lowest_free_id();
    qos.wire_protocol().participant_id = participant_id;
    auto* participant = factory->create_participant(static_cast<dds::DomainId_t>(domain_id), qos, discovery_listener,
                                                    dds::StatusMask::none());
    if (participant != nullptr) ids_in_use[participant] = participant_id;
    if (participant == nullptr) {
        const std::filesystem::path identity = dds_security_identity();
        throw std::runtime_error("cannot create DDS participant '" + participant_name + "' on domain " +
                                 std::to_string(domain_id) + " from profile " + kLoopbackProfileName +
                                 (identity.empty() ? std::string()
                                                   : " with the DDS-Security identity " + identity.string() +
                                                         " (Fast DDS's log above says what it refused)"));
    }
    return participant;
}

void delete_participant(dds::DomainParticipant* participant) {
    if (participant == nullptr) return;
    participant->delete_contained_entities();
    dds::DomainParticipantFactory::get_instance()->delete_participant(participant);
    std::lock_guard lock(ids_mutex);
    ids_in_use.erase(participant);
}

}  // namespace rig
