#include "rig/dds_context.h"

#include <algorithm>

#include <fastdds/dds/publisher/qos/DataWriterQos.hpp>
#include <fastdds/dds/subscriber/qos/DataReaderQos.hpp>

#include "rig/participant_factory.h"

namespace rig {

using eprosima::fastrtps::types::ReturnCode_t;

namespace {

// Reliable + keep-all: lockstep acknowledges a tick only after every sample is in
// every reader's history, so nothing may be dropped or overwritten. Volatile:
// endpoints are matched before the first tick (see rig/lockstep.cpp).
dds::DataWriterQos project_writer_qos(dds::Publisher& publisher) {
    dds::DataWriterQos qos = publisher.get_default_datawriter_qos();
    qos.reliability().kind = dds::RELIABLE_RELIABILITY_QOS;
    qos.history().kind = dds::KEEP_ALL_HISTORY_QOS;
    qos.durability().kind = dds::VOLATILE_DURABILITY_QOS;
    // Readers acknowledge in answer to a heartbeat, and wait_for_acknowledgments
    // waits for that: the heartbeat period is the floor of every lockstep round.
    // Fast DDS's default (3 s) would make each tick take seconds; heartbeats are
    // only sent while samples are unacknowledged, so a short period costs nothing idle.
    qos.reliable_writer_qos().times.heartbeatPeriod = eprosima::fastrtps::Duration_t(0, 200'000);
    qos.reliable_writer_qos().times.initialHeartbeatDelay = eprosima::fastrtps::Duration_t(0, 1'000'000);
    qos.reliable_writer_qos().times.nackResponseDelay = eprosima::fastrtps::Duration_t(0, 0);
    qos.publish_mode().kind = dds::SYNCHRONOUS_PUBLISH_MODE;
    qos.data_sharing().off();
    return qos;
}

dds::DataReaderQos project_reader_qos(dds::Subscriber& subscriber) {
    dds::DataReaderQos qos = subscriber.get_default_datareader_qos();
    qos.reliability().kind = dds::RELIABLE_RELIABILITY_QOS;
    qos.history().kind = dds::KEEP_ALL_HISTORY_QOS;
    qos.durability().kind = dds::VOLATILE_DURABILITY_QOS;
    qos.reliable_reader_qos().times.heartbeatResponseDelay = eprosima::fastrtps::Duration_t(0, 0);
    qos.data_sharing().off();
    return qos;
}

}  // namespace

WriterBase::WriterBase(DdsContext& context, std::string topic_name, dds::Topic* topic, bool counts_as_output)
    : context_(context), topic_name_(std::move(topic_name)), counts_as_output_(counts_as_output) {
    writer_ = context_.publisher().create_datawriter(topic, project_writer_qos(context_.publisher()), &listener_,
                                                     dds::StatusMask::publication_matched());
    if (writer_ == nullptr) throw std::runtime_error("cannot create DDS writer on topic " + topic_name_);
    context_.register_writer(this);
}

WriterBase::~WriterBase() {
    context_.unregister_writer(this);
    context_.publisher().delete_datawriter(writer_);
}

bool WriterBase::write_raw(void* sample) {
    undelivered_.store(true);
    if (!writer_->write(sample)) return false;
    written_.fetch_add(1);
    if (counts_as_output_) context_.note_published();
    return true;
}

bool WriterBase::wait_delivered(std::chrono::milliseconds timeout) {
    const auto ns = std::chrono::duration_cast<std::chrono::nanoseconds>(timeout).count();
    eprosima::fastrtps::Duration_t limit(static_cast<int32_t>(ns / 1'000'000'000),
                                         static_cast<uint32_t>(ns % 1'000'000'000));
    if (writer_->wait_for_acknowledgments(limit) != ReturnCode_t::RETCODE_OK) return false;
    undelivered_.store(false);
    return true;
}

void ReaderBase::MatchListener::on_data_available(dds::DataReader*) { context.notify_data_arrived(); }

ReaderBase::ReaderBase(DdsContext& context, std::string topic_name, dds::Topic* topic)
    : context_(context), topic_name_(std::move(topic_name)), listener_(context) {
    reader_ = context_.subscriber().create_datareader(
        topic, project_reader_qos(context_.subscriber()), &listener_,
        dds::StatusMask::subscription_matched() << dds::StatusMask::data_available());
    if (reader_ == nullptr) throw std::runtime_error("cannot create DDS reader on topic " + topic_name_);
    context_.register_reader(this);
}

ReaderBase::~ReaderBase() {
    context_.unregister_reader(this);
    context_.subscriber().delete_datareader(reader_);
}

bool ReaderBase::wait_for_data(std::chrono::milliseconds timeout) {
    const auto ns = std::chrono::duration_cast<std::chrono::nanoseconds>(timeout).count();
    eprosima::fastrtps::Duration_t limit(static_cast<int32_t>(ns / 1'000'000'000),
                                         static_cast<uint32_t>(ns % 1'000'000'000));
    return reader_->wait_for_unread_message(limit);
}

bool ReaderBase::take_raw(void* sample) {
    dds::SampleInfo info;
    while (reader_->take_next_sample(sample, &info) == ReturnCode_t::RETCODE_OK) {
        if (info.valid_data) {
            taken_.fetch_add(1);
            return true;
        }
        // Dispose / unregister notifications are not samples; nobody writes them here.
    }
    return false;
}

std::uint64_t ReaderBase::received_count() const {
    // Read the unread count first: a sample taken in between is then counted in
    // neither, never twice (the count can only be low, and the waiter re-checks).
    const std::uint64_t unread = reader_->get_unread_count();
    return taken_.load() + unread;
}

DdsContext::DdsContext(std::uint32_t domain_id, const std::string& participant_name) : domain_id_(domain_id) {
    participant_ = create_loopback_participant(domain_id, participant_name);
    publisher_ = participant_->create_publisher(participant_->get_default_publisher_qos());
    subscriber_ = participant_->create_subscriber(participant_->get_default_subscriber_qos());
    if (publisher_ == nullptr || subscriber_ == nullptr) {
        delete_participant(participant_);
        throw std::runtime_error("cannot create DDS publisher/subscriber for " + participant_name);
    }
}

DdsContext::~DdsContext() { delete_participant(participant_); }

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
