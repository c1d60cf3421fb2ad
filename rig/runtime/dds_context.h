#pragma once
// One process's DDS entities: a participant from the loopback profile, one
// publisher, one subscriber, and typed Writer<Msg> / Reader<Msg> endpoints whose
// QoS the whole project shares (reliable, keep-all, volatile): a lockstep node
// steps only once its readers hold every sample the tick counts, so nothing
// written may be lost.
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <string>
#include <vector>

#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/DataWriterListener.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/topic/Topic.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>

#include "msg_traits.h"

namespace rig {

namespace dds = eprosima::fastdds::dds;

class DdsContext;

// Fast DDS's reliability timers for a context's endpoints: how soon a lost
// sample is repaired, against how often Fast DDS's event thread is woken
// (the values and measurements: rig/runtime/dds_context.cpp).
enum class ReliabilityTimers {
    // Lockstep: lost samples are rare (SHM) and cost a slower round, never a
    // different trace; waking the event thread for every write cost process
    // mode 40 % of its round.
    few_wakeups,
    // Real time: a lost sample repaired within about a millisecond, as a
    // 100 Hz device needs; its few writes a second make the wake-ups cheap.
    prompt_repair,
};

// An endpoint of another participant on the domain, as discovery reported it
// (rig/runtime/dds_context.cpp). The harness judges roles from these, not from what a
// node says about itself in its hello.
struct DiscoveredEndpoint {
    std::string participant;  // the name the participant announced ("?" if its announcement came later)
    std::string guid_prefix;  // the participant's GUID prefix in hex: two participants of one name differ here
    std::string topic;
    std::string type;
    bool writer = false;      // false: a reader
    bool removed = false;     // the endpoint went away
};

class ReaderBase;

// In-process delivery (software in the loop, docs/speed.md "In-process
// delivery"): when every node of a run lives in one process, the contexts of
// that process share a LocalBus and a sample goes from Writer<Msg>::publish
// straight into the queues of the typed readers of its topic and type on the
// bus, in the order written, before publish returns. Over DDS the same
// samples reach the same readers in the same order (reliable, keep-all, one
// writer per topic and node, counted delivery before each step), so a node
// cannot tell, and lockstep's counted delivery is met the moment publish
// returns. The DDS endpoints stay: discovery still sees every endpoint (the
// harness's role checks), and a writer also writes over DDS while a reader
// outside the bus is matched (an observer on `--domain`, a raw reader of a
// controller's own topic); the bus's readers drop those DDS copies of bus
// samples and still take what writers outside the bus send (a forger's).
// Endpoints join and leave on their context's thread before and after the
// run; delivery runs on the lockstep's one thread, so the bus takes no lock.
class LocalBus {
public:
    // A context joining the bus; returns its index (what a queued sample says of its writer).
    std::uint32_t add_member(const std::string& guid_prefix);
    const std::string& member_prefix(std::uint32_t member) const { return members_.at(member); }
    // Whether a GUID prefix (hex) is a context on this bus.
    bool is_member(const std::string& guid_prefix) const;
    // The bus's typed readers of a topic and type. The list's address stays
    // the same while the bus lives (a writer keeps it).
    const std::vector<ReaderBase*>& readers_of(const std::string& topic, const std::string& type);
    void add_reader(const std::string& topic, const std::string& type, ReaderBase* reader);
    void remove_reader(ReaderBase* reader);
    // Readers of the bus's contexts that are not on it (a raw reader of a
    // controller's own topic): a writer of their topic also writes over DDS.
    // The count's address stays the same while the bus lives.
    const int& dds_readers_of(const std::string& topic) { return dds_readers_[topic]; }
    void add_dds_reader(const std::string& topic) { ++dds_readers_[topic]; }
    void remove_dds_reader(const std::string& topic) { --dds_readers_[topic]; }
    // Writers on the bus per topic and type: a reader of the bus with one
    // needs no DDS match to be reached.
    void add_writer(const std::string& topic, const std::string& type) { ++writers_[{topic, type}]; }
    void remove_writer(const std::string& topic, const std::string& type) { --writers_[{topic, type}]; }
    bool has_writer(const std::string& topic, const std::string& type) const;

private:
    std::vector<std::string> members_;
    // std::map: a node's address stays the same while the bus lives.
    std::map<std::pair<std::string, std::string>, std::vector<ReaderBase*>> readers_;
    std::map<std::string, int> dds_readers_;
    std::map<std::pair<std::string, std::string>, int> writers_;
};

// Endpoint-independent part of a writer, so the context can wait for all of them.
class WriterBase {
public:
    virtual ~WriterBase();
    WriterBase(const WriterBase&) = delete;
    WriterBase& operator=(const WriterBase&) = delete;

    const std::string& topic_name() const { return topic_name_; }
    int matched_readers() const { return listener_.matched.load(); }
    // Blocks until every reader matched now has acknowledged every sample written.
    bool wait_delivered(std::chrono::milliseconds timeout);
    // Written to since the last successful wait_delivered() (only those need waiting for).
    bool has_undelivered() const { return undelivered_.load(); }
    // Samples written since the writer was created.
    std::uint64_t written_count() const { return written_.load(); }
    bool counts_as_output() const { return counts_as_output_; }

protected:
    WriterBase(DdsContext& context, std::string topic_name, dds::Topic* topic, bool counts_as_output);
    bool write_raw(void* sample);

private:
    friend class DdsContext;
    // The context is going away first (a node declared after it): the DDS writer
    // goes with it, and this object only answers "not written" from now on.
    void detach();

    struct MatchListener : dds::DataWriterListener {
        explicit MatchListener(DdsContext& owner) : context(owner) {}
        DdsContext& context;
        std::atomic<int> matched{0};
        // Matched readers of participants not on the context's LocalBus (an observer).
        std::atomic<int> off_bus{0};
        void on_publication_matched(dds::DataWriter*, const dds::PublicationMatchedStatus& status) override;
    };
    DdsContext* context_;  // null once detached
    std::string topic_name_;
    MatchListener listener_;
    dds::DataWriter* writer_ = nullptr;
    bool counts_as_output_;
    // A large type's bound in serialized bytes, checked before each write so a
    // refusal names it (0: a small type, written exactly as before).
    std::uint32_t max_serialized_bytes_ = 0;
    std::atomic<bool> undelivered_{false};
    std::atomic<std::uint64_t> written_{0};
    // In-process delivery (LocalBus): the bus's readers of this topic and
    // type (null: the context has no bus), and this context's index on it.
    const std::vector<ReaderBase*>* local_readers_ = nullptr;
    const int* member_dds_readers_ = nullptr;  // LocalBus::dds_readers_of this topic
    std::uint32_t local_member_ = 0;
    std::string type_name_;
};

// A typed writer on one topic. Each publish() is counted by the context, which is
// how lockstep knows a node produced output during a tick.
template <class Msg>
class Writer final : public WriterBase {
public:
    Writer(DdsContext& context, const std::string& topic_name, bool counts_as_output = true);
    // Throws std::runtime_error when the sample is not written (a large type's
    // sample past its bound says so by name).
    void publish(const Msg& sample) {
        if (!write_raw(const_cast<Msg*>(&sample))) {
            throw std::runtime_error("DDS write failed on topic " + topic_name());
        }
    }
};

class ReaderBase {
public:
    virtual ~ReaderBase();
    ReaderBase(const ReaderBase&) = delete;
    ReaderBase& operator=(const ReaderBase&) = delete;

    const std::string& topic_name() const { return topic_name_; }
    int matched_writers() const { return listener_.matched.load(); }
    // On a bus (LocalBus), what counts is the bus's samples: a sample a writer
    // outside it sent (a forger's) is taken and recorded, but does not make a
    // node due, as it never did for what the lockstep counts.
    bool has_unread() const {
        if (on_bus_) return local_unread_ > 0;
        return reader_ != nullptr && reader_->get_unread_count() > 0;
    }
    // Whether samples of writers on its context's LocalBus reach it by hand-off.
    bool on_local_bus() const { return on_bus_; }
    // On the bus, and a writer on the bus writes its topic: it is reached
    // whatever DDS discovery has matched so far.
    bool reached_on_local_bus() const { return on_bus_ && bus_->has_writer(topic_name_, type_name_); }
    // Samples that have arrived since the reader was created (taken or not).
    std::uint64_t received_count() const;
    // Blocks (wall time) until a sample is available or the timeout passes.
    bool wait_for_data(std::chrono::milliseconds timeout);

protected:
    ReaderBase(DdsContext& context, std::string topic_name, dds::Topic* topic);
    // Takes one sample into `sample`; false when the history is empty. With
    // `writer_prefix`, also says whose participant wrote it (hex GUID prefix).
    // On a bus, the DDS copies of the bus's own samples are dropped here.
    bool take_raw(void* sample, std::string* writer_prefix = nullptr);
    // A typed reader joins its context's LocalBus, if it has one.
    void join_local_bus();
    // A typed reader leaves it before its queue goes (its destructor).
    void leave_local_bus();
    // The bus's hand-off: a copy of `sample` (of this reader's type) queued.
    // Only typed readers join a bus; any other is never handed a sample
    // (std::logic_error if it were).
    virtual void deliver_local(const void* sample, std::uint32_t writer_member);
    // Bookkeeping of the typed queue: samples queued, and taken.
    void note_local_queued() {
        ++local_unread_;
        local_received_.fetch_add(1, std::memory_order_relaxed);
    }
    void note_local_taken(std::size_t samples) { local_unread_ -= samples; }
    std::size_t local_unread() const { return local_unread_; }
    const LocalBus& local_bus() const { return *bus_; }

private:
    friend class DdsContext;
    friend class WriterBase;
    // As WriterBase::detach: the context goes first; nothing arrives any more.
    void detach();

    struct MatchListener : dds::DataReaderListener {
        MatchListener(DdsContext& context_of, ReaderBase& reader) : context(context_of), owner(reader) {}
        DdsContext& context;
        ReaderBase& owner;
        std::atomic<int> matched{0};
        void on_subscription_matched(dds::DataReader*, const dds::SubscriptionMatchedStatus& status) override;
        void on_data_available(dds::DataReader*) override;
    };
    DdsContext* context_;  // null once detached
    std::string topic_name_;
    std::string type_name_;
    MatchListener listener_;
    dds::DataReader* reader_ = nullptr;
    std::atomic<std::uint64_t> taken_{0};
    // In-process delivery (LocalBus).
    std::shared_ptr<LocalBus> bus_;
    bool on_bus_ = false;
    bool counted_off_bus_ = false;  // in the bus's dds_readers_of count
    std::size_t local_unread_ = 0;
    std::atomic<std::uint64_t> local_received_{0};
    // Set by Fast DDS's listener when a DDS sample arrives: on a bus, only
    // then does take_raw ask Fast DDS for samples.
    std::atomic<bool> dds_pending_{false};
};

// A typed reader: take_all() returns every received sample in arrival order
// (per-writer order is preserved by reliable DDS).
//
// On a LocalBus the bus's samples wait in a queue of slots that is reused
// round after round (a slot's buffers are kept for the next sample), and come
// out before any sample a writer outside the bus sent over DDS.
template <class Msg>
class Reader final : public ReaderBase {
public:
    Reader(DdsContext& context, const std::string& topic_name);
    ~Reader() override { leave_local_bus(); }
    std::vector<Msg> take_all() {
        std::vector<Msg> samples;
        samples.reserve(local_unread());
        for (std::size_t i = 0; i < local_unread(); ++i) samples.push_back(std::move(queue_[i].sample));
        note_local_taken(local_unread());
        Msg sample;
        while (take_raw(&sample)) samples.push_back(sample);
        return samples;
    }
    // The same, each with the GUID prefix (hex) of the participant that wrote it.
    std::vector<std::pair<Msg, std::string>> take_all_with_writer() {
        std::vector<std::pair<Msg, std::string>> samples;
        samples.reserve(local_unread());
        for (std::size_t i = 0; i < local_unread(); ++i) {
            samples.emplace_back(std::move(queue_[i].sample), local_bus().member_prefix(queue_[i].writer_member));
        }
        note_local_taken(local_unread());
        Msg sample;
        std::string writer;
        while (take_raw(&sample, &writer)) samples.emplace_back(sample, writer);
        return samples;
    }

private:
    struct Queued {
        Msg sample;
        std::uint32_t writer_member = 0;
    };
    void deliver_local(const void* sample, std::uint32_t writer_member) override {
        const std::size_t slot = local_unread();
        if (slot == queue_.size()) queue_.emplace_back();
        queue_[slot].sample = *static_cast<const Msg*>(sample);
        queue_[slot].writer_member = writer_member;
        note_local_queued();
    }
    std::vector<Queued> queue_;  // the first local_unread() slots hold samples
};

// A sample of a topic whose type the rig does not know (a controller's own
// diagnostic topic): its serialized bytes as they came, encapsulation header
// included. RawReader records them without decoding.
struct RawSample {
    std::vector<unsigned char> bytes;
};

class DdsContext {
public:
    // `watch_discovery`: keep every endpoint other participants create or remove
    // on the domain, for take_discoveries() (the harness's role check).
    DdsContext(std::uint32_t domain_id, const std::string& participant_name, bool watch_discovery = false,
               ReliabilityTimers timers = ReliabilityTimers::few_wakeups);
    ~DdsContext();
    DdsContext(const DdsContext&) = delete;
    DdsContext& operator=(const DdsContext&) = delete;

    std::uint32_t domain_id() const { return domain_id_; }
    // In-process delivery (LocalBus): this context's endpoints hand samples to
    // the bus's other endpoints directly. Only before any endpoint is made
    // (std::logic_error after); contexts share a bus by joining the same one.
    void join_local_bus(std::shared_ptr<LocalBus> bus);
    const std::shared_ptr<LocalBus>& local_bus() const { return bus_; }
    // Every reader of this context is reached by hand-off (on a bus, no raw
    // reader): what was published is in the readers when publish returns,
    // as far as writers on the bus go.
    bool all_readers_on_local_bus() const;
    std::uint32_t local_bus_member() const { return bus_member_; }
    // The timers every endpoint made in this context gets (a large type gets
    // prompt_repair whatever this says).
    ReliabilityTimers reliability_timers() const { return timers_; }
    // This participant's GUID prefix (hex), as Reader::take_all_with_writer reports writers.
    const std::string& guid_prefix() const { return guid_prefix_; }
    // Whether a participant is the rig's own: its GUID prefix is of this process
    // (the first 8 bytes, vendor, host and process, are ours; with DDS-Security,
    // the first 6, which say whose certificate it holds), whichever case or
    // domain it serves, and it is not a guest. Samples and endpoints of the
    // rig's own participants never count as a controller's.
    bool is_rig_participant(const std::string& guid_prefix) const;
    // A participant in this process that is not the rig's: a controller plugin
    // run in process (rig/runtime/node_plugin.h). Its endpoints and samples are
    // judged as a controller process's are.
    void add_guest_participant(const std::string& guid_prefix);
    // Endpoints of participants of other processes discovered or removed since the
    // last call, in the order discovery reported them (empty unless watch_discovery).
    std::vector<DiscoveredEndpoint> take_discoveries();
    // DDS-Security: the GUID prefixes of the participants whose authentication
    // this one refused (no identity, or one the run's CA did not sign), each
    // once, in order (empty unless watch_discovery).
    std::vector<std::string> refused_participants() const;
    // The name a participant announced, by GUID prefix ("?" when unknown).
    std::string participant_name(const std::string& guid_prefix) const;
    dds::DomainParticipant& participant() { return *participant_; }
    dds::Publisher& publisher() { return *publisher_; }
    dds::Subscriber& subscriber() { return *subscriber_; }

    // A topic whose type is only known by name (the rig reads its samples as raw bytes).
    dds::Topic* raw_topic(const std::string& name, const std::string& type_name);

    template <class Msg>
    dds::Topic* topic(const std::string& name) {
        using PubSub = typename MsgTraits<Msg>::PubSubType;
        return topic_for(name, [] { return dds::TypeSupport(new PubSub()); });
    }

    // Samples published (by writers that count as output) since the last call.
    std::uint32_t take_published_count() { return published_count_.exchange(0); }
    void note_published() { published_count_.fetch_add(1); }

    // Per topic, the samples this process's output writers have written so far
    // (the lockstep clock's own writers do not count).
    std::map<std::string, std::uint64_t> written_counts() const;
    // Waits until every reader of a topic in `expected` has received at least that
    // many samples on it (counted delivery, rig/runtime/lockstep.h). Returns the topics
    // still short when the timeout passes (empty = all there).
    std::vector<std::string> wait_received(const std::map<std::string, std::uint64_t>& expected,
                                           std::chrono::milliseconds timeout);
    // Called by readers when data arrives (wakes wait_received and
    // wait_for_arrival); anything else that brings input (a Modbus master's write)
    // may call it too.
    void notify_data_arrived();
    // How many arrivals so far; wait_for_arrival returns once it differs from `seen`.
    std::uint64_t arrival_count();
    // Blocks until an arrival after `seen` or the deadline; true on an arrival.
    bool wait_for_arrival(std::uint64_t seen, std::chrono::steady_clock::time_point deadline);

    // Called by the endpoints' listeners when one of them gains or loses a
    // counterpart: wakes wait_for_matching_change. Start-up waits for matches
    // with it instead of polling: the clock topics' discovery ended 40 ms
    // before a 50 ms poll noticed it, most of a case's start-up.
    void notify_matching_changed();
    // How many matching changes so far; wait_for_matching_change returns once it differs from `seen`.
    std::uint64_t matching_change_count();
    // Blocks until a matching change after `seen` or the timeout; true on a change.
    bool wait_for_matching_change(std::uint64_t seen, std::chrono::milliseconds timeout);

    // Waits until every writer's samples are acknowledged by all matched readers.
    // Returns the topics that did not make it in time (empty = all delivered).
    std::vector<std::string> wait_all_delivered(std::chrono::milliseconds timeout);

    // Registry used by wait_all_delivered and endpoint-matching checks.
    void register_writer(WriterBase* writer);
    void unregister_writer(WriterBase* writer);
    void register_reader(ReaderBase* reader);
    void unregister_reader(ReaderBase* reader);
    std::vector<WriterBase*> writers() const;
    std::vector<ReaderBase*> readers() const;

private:
    dds::Topic* topic_for(const std::string& name, dds::TypeSupport (*make_type)());

    class DiscoveryWatch;
    std::uint32_t domain_id_;
    ReliabilityTimers timers_;
    std::shared_ptr<LocalBus> bus_;
    std::uint32_t bus_member_ = 0;
    std::unique_ptr<DiscoveryWatch> discovery_;  // before participant_: outlives it
    std::string guid_prefix_;
    bool secured_ = false;  // created with a DDS-Security identity (rig/runtime/dds_security.h)
    mutable std::mutex guests_mutex_;
    std::vector<std::string> guest_prefixes_;
    dds::DomainParticipant* participant_ = nullptr;
    dds::Publisher* publisher_ = nullptr;
    dds::Subscriber* subscriber_ = nullptr;
    std::map<std::string, dds::Topic*> topics_;
    std::atomic<std::uint32_t> published_count_{0};
    mutable std::mutex registry_mutex_;
    std::vector<WriterBase*> writers_;
    std::vector<ReaderBase*> readers_;
    std::mutex arrival_mutex_;
    std::condition_variable arrival_;
    std::uint64_t arrivals_ = 0;
    std::condition_variable matching_;  // under arrival_mutex_
    std::uint64_t matching_changes_ = 0;
};

// Reads any topic as raw serialized samples (RawSample), whatever its type.
class RawReader final : public ReaderBase {
public:
    RawReader(DdsContext& context, const std::string& topic_name, const std::string& type_name)
        : ReaderBase(context, topic_name, context.raw_topic(topic_name, type_name)) {}
    std::vector<std::pair<RawSample, std::string>> take_all_with_writer() {
        std::vector<std::pair<RawSample, std::string>> samples;
        RawSample sample;
        std::string writer;
        while (take_raw(&sample, &writer)) samples.emplace_back(sample, writer);
        return samples;
    }
};

template <class Msg>
Writer<Msg>::Writer(DdsContext& context, const std::string& topic_name, bool counts_as_output)
    : WriterBase(context, topic_name, context.topic<Msg>(topic_name), counts_as_output) {}

template <class Msg>
Reader<Msg>::Reader(DdsContext& context, const std::string& topic_name)
    : ReaderBase(context, topic_name, context.topic<Msg>(topic_name)) {
    join_local_bus();
}

}  // namespace rig
