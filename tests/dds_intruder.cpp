// An intruder for dds_security_test: a participant that is not the run's
// controller, on the run's domain and the loopback profile, with whatever
// DDS-Security identity RIG_DDS_SECURITY_DIR gives it (none: a plain
// participant; another CA's: an impostor). It commands every boom section open
// on the actuator topic every 20 ms until SIGTERM, and prints what it saw, one
// fact a line:
//   self PREFIX                its own GUID prefix (hex)
//   discovered NAME            a participant it discovered (SPDP is plain: a
//                              secured rig is seen, not reached)
//   authorized PREFIX / unauthorized PREFIX
//                              a secured handshake's outcome
//   matched_readers N          each change of its writer's matched readers
//   written N                  at the end: the commands it wrote
//   max_matched_readers N      at the end: the most readers it ever reached
//   usage: dds_intruder --domain N
#include <signal.h>

#include <algorithm>
#include <atomic>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <iostream>
#include <mutex>
#include <string>

#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantListener.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/DataWriterListener.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/publisher/qos/DataWriterQos.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>

#include "idl/msg_traits.h"
#include "idl/topics.h"
#include "rig/runtime/participant_factory.h"

namespace {

namespace fdds = eprosima::fastdds::dds;

// How often the intruder writes its command (wall time): often enough that a
// reader it reaches gets many during any case.
constexpr long kWritePeriodNs = 20'000'000;

std::mutex print_mutex;
void say(const std::string& line) {
    std::lock_guard lock(print_mutex);
    std::cout << line << std::endl;
}

std::string hex_prefix(const eprosima::fastrtps::rtps::GuidPrefix_t& prefix) {
    static const char* digits = "0123456789abcdef";
    std::string hex;
    for (const auto byte : prefix.value) {
        hex += digits[byte >> 4];
        hex += digits[byte & 0xf];
    }
    return hex;
}

class Watch final : public fdds::DomainParticipantListener {
public:
    void on_participant_discovery(fdds::DomainParticipant*, eprosima::fastrtps::rtps::ParticipantDiscoveryInfo&& info) override {
        if (info.status == eprosima::fastrtps::rtps::ParticipantDiscoveryInfo::DISCOVERED_PARTICIPANT) {
            say("discovered " + info.info.m_participantName.to_string());
        }
    }
    void onParticipantAuthentication(fdds::DomainParticipant*,
                                     eprosima::fastrtps::rtps::ParticipantAuthenticationInfo&& info) override {
        const bool authorized =
            info.status == eprosima::fastrtps::rtps::ParticipantAuthenticationInfo::AUTHORIZED_PARTICIPANT;
        say(std::string(authorized ? "authorized " : "unauthorized ") + hex_prefix(info.guid.guidPrefix));
    }
};

class Matches final : public fdds::DataWriterListener {
public:
    std::atomic<int> most{0};
    void on_publication_matched(fdds::DataWriter*, const fdds::PublicationMatchedStatus& status) override {
        most.store(std::max(most.load(), status.current_count));
        say("matched_readers " + std::to_string(status.current_count));
    }
};

}  // namespace

int main(int argc, char** argv) {
    if (argc != 3 || std::strcmp(argv[1], "--domain") != 0) {
        std::cerr << "usage: dds_intruder --domain N\n";
        return 2;
    }
    const auto domain = static_cast<std::uint32_t>(std::strtoul(argv[2], nullptr, 10));
    // SIGTERM ends the loop below; it is waited for, never delivered.
    sigset_t stop;
    sigemptyset(&stop);
    sigaddset(&stop, SIGTERM);
    sigaddset(&stop, SIGINT);
    pthread_sigmask(SIG_BLOCK, &stop, nullptr);

    Watch watch;
    Matches matches;
    std::uint64_t written = 0;
    fdds::DomainParticipant* participant = nullptr;
    try {
        participant = rig::create_loopback_participant(domain, "intruder", &watch);
        say("self " + hex_prefix(participant->guid().guidPrefix));
        fdds::TypeSupport type(new rig::MsgTraits<rig::msg::SectionValves>::PubSubType());
        type.register_type(participant);
        fdds::Topic* topic =
            participant->create_topic(rig::topics::kSectionValves, type.get_type_name(), participant->get_default_topic_qos());
        fdds::Publisher* publisher = participant->create_publisher(participant->get_default_publisher_qos());
        if (topic == nullptr || publisher == nullptr) throw std::runtime_error("cannot create the topic or publisher");
        // The QoS a controller's writer has (docs/controller-contract.md section 2): a reader of the rig's would match it.
        fdds::DataWriterQos qos = publisher->get_default_datawriter_qos();
        qos.reliability().kind = fdds::RELIABLE_RELIABILITY_QOS;
        qos.history().kind = fdds::KEEP_ALL_HISTORY_QOS;
        qos.durability().kind = fdds::VOLATILE_DURABILITY_QOS;
        qos.data_sharing().off();
        fdds::DataWriter* writer = publisher->create_datawriter(topic, qos, &matches, fdds::StatusMask::publication_matched());
        if (writer == nullptr) throw std::runtime_error("cannot create the writer on " + std::string(rig::topics::kSectionValves));
        rig::msg::SectionValves every_section_open;
        every_section_open.open_mask(0xffff);
        const timespec period{0, kWritePeriodNs};
        for (;;) {
            if (writer->write(&every_section_open)) ++written;
            if (sigtimedwait(&stop, nullptr, &period) > 0) break;
        }
    } catch (const std::exception& error) {
        std::cerr << "dds_intruder: " << error.what() << "\n";
        rig::delete_participant(participant);
        return 1;
    }
    say("written " + std::to_string(written));
    say("max_matched_readers " + std::to_string(matches.most.load()));
    rig::delete_participant(participant);
    return 0;
}
