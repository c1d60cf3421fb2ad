#include "rig/runtime/dds_context.h"

#include <algorithm>
#include <functional>

#include <fastdds/dds/domain/DomainParticipantListener.hpp>
#include <fastdds/dds/topic/TopicDataType.hpp>
#include <fastdds/dds/publisher/qos/DataWriterQos.hpp>
#include <fastdds/dds/subscriber/qos/DataReaderQos.hpp>

#include "rig/runtime/dds_security.h"
#include "rig/runtime/participant_factory.h"

namespace rig {

using eprosima::fastrtps::types::ReturnCode_t;

namespace {

// Reliable + keep-all: nothing written may be dropped or overwritten, since a
// lockstep node steps only once its readers hold every sample counted in the
// tick (counted delivery, rig/runtime/lockstep.h). Volatile: endpoints are
// matched before the first tick (see rig/runtime/lockstep.cpp).
//
// The reliability timers (ReliabilityTimers, dds_context.h) are Fast DDS's
// event thread's work; on a 2-core machine each wake-up of that thread is a
// context switch inside the lockstep round. No lockstep round waits for an
// acknowledgement (counted delivery replaced wait_for_acknowledgments; a
// follower's last ack, the ping-pong's end, `rig dds-check`'s echo and
// vision_bench's frames still wait for one), so `few_wakeups` sets:
// - nackSupressionDuration 5 ms: Fast DDS 2.9 arms this timer for each sample
//   it sends to a reliable remote reader (the sample is UNDERWAY until it
//   fires) and wakes the event thread when it is not already armed. At 0 it
//   expired at once, so every write woke the event thread (3.4 wake-ups a round
//   in the harness, 2.1 in the controller, counted with perf's sched_wakeup on
//   a fusion case). At 5 ms the writes of a round and of the rounds after it
//   find it armed.
// - heartbeatPeriod 10 ms (0.2 ms before, when every round waited for acks): a
//   heartbeat, and the reader's acknack in answer, every 10 ms while samples are
//   unacknowledged, not every round. 100 ms and 1 s measured no faster.
// - heartbeatResponseDelay 2 ms (reader side): heartbeats arriving within 2 ms
//   are answered by one acknack.
// A sample waits out the suppression before a heartbeat announces it, so an
// acknowledgement, and the repair of a lost sample, take up to about 17 ms
// (5 + 10 + 2), and keep-all histories hold that long of samples (far under
// max_samples). Samples are lost when a UDP datagram is, or when a
// shared-memory port or segment is full; in lockstep a loss is a slower round,
// never a different trace. `rig bench` before / after, same run: process mode
// 169.9 -> 100.4 us a round, the ping-pong floor 97.7 -> 63.8 us
// (docs/speed.md).
//
// `prompt_repair` keeps the timers the project had before (heartbeat 0.2 ms,
// no suppression, an immediate acknack): real-time runs, where a device
// sample repaired 17 ms late is a late sample, and large types (camera frames:
// each spans several shared-memory buffers, a full segment drops fragments,
// and a frame a writer sends a few times a second costs nothing to wake for).
dds::DataWriterQos project_writer_qos(dds::Publisher& publisher, ReliabilityTimers timers) {
    dds::DataWriterQos qos = publisher.get_default_datawriter_qos();
    qos.reliability().kind = dds::RELIABLE_RELIABILITY_QOS;
    qos.history().kind = dds::KEEP_ALL_HISTORY_QOS;
    qos.durability().kind = dds::VOLATILE_DURABILITY_QOS;
    auto& times = qos.reliable_writer_qos().times;
    times.initialHeartbeatDelay = eprosima::fastrtps::Duration_t(0, 1'000'000);
    times.nackResponseDelay = eprosima::fastrtps::Duration_t(0, 0);
    if (timers == ReliabilityTimers::few_wakeups) {
        times.heartbeatPeriod = eprosima::fastrtps::Duration_t(0, 10'000'000);
        times.nackSupressionDuration = eprosima::fastrtps::Duration_t(0, 5'000'000);
    } else {
        times.heartbeatPeriod = eprosima::fastrtps::Duration_t(0, 200'000);
        times.nackSupressionDuration = eprosima::fastrtps::Duration_t(0, 0);
    }
    qos.publish_mode().kind = dds::SYNCHRONOUS_PUBLISH_MODE;
    qos.data_sharing().off();
    return qos;
}

// A type whose bounded serialized size exceeds this (seed 001's CameraFrame:
// 11 MB for up to 2560 x 1440 RGB) gets large-type history memory below. Every
// other type of the project stays far under it (the raw diagnostic type is
// exactly 64 KiB) and keeps Fast DDS's defaults, so nothing about small types changes.
constexpr std::uint32_t kLargeTypeBytes = 64 * 1024;

// The bounded serialized size of a topic's type (encapsulation included).
std::uint32_t max_serialized_size(dds::DomainParticipant& participant, const dds::Topic& topic) {
    const dds::TypeSupport type = participant.find_type(topic.get_type_name());
    return type.empty() ? 0 : type->m_typeSize;
}

// Fast DDS's default history memory (PREALLOCATED_WITH_REALLOC) reserves
// `allocated_samples` payloads (100 by default) of the type's bound up front,
// for the writer and again for each reader. With an 11 MB bound that is 1.1 GB
// an endpoint: a writer and a reader in one process were 2.1 GB resident as
// soon as frames flowed (vision_bench BM_DeliverFrameOverDds,
// docs/seed001-vision.md). One slot up front, more made as frames are in flight
// at once, keeps the payloads at the frames really held (72 MB peak for that
// pair) at the same cost per frame. DYNAMIC_REUSABLE_MEMORY_MODE was measured
// too: 32 MB, but 2.2 ms of CPU a frame instead of 0.16 ms in process (each
// payload allocated and faulted in anew), so the preallocating policy stays.
// Reliability, keep-all, max_samples and thus counted delivery are untouched.
template <class Qos>
void apply_large_type_memory(Qos& qos) {
    qos.resource_limits().allocated_samples = 1;
}

dds::DataReaderQos project_reader_qos(dds::Subscriber& subscriber, ReliabilityTimers timers) {
    dds::DataReaderQos qos = subscriber.get_default_datareader_qos();
    qos.reliability().kind = dds::RELIABLE_RELIABILITY_QOS;
    qos.history().kind = dds::KEEP_ALL_HISTORY_QOS;
    qos.durability().kind = dds::VOLATILE_DURABILITY_QOS;
    qos.reliable_reader_qos().times.heartbeatResponseDelay =
        timers == ReliabilityTimers::few_wakeups ? eprosima::fastrtps::Duration_t(0, 2'000'000)
                                                 : eprosima::fastrtps::Duration_t(0, 0);
    qos.data_sharing().off();
    return qos;
}

// Empties the writer's history before deleting it. Fast DDS 2.9.1's
// StatefulWriter destructor releases the history's changes one by one, taking
// and dropping the writer's mutex for each, while the periodic heartbeat (armed
// while anything is unacknowledged: a reader that died mid-case leaves it so)
// can take that mutex in between and walk a history of released changes; a
// released change's sequence number sends add_gaps_for_holes_in_history_
// counting towards 2^64 with the mutex held, and the destructor never gets it
// back. clear_history removes the changes through the history, under the mutex,
// so the heartbeat sees an empty history. Nothing written is lost: the writer is
// going away, and a tick that needed it was acknowledged (or failed) before.
void delete_writer(dds::Publisher& publisher, dds::DataWriter* writer) {
    if (writer == nullptr) return;
    std::size_t removed = 0;
    writer->clear_history(&removed);
    publisher.delete_datawriter(writer);
}

constexpr std::size_t kPrefixBytes = eprosima::fastrtps::rtps::GuidPrefix_t::size;

std::string hex_prefix(const unsigned char* bytes, std::size_t size) {
    static const char* digits = "0123456789abcdef";
    std::string hex;
    for (std::size_t i = 0; i < size; ++i) {
        hex += digits[bytes[i] >> 4];
        hex += digits[bytes[i] & 0xf];
    }
    return hex;
}

}  // namespace

WriterBase::WriterBase(DdsContext& context, std::string topic_name, dds::Topic* topic, bool counts_as_output)
    : context_(&context), topic_name_(std::move(topic_name)), listener_(context), counts_as_output_(counts_as_output) {
    const std::uint32_t bound = max_serialized_size(context_->participant(), *topic);
    const bool large = bound > kLargeTypeBytes;
    dds::DataWriterQos qos =
        project_writer_qos(context_->publisher(), large ? ReliabilityTimers::prompt_repair : context_->reliability_timers());
    if (large) {
        apply_large_type_memory(qos);
        max_serialized_bytes_ = bound;
    }
    writer_ = context_->publisher().create_datawriter(topic, qos, &listener_, dds::StatusMask::publication_matched());
    if (writer_ == nullptr) throw std::runtime_error("cannot create DDS writer on topic " + topic_name_);
    if (const std::shared_ptr<LocalBus>& bus = context_->local_bus()) {
        type_name_ = topic->get_type_name();
        local_readers_ = &bus->readers_of(topic_name_, type_name_);
        member_dds_readers_ = &bus->dds_readers_of(topic_name_);
        local_member_ = context_->local_bus_member();
        bus->add_writer(topic_name_, type_name_);
    }
    context_->register_writer(this);
}

WriterBase::~WriterBase() {
    if (context_ == nullptr) return;  // detached: the context deleted the DDS writer
    if (local_readers_ != nullptr) context_->local_bus()->remove_writer(topic_name_, type_name_);
    context_->unregister_writer(this);
    delete_writer(context_->publisher(), writer_);
}

void WriterBase::detach() {
    if (local_readers_ != nullptr) context_->local_bus()->remove_writer(topic_name_, type_name_);
    delete_writer(context_->publisher(), writer_);
    writer_ = nullptr;
    context_ = nullptr;
    local_readers_ = nullptr;
}

bool WriterBase::write_raw(void* sample) {
    if (writer_ == nullptr) return false;
    if (max_serialized_bytes_ != 0) {
        // A frame past its type's bound would only fail inside Fast DDS as "write
        // failed" (the serializer runs out of the bound-sized payload); say which
        // bound, before anything is written. Large types only: the size costs
        // a call per write, and small types keep exactly their old path.
        const std::uint32_t size = writer_->get_type()->getSerializedSizeProvider(sample)();
        if (size > max_serialized_bytes_) {
            throw std::runtime_error("DDS write refused on topic " + topic_name_ + ": the sample serializes to " +
                                     std::to_string(size) + " bytes, past its type's bound of " +
                                     std::to_string(max_serialized_bytes_) + " bytes (" +
                                     writer_->get_type().get_type_name() + ")");
        }
    }
    if (local_readers_ != nullptr) {
        // In-process delivery (LocalBus, dds_context.h): the bus's readers hold
        // the sample now. DDS carries it only while a reader off the bus
        // listens: another process's (an observer), or a raw reader here.
        for (ReaderBase* reader : *local_readers_) reader->deliver_local(sample, local_member_);
        if (listener_.off_bus.load(std::memory_order_relaxed) > 0 || *member_dds_readers_ > 0) {
            undelivered_.store(true);
            if (!writer_->write(sample)) return false;
        }
    } else {
        undelivered_.store(true);
        if (!writer_->write(sample)) return false;
    }
    written_.fetch_add(1);
    if (counts_as_output_) context_->note_published();
    return true;
}

bool WriterBase::wait_delivered(std::chrono::milliseconds timeout) {
    const auto ns = std::chrono::duration_cast<std::chrono::nanoseconds>(timeout).count();
    eprosima::fastrtps::Duration_t limit(static_cast<int32_t>(ns / 1'000'000'000),
                                         static_cast<uint32_t>(ns % 1'000'000'000));
    if (writer_ == nullptr || writer_->wait_for_acknowledgments(limit) != ReturnCode_t::RETCODE_OK) return false;
    undelivered_.store(false);
    return true;
}

void ReaderBase::MatchListener::on_data_available(dds::DataReader*) {
    owner.dds_pending_.store(true);
    context.notify_data_arrived();
}

void ReaderBase::MatchListener::on_subscription_matched(dds::DataReader*, const dds::SubscriptionMatchedStatus& status) {
    matched.store(status.current_count);
    context.notify_matching_changed();
}

void WriterBase::MatchListener::on_publication_matched(dds::DataWriter*, const dds::PublicationMatchedStatus& status) {
    // Before the matched count: whoever sees the match counted sees it here too.
    if (const std::shared_ptr<LocalBus>& bus = context.local_bus(); bus && status.current_count_change != 0) {
        // The reader's GUID: its first 12 bytes are its participant's prefix.
        if (!bus->is_member(hex_prefix(status.last_subscription_handle.value, kPrefixBytes))) {
            off_bus.fetch_add(status.current_count_change);
        }
    }
    matched.store(status.current_count);
    context.notify_matching_changed();
}

ReaderBase::ReaderBase(DdsContext& context, std::string topic_name, dds::Topic* topic)
    : context_(&context), topic_name_(std::move(topic_name)), type_name_(topic->get_type_name()), listener_(context, *this) {
    const bool large = max_serialized_size(context_->participant(), *topic) > kLargeTypeBytes;
    dds::DataReaderQos qos =
        project_reader_qos(context_->subscriber(), large ? ReliabilityTimers::prompt_repair : context_->reliability_timers());
    if (large) apply_large_type_memory(qos);
    reader_ = context_->subscriber().create_datareader(
        topic, qos, &listener_, dds::StatusMask::subscription_matched() << dds::StatusMask::data_available());
    if (reader_ == nullptr) throw std::runtime_error("cannot create DDS reader on topic " + topic_name_);
    if (context_->local_bus()) {
        // Off the bus until a typed reader joins it (join_local_bus).
        bus_ = context_->local_bus();
        bus_->add_dds_reader(topic_name_);
        counted_off_bus_ = true;
    }
    context_->register_reader(this);
}

ReaderBase::~ReaderBase() {
    leave_local_bus();
    if (counted_off_bus_) bus_->remove_dds_reader(topic_name_);
    if (context_ == nullptr) return;  // detached: the context deleted the DDS reader
    context_->unregister_reader(this);
    context_->subscriber().delete_datareader(reader_);
}

void ReaderBase::detach() {
    leave_local_bus();
    if (counted_off_bus_) bus_->remove_dds_reader(topic_name_);
    counted_off_bus_ = false;
    context_->subscriber().delete_datareader(reader_);
    reader_ = nullptr;
    context_ = nullptr;
}

void ReaderBase::join_local_bus() {
    if (!counted_off_bus_) return;  // no bus
    bus_->remove_dds_reader(topic_name_);
    counted_off_bus_ = false;
    bus_->add_reader(topic_name_, type_name_, this);
    on_bus_ = true;
}

void ReaderBase::leave_local_bus() {
    if (!on_bus_) return;
    bus_->remove_reader(this);
    on_bus_ = false;  // bus_ stays: queued samples still name their writers by it
}

void ReaderBase::deliver_local(const void*, std::uint32_t) {
    throw std::logic_error("in-process delivery to a reader of " + topic_name_ + " that is not on the bus");
}

bool ReaderBase::wait_for_data(std::chrono::milliseconds timeout) {
    const auto ns = std::chrono::duration_cast<std::chrono::nanoseconds>(timeout).count();
    eprosima::fastrtps::Duration_t limit(static_cast<int32_t>(ns / 1'000'000'000),
                                         static_cast<uint32_t>(ns % 1'000'000'000));
    return reader_ != nullptr && reader_->wait_for_unread_message(limit);
}

namespace {

std::string prefix_of(const eprosima::fastrtps::rtps::GuidPrefix_t& prefix) {
    return hex_prefix(prefix.value, eprosima::fastrtps::rtps::GuidPrefix_t::size);
}

}  // namespace

bool ReaderBase::take_raw(void* sample, std::string* writer_prefix) {
    if (reader_ == nullptr) return false;
    if (on_bus_) {
        // Fast DDS is asked only after its listener said something came; the
        // flag is cleared before asking, so a sample arriving meanwhile sets it again.
        if (!dds_pending_.load()) return false;
        dds_pending_.store(false);
    }
    dds::SampleInfo info;
    while (reader_->take_next_sample(sample, &info) == ReturnCode_t::RETCODE_OK) {
        if (info.valid_data) {
            // The publication handle is the writer's GUID: its first 12 bytes are its participant's prefix.
            unsigned char bytes[kPrefixBytes];
            for (std::size_t i = 0; i < sizeof bytes; ++i) bytes[i] = info.publication_handle.value[i];
            if (on_bus_) {
                // A bus sample that also went over DDS (for an observer) was handed over already.
                if (bus_->is_member(hex_prefix(bytes, sizeof bytes))) continue;
                dds_pending_.store(true);  // more may wait behind this one
            }
            taken_.fetch_add(1);
            if (writer_prefix != nullptr) *writer_prefix = hex_prefix(bytes, sizeof bytes);
            return true;
        }
        // Dispose / unregister notifications are not samples; nobody writes them here.
    }
    return false;
}

std::uint64_t ReaderBase::received_count() const {
    // On a bus: every bus sample was counted as it was handed over; what came
    // over DDS from outside the bus counts once taken.
    if (on_bus_) return local_received_.load(std::memory_order_relaxed) + taken_.load();
    // Read the unread count first: a sample taken in between is then counted in
    // neither, never twice (the count can only be low, and the waiter re-checks).
    const std::uint64_t unread = reader_ != nullptr ? reader_->get_unread_count() : 0;
    return taken_.load() + unread;
}

// Discovery callbacks arrive on Fast DDS's threads; they only append under a lock.
class DdsContext::DiscoveryWatch final : public dds::DomainParticipantListener {
public:
    void on_participant_discovery(dds::DomainParticipant*, eprosima::fastrtps::rtps::ParticipantDiscoveryInfo&& info) override {
        using Status = eprosima::fastrtps::rtps::ParticipantDiscoveryInfo::DISCOVERY_STATUS;
        if (info.status != Status::DISCOVERED_PARTICIPANT && info.status != Status::CHANGED_QOS_PARTICIPANT) return;
        std::lock_guard lock(mutex);
        names[prefix_of(info.info.m_guid.guidPrefix)] = info.info.m_participantName.to_string();
    }
    void on_subscriber_discovery(dds::DomainParticipant*, eprosima::fastrtps::rtps::ReaderDiscoveryInfo&& info) override {
        using Status = eprosima::fastrtps::rtps::ReaderDiscoveryInfo::DISCOVERY_STATUS;
        if (info.status != Status::DISCOVERED_READER && info.status != Status::REMOVED_READER) return;
        add(prefix_of(info.info.guid().guidPrefix), info.info.topicName().to_string(), info.info.typeName().to_string(),
            false, info.status == Status::REMOVED_READER);
    }
    void on_publisher_discovery(dds::DomainParticipant*, eprosima::fastrtps::rtps::WriterDiscoveryInfo&& info) override {
        using Status = eprosima::fastrtps::rtps::WriterDiscoveryInfo::DISCOVERY_STATUS;
        if (info.status != Status::DISCOVERED_WRITER && info.status != Status::REMOVED_WRITER) return;
        add(prefix_of(info.info.guid().guidPrefix), info.info.topicName().to_string(), info.info.typeName().to_string(),
            true, info.status == Status::REMOVED_WRITER);
    }
#if HAVE_SECURITY  // Fast DDS built without its security plugins has no such callback
    void onParticipantAuthentication(dds::DomainParticipant*,
                                     eprosima::fastrtps::rtps::ParticipantAuthenticationInfo&& info) override {
        if (info.status != eprosima::fastrtps::rtps::ParticipantAuthenticationInfo::UNAUTHORIZED_PARTICIPANT) return;
        const std::string prefix = prefix_of(info.guid.guidPrefix);
        std::lock_guard lock(mutex);
        if (std::find(refused.begin(), refused.end(), prefix) == refused.end()) refused.push_back(prefix);
    }
#endif
    void add(std::string prefix, std::string topic, std::string type, bool writer, bool removed) {
        std::lock_guard lock(mutex);
        const auto name = names.find(prefix);
        pending.push_back(DiscoveredEndpoint{name == names.end() ? "?" : name->second, std::move(prefix),
                                             std::move(topic), std::move(type), writer, removed});
    }

    mutable std::mutex mutex;
    std::map<std::string, std::string> names;  // GUID prefix -> participant name
    std::vector<DiscoveredEndpoint> pending;
    std::vector<std::string> refused;  // GUID prefixes whose authentication failed
};

DdsContext::DdsContext(std::uint32_t domain_id, const std::string& participant_name, bool watch_discovery,
                       ReliabilityTimers timers)
    : domain_id_(domain_id), timers_(timers) {
    if (watch_discovery) discovery_ = std::make_unique<DiscoveryWatch>();
    participant_ = create_loopback_participant(domain_id, participant_name, discovery_.get());
    guid_prefix_ = prefix_of(participant_->guid().guidPrefix);
    secured_ = has_dds_security(participant_->get_qos().properties());
    publisher_ = participant_->create_publisher(participant_->get_default_publisher_qos());
    subscriber_ = participant_->create_subscriber(participant_->get_default_subscriber_qos());
    if (publisher_ == nullptr || subscriber_ == nullptr) {
        delete_participant(participant_);
        throw std::runtime_error("cannot create DDS publisher/subscriber for " + participant_name);
    }
}

DdsContext::~DdsContext() {
    // A node declared after its context outlives it: its endpoints lose their
    // DDS entities here, with the participant, and their own destructors then
    // leave the (gone) context alone.
    std::vector<WriterBase*> writers;
    std::vector<ReaderBase*> readers;
    {
        std::lock_guard lock(registry_mutex_);
        writers.swap(writers_);
        readers.swap(readers_);
    }
    for (WriterBase* writer : writers) writer->detach();
    for (ReaderBase* reader : readers) reader->detach();
    delete_participant(participant_);
}

void DdsContext::join_local_bus(std::shared_ptr<LocalBus> bus) {
    {
        std::lock_guard lock(registry_mutex_);
        if (!writers_.empty() || !readers_.empty()) {
            throw std::logic_error("DdsContext::join_local_bus after endpoints were made (participant " + guid_prefix_ + ")");
        }
    }
    bus_member_ = bus->add_member(guid_prefix_);
    bus_ = std::move(bus);
}

bool DdsContext::all_readers_on_local_bus() const {
    if (!bus_) return false;
    std::lock_guard lock(registry_mutex_);
    return std::all_of(readers_.begin(), readers_.end(), [](const ReaderBase* reader) { return reader->on_local_bus(); });
}

std::uint32_t LocalBus::add_member(const std::string& guid_prefix) {
    members_.push_back(guid_prefix);
    return static_cast<std::uint32_t>(members_.size() - 1);
}

bool LocalBus::is_member(const std::string& guid_prefix) const {
    return std::find(members_.begin(), members_.end(), guid_prefix) != members_.end();
}

const std::vector<ReaderBase*>& LocalBus::readers_of(const std::string& topic, const std::string& type) {
    return readers_[{topic, type}];
}

void LocalBus::add_reader(const std::string& topic, const std::string& type, ReaderBase* reader) {
    readers_[{topic, type}].push_back(reader);
}

bool LocalBus::has_writer(const std::string& topic, const std::string& type) const {
    const auto it = writers_.find({topic, type});
    return it != writers_.end() && it->second > 0;
}

void LocalBus::remove_reader(ReaderBase* reader) {
    for (auto& [key, readers] : readers_) readers.erase(std::remove(readers.begin(), readers.end(), reader), readers.end());
}

dds::Topic* DdsContext::topic_for(const std::string& name, dds::TypeSupport (*make_type)()) {
    if (auto it = topics_.find(name); it != topics_.end()) return it->second;
    dds::TypeSupport type = make_type();
    const std::string type_name = type.get_type_name();
    if (participant_->find_type(type_name).empty()) {
        if (type.register_type(participant_) != ReturnCode_t::RETCODE_OK) {
            throw std::runtime_error("cannot register DDS type " + type_name);
        }
    }
    dds::Topic* topic = participant_->create_topic(name, type_name, participant_->get_default_topic_qos());
    if (topic == nullptr) throw std::runtime_error("cannot create DDS topic " + name + " of type " + type_name);
    topics_.emplace(name, topic);
    return topic;
}

namespace {

// A topic type known by name only: serialized samples pass through as bytes.
class RawPayloadType final : public dds::TopicDataType {
public:
    explicit RawPayloadType(const std::string& type_name) {
        setName(type_name.c_str());
        m_typeSize = 64 * 1024;  // enough for any diagnostic sample; larger ones are refused, not truncated
        m_isGetKeyDefined = false;
    }
    bool serialize(void* data, eprosima::fastrtps::rtps::SerializedPayload_t* payload) override {
        const auto& bytes = static_cast<RawSample*>(data)->bytes;
        if (bytes.size() > payload->max_size) return false;
        std::copy(bytes.begin(), bytes.end(), payload->data);
        payload->length = static_cast<std::uint32_t>(bytes.size());
        return true;
    }
    bool deserialize(eprosima::fastrtps::rtps::SerializedPayload_t* payload, void* data) override {
        auto& bytes = static_cast<RawSample*>(data)->bytes;
        bytes.assign(payload->data, payload->data + payload->length);
        return true;
    }
    std::function<std::uint32_t()> getSerializedSizeProvider(void* data) override {
        return [data] { return static_cast<std::uint32_t>(static_cast<RawSample*>(data)->bytes.size()); };
    }
    void* createData() override { return new RawSample(); }
    void deleteData(void* data) override { delete static_cast<RawSample*>(data); }
    bool getKey(void*, eprosima::fastrtps::rtps::InstanceHandle_t*, bool) override { return false; }
};

}  // namespace

dds::Topic* DdsContext::raw_topic(const std::string& name, const std::string& type_name) {
    if (auto it = topics_.find(name); it != topics_.end()) return it->second;
    if (participant_->find_type(type_name).empty()) {
        dds::TypeSupport type(new RawPayloadType(type_name));
        if (type.register_type(participant_) != ReturnCode_t::RETCODE_OK) {
            throw std::runtime_error("cannot register DDS type " + type_name + " (raw, for topic " + name + ")");
        }
    }
    dds::Topic* topic = participant_->create_topic(name, type_name, participant_->get_default_topic_qos());
    if (topic == nullptr) throw std::runtime_error("cannot create DDS topic " + name + " of type " + type_name);
    topics_.emplace(name, topic);
    return topic;
}

std::vector<DiscoveredEndpoint> DdsContext::take_discoveries() {
    std::vector<DiscoveredEndpoint> taken;
    if (!discovery_) return taken;
    std::lock_guard lock(discovery_->mutex);
    for (DiscoveredEndpoint& endpoint : discovery_->pending) {
        if (is_rig_participant(endpoint.guid_prefix)) continue;  // the rig's own endpoints
        // A participant's name may have been announced after its first endpoint.
        if (endpoint.participant == "?") {
            if (const auto name = discovery_->names.find(endpoint.guid_prefix); name != discovery_->names.end()) {
                endpoint.participant = name->second;
            }
        }
        taken.push_back(std::move(endpoint));
    }
    discovery_->pending.clear();
    return taken;
}

bool DdsContext::is_rig_participant(const std::string& guid_prefix) const {
    // Fast DDS prefixes: 2 bytes vendor, 2 bytes host, 4 bytes process, 4 bytes participant.
    // With DDS-Security the prefix is the PKI-DH "adjusted" one instead: its
    // first 6 bytes (47 bits) come from a hash of the certificate's subject, the
    // rest from a hash of the plain prefix, so what a secured participant's
    // prefix says is whose identity it holds: the rig's is the one of ours.
    const std::size_t owner_hex_digits = secured_ ? 12 : 16;
    if (guid_prefix.compare(0, owner_hex_digits, guid_prefix_, 0, owner_hex_digits) != 0) return false;
    std::lock_guard lock(guests_mutex_);
    return std::find(guest_prefixes_.begin(), guest_prefixes_.end(), guid_prefix) == guest_prefixes_.end();
}

void DdsContext::add_guest_participant(const std::string& guid_prefix) {
    std::lock_guard lock(guests_mutex_);
    guest_prefixes_.push_back(guid_prefix);
}

std::vector<std::string> DdsContext::refused_participants() const {
    if (!discovery_) return {};
    std::lock_guard lock(discovery_->mutex);
    return discovery_->refused;
}

std::string DdsContext::participant_name(const std::string& guid_prefix) const {
    if (guid_prefix == guid_prefix_) return participant_->get_qos().name().to_string();
    if (!discovery_) return "?";
    std::lock_guard lock(discovery_->mutex);
    const auto name = discovery_->names.find(guid_prefix);
    return name == discovery_->names.end() ? "?" : name->second;
}

std::map<std::string, std::uint64_t> DdsContext::written_counts() const {
    std::map<std::string, std::uint64_t> counts;
    for (WriterBase* writer : writers()) {
        if (writer->counts_as_output()) counts[writer->topic_name()] += writer->written_count();
    }
    return counts;
}

void DdsContext::notify_data_arrived() {
    {
        std::lock_guard lock(arrival_mutex_);
        ++arrivals_;
    }
    arrival_.notify_all();
}

std::uint64_t DdsContext::arrival_count() {
    std::lock_guard lock(arrival_mutex_);
    return arrivals_;
}

bool DdsContext::wait_for_arrival(std::uint64_t seen, std::chrono::steady_clock::time_point deadline) {
    std::unique_lock lock(arrival_mutex_);
    return arrival_.wait_until(lock, deadline, [&] { return arrivals_ != seen; });
}

void DdsContext::notify_matching_changed() {
    {
        std::lock_guard lock(arrival_mutex_);
        ++matching_changes_;
    }
    matching_.notify_all();
}

std::uint64_t DdsContext::matching_change_count() {
    std::lock_guard lock(arrival_mutex_);
    return matching_changes_;
}

bool DdsContext::wait_for_matching_change(std::uint64_t seen, std::chrono::milliseconds timeout) {
    std::unique_lock lock(arrival_mutex_);
    return matching_.wait_for(lock, timeout, [&] { return matching_changes_ != seen; });
}

std::vector<std::string> DdsContext::wait_received(const std::map<std::string, std::uint64_t>& expected,
                                                   std::chrono::milliseconds timeout) {
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    std::vector<std::string> short_topics;
    for (;;) {
        std::unique_lock lock(arrival_mutex_);
        const std::uint64_t seen = arrivals_;
        lock.unlock();
        short_topics.clear();
        for (ReaderBase* reader : readers()) {
            const auto it = expected.find(reader->topic_name());
            if (it != expected.end() && reader->received_count() < it->second) short_topics.push_back(it->first);
        }
        if (short_topics.empty()) return short_topics;
        lock.lock();
        // Sleep until the next arrival (or the deadline); arrivals since `seen` wake us at once.
        if (!arrival_.wait_until(lock, deadline, [&] { return arrivals_ != seen; })) return short_topics;
    }
}

std::vector<std::string> DdsContext::wait_all_delivered(std::chrono::milliseconds timeout) {
    std::vector<std::string> late;
    // A writer that wrote nothing since its last acknowledged sample has nothing to
    // wait for; skipping it spares a round through Fast DDS per writer per instant.
    for (WriterBase* writer : writers()) {
        if (writer->has_undelivered() && !writer->wait_delivered(timeout)) late.push_back(writer->topic_name());
    }
    return late;
}

void DdsContext::register_writer(WriterBase* writer) {
    std::lock_guard lock(registry_mutex_);
    writers_.push_back(writer);
}
void DdsContext::unregister_writer(WriterBase* writer) {
    std::lock_guard lock(registry_mutex_);
    writers_.erase(std::remove(writers_.begin(), writers_.end(), writer), writers_.end());
}
void DdsContext::register_reader(ReaderBase* reader) {
    std::lock_guard lock(registry_mutex_);
    readers_.push_back(reader);
}
void DdsContext::unregister_reader(ReaderBase* reader) {
    std::lock_guard lock(registry_mutex_);
    readers_.erase(std::remove(readers_.begin(), readers_.end(), reader), readers_.end());
}
std::vector<WriterBase*> DdsContext::writers() const {
    std::lock_guard lock(registry_mutex_);
    return writers_;
}
std::vector<ReaderBase*> DdsContext::readers() const {
    std::lock_guard lock(registry_mutex_);
    return readers_;
}

}  // namespace rig
