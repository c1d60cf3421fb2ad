#include "rig/runtime/lockstep.h"

#include <algorithm>
#include <iostream>
#include <set>
#include <map>
#include <sstream>

#include "idl/topics.h"

namespace rig {

namespace {

constexpr std::chrono::milliseconds kPollSlice{50};
// Wall time between copies of the hello while a remote has not answered it.
constexpr std::chrono::milliseconds kHelloRepeat{200};
// Rounds at one instant before we call it a feedback loop between nodes.
constexpr int kMaxRoundsPerInstant = 64;

std::vector<std::string> split_topics(const std::string& joined) {
    std::vector<std::string> topics;
    std::stringstream stream(joined);
    std::string topic;
    while (std::getline(stream, topic, ',')) {
        if (!topic.empty()) topics.push_back(topic);
    }
    return topics;
}

using TopicCounts = std::map<std::string, std::uint64_t>;

// idl/clock.idl bounds the list (32 topics, names of 64 characters): the clock
// samples stay small enough for Fast DDS to deliver them in one message over
// shared memory (at 64 x 128 they were not delivered at all).
constexpr std::size_t kMaxCountedTopics = 32;
constexpr std::size_t kMaxTopicNameLength = 64;

void fill_counts(const TopicCounts& counts, std::vector<msg::TopicCount>& out) {
    if (counts.size() > kMaxCountedTopics) {
        throw std::length_error("lockstep: " + std::to_string(counts.size()) + " topics carry samples, the clock can count " +
                                std::to_string(kMaxCountedTopics) + " (idl/clock.idl)");
    }
    out.clear();
    for (const auto& [topic, samples] : counts) {
        if (topic.size() > kMaxTopicNameLength) {
            throw std::length_error("lockstep: topic name '" + topic + "' is longer than " +
                                    std::to_string(kMaxTopicNameLength) + " characters (idl/clock.idl)");
        }
        msg::TopicCount count;
        count.topic(topic);
        count.samples(samples);
        out.push_back(count);
    }
}

TopicCounts read_counts(const std::vector<msg::TopicCount>& in) {
    TopicCounts counts;
    for (const msg::TopicCount& count : in) counts[count.topic().to_string()] = count.samples();
    return counts;
}

std::string join(const std::vector<std::string>& items) {
    std::string joined;
    for (const auto& item : items) joined += (joined.empty() ? "" : ", ") + item;
    return joined;
}

std::string format_time(TimeNs t) {
    std::ostringstream out;
    out.setf(std::ios::fixed);
    out.precision(3);
    out << ns_to_seconds(t) << " s";
    return out.str();
}

}  // namespace

LockstepMaster::LockstepMaster(DdsContext& dds, LockstepTimeouts timeouts) : dds_(dds), timeouts_(timeouts) {}

LockstepMaster::~LockstepMaster() { shutdown(); }

void LockstepMaster::add_local_node(Node& node) { locals_.push_back(Local{&node, 0}); }

void LockstepMaster::add_remote_node(const std::string& name, std::function<std::optional<std::string>()> liveness) {
    Remote remote;
    remote.name = name;
    remote.liveness = std::move(liveness);
    remotes_.push_back(std::move(remote));
}

void LockstepMaster::add_in_process_node(Node& node, DdsContext& node_dds) {
    Remote remote;
    remote.name = node.name();
    remote.in_process = &node;
    remote.in_process_dds = &node_dds;
    remotes_.push_back(std::move(remote));
}

std::size_t LockstepMaster::process_remote_count() const {
    return static_cast<std::size_t>(
        std::count_if(remotes_.begin(), remotes_.end(), [](const Remote& remote) { return remote.in_process == nullptr; }));
}

void LockstepMaster::wait_in_process_matched(const Remote& remote,
                                             const std::function<void(const std::string&)>& check_startup) {
    // As a follower process before its hello: a reader no one writes is a
    // configuration error, reported with the node's name when the bound passes.
    DdsContext& node_dds = *remote.in_process_dds;
    for (ReaderBase* reader : node_dds.readers()) {
        // A writer on the LocalBus reaches it by hand-off (rig/runtime/dds_context.h).
        if (reader->reached_on_local_bus()) continue;
        for (;;) {
            const std::uint64_t seen = node_dds.matching_change_count();
            if (reader->matched_writers() >= 1) break;
            check_startup("node '" + remote.name + "': a writer for the topic it reads, " + reader->topic_name());
            node_dds.wait_for_matching_change(seen, kPollSlice);
        }
    }
}

void LockstepMaster::start() {
    tick_writer_ = std::make_unique<Writer<msg::ClockTick>>(dds_, topics::kClockTick, false);
    ack_reader_ = std::make_unique<Reader<msg::ClockAck>>(dds_, topics::kClockAck);
    for (Local& local : locals_) local.node->configure(dds_);
    for (Remote& remote : remotes_) {
        if (remote.in_process == nullptr) continue;
        try {
            remote.in_process->configure(*remote.in_process_dds);
            remote.configured = true;
        } catch (const std::exception& error) {
            throw NodeFailure(FailureKind::node_fatal_error, remote.name, std::string("configure failed: ") + error.what());
        }
    }

    const WallStopwatch waited;
    const std::function<void(const std::string&)> check_startup = [&](const std::string& what) {
        if (watchdog_) watchdog_();
        for (const Remote& remote : remotes_) {
            if (auto gone = remote.liveness ? remote.liveness() : std::nullopt) throw NodeFailure(FailureKind::node_exited, remote.name, *gone);
        }
        if (waited.elapsed() > timeouts_.startup) {
            std::string names;
            for (const Remote& remote : remotes_) names += (names.empty() ? "" : ", ") + remote.name;
            throw NodeFailure(FailureKind::startup_timeout, names.empty() ? "harness" : names,
                              what + " not done within " + std::to_string(timeouts_.startup.count()) + " ms");
        }
    };

    if (!remotes_.empty()) {
        const int expected = static_cast<int>(process_remote_count());
        for (;;) {
            // Read before the check: a match in between is then a change seen.
            const std::uint64_t seen = dds_.matching_change_count();
            if (tick_writer_->matched_readers() >= expected && ack_reader_->matched_writers() >= expected) break;
            check_startup("DDS discovery of the clock topics");
            dds_.wait_for_matching_change(seen, kPollSlice);
        }
        for (const Remote& remote : remotes_) {
            if (remote.in_process != nullptr) wait_in_process_matched(remote, check_startup);
        }
        // Hello: seq 0.
        tick_remotes(0, false);
        if (after_hello_) {
            std::vector<HelloTopics> hellos;
            for (const Remote& remote : remotes_) {
                hellos.push_back(HelloTopics{remote.name, remote.subscribed_topics, remote.published_topics});
            }
            after_hello_(hellos);
        }
    }

    // No process to tick and every reader reached by hand-off (software in the
    // loop, rig/runtime/dds_context.h LocalBus): a sample is in its readers when
    // publish returns, so counted delivery holds without counting, and no DDS
    // match need be waited for (discovery goes on, for the role checks and
    // observers, while time runs).
    delivered_at_publish_ = process_remote_count() == 0 && dds_.all_readers_on_local_bus() &&
                            std::all_of(remotes_.begin(), remotes_.end(), [](const Remote& remote) {
                                return remote.in_process_dds->all_readers_on_local_bus();
                            });
    // Every writer must reach every reader of its topic (local ones and the remotes
    // that said they read it) before time starts, or early samples would be lost.
    for (WriterBase* writer : dds_.writers()) {
        if (delivered_at_publish_) break;
        if (writer == tick_writer_.get()) continue;
        int expected = 0;
        for (ReaderBase* reader : dds_.readers()) expected += reader->topic_name() == writer->topic_name();
        for (const Remote& remote : remotes_) {
            expected += static_cast<int>(std::count(remote.subscribed_topics.begin(), remote.subscribed_topics.end(),
                                                    writer->topic_name()));
        }
        for (;;) {
            const std::uint64_t seen = dds_.matching_change_count();
            if (writer->matched_readers() >= expected) break;
            check_startup("matching of topic " + writer->topic_name() + " (" +
                          std::to_string(writer->matched_readers()) + "/" + std::to_string(expected) + " readers)");
            dds_.wait_for_matching_change(seen, kPollSlice);
        }
    }
    // And every local reader must be reached by every writer of its topic: ours
    // (checked above from the writer's side) and the remotes' (from here: a
    // remote only knows that one reader matched its writer, not that all did).
    for (ReaderBase* reader : dds_.readers()) {
        if (delivered_at_publish_) break;
        if (reader == ack_reader_.get()) continue;
        int expected = 0;
        for (WriterBase* writer : dds_.writers()) expected += writer->topic_name() == reader->topic_name();
        for (const Remote& remote : remotes_) {
            expected += static_cast<int>(std::count(remote.published_topics.begin(), remote.published_topics.end(),
                                                    reader->topic_name()));
        }
        for (;;) {
            const std::uint64_t seen = dds_.matching_change_count();
            if (reader->matched_writers() >= expected) break;
            check_startup("matching of topic " + reader->topic_name() + " (" +
                          std::to_string(reader->matched_writers()) + "/" + std::to_string(expected) + " writers)");
            dds_.wait_for_matching_change(seen, kPollSlice);
        }
    }
    for (Local& local : locals_) local.node->activate(0);
    started_ = true;
}

LockstepMaster::TopicCounts LockstepMaster::all_published_counts() const {
    TopicCounts totals = dds_.written_counts();
    for (const Remote& remote : remotes_) {
        for (const auto& [topic, samples] : remote.published_counts) totals[topic] += samples;
    }
    return totals;
}

LockstepMaster::TopicCounts LockstepMaster::reader_counts() const {
    TopicCounts counts;
    for (ReaderBase* reader : dds_.readers()) {
        if (reader != ack_reader_.get()) ++counts[reader->topic_name()];
    }
    for (const Remote& remote : remotes_) {
        for (const std::string& topic : remote.subscribed_topics) ++counts[topic];
    }
    return counts;
}

void LockstepMaster::check_remotes_alive(TimeNs t) const {
    for (const Remote& remote : remotes_) {
        if (auto gone = remote.liveness ? remote.liveness() : std::nullopt) {
            throw NodeFailure(FailureKind::node_exited, remote.name, *gone + " (at t=" + format_time(t) + ")");
        }
    }
}

void LockstepMaster::wait_local_readers(TimeNs t) {
    // In slices, so a remote that died is reported as such rather than as slow.
    const TopicCounts expected = all_published_counts();
    const WallStopwatch waited;
    for (;;) {
        const auto short_topics = dds_.wait_received(expected, kPollSlice);
        if (short_topics.empty()) return;
        if (watchdog_) watchdog_();
        for (const Remote& remote : remotes_) {
            if (auto gone = remote.liveness ? remote.liveness() : std::nullopt) {
                throw NodeFailure(FailureKind::node_exited, remote.name, *gone + " (at t=" + format_time(t) + ")");
            }
        }
        if (waited.elapsed() > timeouts_.delivery) {
            std::string writers;
            for (const Remote& remote : remotes_) writers += (writers.empty() ? "" : ", ") + remote.name;
            throw NodeFailure(FailureKind::delivery_timeout, writers.empty() ? "harness" : writers,
                              "samples on " + join(short_topics) + " did not arrive at the harness at t=" +
                                  format_time(t) + " within " + std::to_string(timeouts_.delivery.count()) + " ms");
        }
    }
}

std::uint32_t LockstepMaster::tick_remotes(TimeNs t, bool shutdown) {
    if (delivered_at_publish_) {
        // Only in-process nodes, and nothing to count (start()): each steps as
        // below, without the tick's counts.
        const std::uint64_t seq = seq_++;
        std::uint32_t published = 0;
        for (Remote& remote : remotes_) published += step_in_process(remote, seq, t, shutdown, no_counts_);
        return published;
    }
    msg::ClockTick tick;
    tick.seq(seq_);
    tick.time_ns(t);
    tick.shutdown(shutdown);
    const TopicCounts published_before = all_published_counts();
    fill_counts(published_before, tick.published_counts());
    if (seq_ == 1) fill_counts(reader_counts(), tick.reader_counts());
    const std::uint64_t seq = seq_++;
    std::size_t outstanding = process_remote_count();
    if (outstanding > 0) tick_writer_->publish(tick);

    const bool hello = seq == 0;
    const auto limit = hello ? timeouts_.startup : timeouts_.ack;
    std::vector<bool> answered(remotes_.size(), false);
    std::uint32_t published = 0;
    // In-process nodes take the tick here, with the counts it carries: they see
    // what a follower process would see, no more (what they publish now is not
    // counted for the processes answering this same tick, as between processes).
    for (std::size_t i = 0; i < remotes_.size(); ++i) {
        if (remotes_[i].in_process == nullptr) continue;
        answered[i] = true;
        published += step_in_process(remotes_[i], seq, t, shutdown, published_before);
    }
    const WallStopwatch waited;
    WallStopwatch since_hello;
    while (outstanding > 0) {
        // The hello again until every remote answered: a reader that matched our
        // writer after the hello was written never gets it (Cyclone DDS starts a
        // volatile reader after the last sample of the writer's first heartbeat,
        // docs/controller-contract.md "Conformance findings"). It carries no time;
        // a remote answers each copy, and the extra answers are ignored below.
        if (hello && since_hello.elapsed() > kHelloRepeat) {
            tick_writer_->publish(tick);
            since_hello = WallStopwatch();
        }
        ack_reader_->wait_for_data(std::min(kPollSlice, limit));
        for (const msg::ClockAck& ack : ack_reader_->take_all()) {
            if (ack.seq() != seq) continue;  // a late answer to an older tick
            for (std::size_t i = 0; i < remotes_.size(); ++i) {
                if (answered[i] || remotes_[i].name != ack.node_name().to_string()) continue;
                if (ack.fatal_error().size() > 0) throw NodeFailure(FailureKind::node_fatal_error, remotes_[i].name, ack.fatal_error().to_string());
                answered[i] = true;
                --outstanding;
                remotes_[i].next_wake_ns = ack.next_wake_ns();
                remotes_[i].published_counts = read_counts(ack.published_counts());
                published += ack.published_count();
                if (hello) {
                    remotes_[i].subscribed_topics = split_topics(ack.subscribed_topics().to_string());
                    remotes_[i].published_topics = split_topics(ack.published_topics().to_string());
                }
            }
        }
        if (outstanding == 0) break;
        if (watchdog_ && !shutdown) watchdog_();
        for (std::size_t i = 0; i < remotes_.size(); ++i) {
            if (answered[i]) continue;
            if (auto gone = remotes_[i].liveness ? remotes_[i].liveness() : std::nullopt) {
                throw NodeFailure(FailureKind::node_exited, remotes_[i].name, *gone + " (waiting for tick " + std::to_string(seq) +
                                                        " at t=" + format_time(t) + ")");
            }
            if (waited.elapsed() > limit) {
                throw NodeFailure(FailureKind::node_unresponsive, remotes_[i].name, "did not acknowledge " +
                                                        std::string(shutdown ? "the shutdown tick" : "tick ") +
                                                        (shutdown ? "" : std::to_string(seq)) + " at t=" +
                                                        format_time(t) + " within " +
                                                        std::to_string(limit.count()) + " ms");
            }
        }
    }
    return published;
}

std::uint32_t LockstepMaster::step_in_process(Remote& remote, std::uint64_t seq, TimeNs t, bool shutdown,
                                              const TopicCounts& published_before) {
    DdsContext& node_dds = *remote.in_process_dds;
    Node& node = *remote.in_process;
    if (seq == 0) {
        // The hello's answer: the topics it reads and writes.
        remote.subscribed_topics.clear();
        remote.published_topics.clear();
        for (ReaderBase* reader : node_dds.readers()) remote.subscribed_topics.push_back(reader->topic_name());
        for (WriterBase* writer : node_dds.writers()) remote.published_topics.push_back(writer->topic_name());
        remote.next_wake_ns = 0;
        return 0;
    }
    if (shutdown) {
        remote.shut_down = true;
        remote.next_wake_ns = kNever;
        try {
            node.shutdown();
        } catch (const std::exception& error) {
            throw NodeFailure(FailureKind::node_fatal_error, remote.name, std::string("shutdown: ") + error.what());
        }
        return 0;
    }
    // Counted delivery, as a follower: everything published so far is in its
    // readers before it takes its inputs.
    const WallStopwatch waited;
    while (!delivered_at_publish_) {
        const auto short_topics = node_dds.wait_received(published_before, kPollSlice);
        if (short_topics.empty()) break;
        if (watchdog_) watchdog_();
        check_remotes_alive(t);
        if (waited.elapsed() > timeouts_.delivery) {
            throw NodeFailure(FailureKind::delivery_timeout, remote.name,
                              "samples on " + join(short_topics) + " published by t=" + format_time(t) +
                                  " did not arrive within " + std::to_string(timeouts_.delivery.count()) + " ms");
        }
    }
    node_dds.take_published_count();
    if (!remote.activated && !delivered_at_publish_) {
        // Its writers reach every reader of their topics before it first
        // publishes (the first tick's reader counts, lockstep.h).
        const TopicCounts readers = reader_counts();
        const WallStopwatch matching;
        for (WriterBase* writer : node_dds.writers()) {
            const auto it = readers.find(writer->topic_name());
            if (it == readers.end()) continue;
            for (;;) {
                const std::uint64_t seen = node_dds.matching_change_count();
                if (static_cast<std::uint64_t>(writer->matched_readers()) >= it->second) break;
                if (watchdog_) watchdog_();
                if (matching.elapsed() > timeouts_.startup) {
                    throw NodeFailure(FailureKind::startup_timeout, remote.name,
                                      "its writer of " + writer->topic_name() + " reached " +
                                          std::to_string(writer->matched_readers()) + " of " +
                                          std::to_string(it->second) + " readers within " +
                                          std::to_string(timeouts_.startup.count()) + " ms");
                }
                node_dds.wait_for_matching_change(seen, kPollSlice);
            }
        }
    }
    try {
        if (!remote.activated) {
            node.activate(t);
            remote.activated = true;
        }
        remote.next_wake_ns = node.step(t);
    } catch (const std::exception& error) {
        throw NodeFailure(FailureKind::node_fatal_error, remote.name, error.what());
    }
    // Counted for the next tick's counts and the master's readers (not
    // needed when everything is delivered at publish).
    if (!delivered_at_publish_) remote.published_counts = node_dds.written_counts();
    return node_dds.take_published_count();
}

std::optional<TimeNs> LockstepMaster::advance(TimeNs until_ns) {
    if (!started_) throw std::logic_error("LockstepMaster::advance before start");
    TimeNs t = kNever;
    for (const Local& local : locals_) t = std::min(t, local.next_wake_ns);
    for (const Remote& remote : remotes_) t = std::min(t, remote.next_wake_ns);
    if (t == kNever || t > until_ns) return std::nullopt;
    t = std::max(t, now_ns_);  // a node asking for the past is due now
    now_ns_ = t;
    for (TruthModel* model : truth_models_) model->advance_to(t);

    for (int round = 0;; ++round) {
        if (round >= kMaxRoundsPerInstant) {
            throw NodeFailure(FailureKind::feedback_loop, "harness", "nodes kept answering each other at t=" + format_time(t) + " for " +
                                             std::to_string(kMaxRoundsPerInstant) + " rounds (a feedback loop)");
        }
        for (Local& local : locals_) {
            const bool due = round == 0 && local.next_wake_ns <= t;
            if (due || local.node->has_unread_input()) local.next_wake_ns = local.node->step(t);
        }
        const std::uint32_t published_by_locals = dds_.take_published_count();

        bool remote_due = false;
        for (const Remote& remote : remotes_) remote_due |= round == 0 && remote.next_wake_ns <= t;
        if (!remotes_.empty() && (remote_due || published_by_locals > 0)) {
            // The tick carries the published counts; each remote waits for its
            // readers to hold them before it steps.
            tick_remotes(t, false);
        }
        // Local readers (the trace, local nodes) hold everything published at t,
        // here and in the remotes, before the round ends.
        if (!delivered_at_publish_) wait_local_readers(t);
        if (after_round_) after_round_(t, round);
        if (watchdog_) watchdog_();
        // Another round only for a local node with input to take: what the
        // remotes published is in the local readers now (wait_local_readers),
        // and a remote is ticked again at t only for what the local nodes
        // publish. A round for the remotes' samples alone stepped no node and
        // recorded nothing (the recorder drained them in this round), so it is
        // not run: continuation-6kmh 7733 -> 7091 rounds, the same trace.
        bool pending = false;
        for (const Local& local : locals_) pending |= local.node->has_unread_input();
        if (!pending) break;
    }
    return t;
}

void LockstepMaster::shutdown(bool after_failure) noexcept {
    if (shut_down_) return;
    shut_down_ = true;
    if (started_ && process_remote_count() > 0) {
        try {
            if (after_failure) {
                msg::ClockTick tick;
                tick.seq(seq_++);
                tick.time_ns(now_ns_);
                tick.shutdown(true);
                tick_writer_->publish(tick);
            } else {
                tick_remotes(now_ns_, true);
            }
        } catch (const std::exception& error) {
            std::cerr << "rig: during shutdown: " << error.what() << "\n";
        }
    }
    // In-process nodes the shutdown tick did not reach (a failed run, or a run
    // with no process to tick) still end like a follower told to stop.
    for (Remote& remote : remotes_) {
        if (remote.in_process == nullptr || !remote.configured || remote.shut_down) continue;
        remote.shut_down = true;
        try {
            remote.in_process->shutdown();
        } catch (const std::exception& error) {
            std::cerr << "rig: shutting down node '" << remote.name << "': " << error.what() << "\n";
        }
    }
    for (auto it = locals_.rbegin(); it != locals_.rend(); ++it) {
        try {
            it->node->shutdown();
        } catch (const std::exception& error) {
            std::cerr << "rig: shutting down node '" << it->node->name() << "': " << error.what() << "\n";
        }
    }
}

FollowerLink::FollowerLink(DdsContext& dds, const FollowerOptions& options)
    : dds_(dds),
      options_(options),
      tick_reader_(std::make_unique<Reader<msg::ClockTick>>(dds, topics::kClockTick)),
      ack_writer_(std::make_unique<Writer<msg::ClockAck>>(dds, topics::kClockAck, false)) {}

bool FollowerLink::wait_matched() {
    // Every reader must have a writer before we say hello: a node reading a topic
    // no one writes is a configuration error the master reports with our name.
    // Writers need no reader yet: a topic a controller writes for its own
    // diagnostics has none until the rig, told of it in the hello, records it;
    // the first tick's reader counts then say whom each writer must reach.
    const WallStopwatch startup;
    for (;;) {
        const std::uint64_t seen = dds_.matching_change_count();
        std::vector<std::string> unmatched;
        for (ReaderBase* reader : dds_.readers()) {
            if (reader->matched_writers() < 1) unmatched.push_back("reads " + reader->topic_name());
        }
        // The clock's own ack writer must reach the master, or the hello is lost.
        if (ack_writer_->matched_readers() < 1) unmatched.push_back("writes " + ack_writer_->topic_name());
        if (unmatched.empty()) return true;
        if (startup.elapsed() > options_.startup_timeout) {
            std::string list;
            for (const auto& item : unmatched) list += (list.empty() ? "" : "; ") + item;
            std::cerr << options_.node_name << ": no DDS counterpart within " << options_.startup_timeout.count()
                      << " ms for: " << list << "\n";
            return false;
        }
        dds_.wait_for_matching_change(seen, kPollSlice);
    }
}

namespace {

// The hello's topic lists are bounded strings (idl/clock.idl); a longer list
// would be cut and the harness would wait for the wrong endpoints.
const std::string& checked_topic_list(const std::string& list, const char* what) {
    constexpr std::size_t kMaxTopicListLength = 1024;
    if (list.size() > kMaxTopicListLength) {
        throw std::length_error(std::string("lockstep hello: the ") + what + " topic list is " +
                                std::to_string(list.size()) + " characters, more than the clock's " +
                                std::to_string(kMaxTopicListLength) + " (idl/clock.idl)");
    }
    return list;
}

}  // namespace

void FollowerLink::ack(std::uint64_t seq, TimeNs next_wake, std::uint32_t published, const std::string& subscribed,
                       const std::string& fatal) {
    msg::ClockAck ack;
    ack.node_name(options_.node_name);
    ack.seq(seq);
    ack.next_wake_ns(next_wake);
    ack.published_count(published);
    fill_counts(dds_.written_counts(), ack.published_counts());
    ack.subscribed_topics(checked_topic_list(subscribed, "subscribed"));
    if (seq == 0) {
        std::string written_topics;
        for (WriterBase* writer : dds_.writers()) {
            if (writer == ack_writer_.get()) continue;
            written_topics += (written_topics.empty() ? "" : ",") + writer->topic_name();
        }
        ack.published_topics(checked_topic_list(written_topics, "published"));
    }
    ack.fatal_error(fatal.substr(0, 500));
    ack_writer_->publish(ack);
}

void FollowerLink::final_ack(std::uint64_t seq, const std::string& fatal) {
    ack(seq, kNever, 0, "", fatal);
    ack_writer_->wait_delivered(options_.delivery_timeout);
}

std::optional<msg::ClockTick> FollowerLink::next_tick(std::chrono::milliseconds timeout) {
    if (pending_.empty()) {
        if (!tick_reader_->wait_for_data(timeout)) return std::nullopt;
        for (msg::ClockTick& tick : tick_reader_->take_all()) pending_.push_back(std::move(tick));
    }
    while (!pending_.empty()) {
        msg::ClockTick tick = std::move(pending_.front());
        pending_.pop_front();
        if (tick.seq() != 0) return tick;
        // Hello: say which topics we read, so the master waits for its writers to reach them.
        std::string subscribed;
        for (ReaderBase* reader : dds_.readers()) {
            if (reader == tick_reader_.get()) continue;
            subscribed += (subscribed.empty() ? "" : ",") + reader->topic_name();
        }
        ack(0, 0, 0, subscribed, "");
    }
    return std::nullopt;
}

bool FollowerLink::harness_present() const { return tick_reader_->matched_writers() > 0; }

std::string FollowerLink::wait_writers_reach_readers(const msg::ClockTick& first_tick) {
    const TopicCounts readers = read_counts(first_tick.reader_counts());
    const WallStopwatch waited;
    for (;;) {
        const std::uint64_t seen = dds_.matching_change_count();
        std::vector<std::string> short_topics;
        for (WriterBase* writer : dds_.writers()) {
            const auto it = readers.find(writer->topic_name());
            if (it == readers.end() || writer == ack_writer_.get()) continue;
            if (static_cast<std::uint64_t>(writer->matched_readers()) < it->second) {
                short_topics.push_back(writer->topic_name() + " (" + std::to_string(writer->matched_readers()) + "/" +
                                       std::to_string(it->second) + " readers)");
            }
        }
        if (short_topics.empty()) return {};
        if (waited.elapsed() > options_.startup_timeout) {
            return "writers did not reach every reader within " + std::to_string(options_.startup_timeout.count()) +
                   " ms: " + join(short_topics);
        }
        dds_.wait_for_matching_change(seen, kPollSlice);
    }
}

std::variant<std::unique_ptr<FollowerLink>, int> start_follower(Node& node, DdsContext& dds,
                                                               const FollowerOptions& options) {
    std::unique_ptr<FollowerLink> link;
    try {
        link = std::make_unique<FollowerLink>(dds, options);
        node.configure(dds);
    } catch (const std::exception& error) {
        std::cerr << options.node_name << ": configure failed: " << error.what() << "\n";
        return 2;
    }
    if (!link->wait_matched()) return 3;
    return link;
}

int run_lockstep_follower(Node& node, DdsContext& dds, ManualClock& clock, const FollowerOptions& options) {
    auto started = start_follower(node, dds, options);
    if (const int* exit_code = std::get_if<int>(&started)) return *exit_code;
    const std::unique_ptr<FollowerLink> link = std::move(std::get<std::unique_ptr<FollowerLink>>(started));

    bool activated = false;
    WallStopwatch idle;
    for (;;) {
        const std::optional<msg::ClockTick> tick = link->next_tick(kPollSlice);
        if (!tick) {
            if (idle.elapsed() > options.idle_timeout) {
                std::cerr << options.node_name << ": no tick from the harness for " << options.idle_timeout.count()
                          << " ms; exiting\n";
                return 4;
            }
            continue;
        }
        idle = WallStopwatch();
        if (tick->shutdown()) {
            node.shutdown();
            link->final_ack(tick->seq(), "");
            return 0;
        }
        if (tick->time_ns() >= options.stall_at_ns) {
            std::cerr << options.node_name << ": stalling at t=" << format_time(tick->time_ns())
                      << " as asked (--stall-at-s)\n";
            for (;;) RealtimeClock().sleep_until_ns(seconds_to_ns(3600.0));  // until the harness kills us
        }
        clock.set_ns(tick->time_ns());
        // Counted delivery: everything published so far must be in our readers
        // before we take our inputs (a sample published at t is seen at t).
        if (const auto short_topics = dds.wait_received(read_counts(tick->published_counts()), options.delivery_timeout);
            !short_topics.empty()) {
            const std::string problem = "samples on " + join(short_topics) + " published by t=" +
                                        format_time(tick->time_ns()) + " did not arrive within " +
                                        std::to_string(options.delivery_timeout.count()) + " ms";
            link->final_ack(tick->seq(), problem);
            std::cerr << options.node_name << ": " << problem << "\n";
            return 5;
        }
        dds.take_published_count();
        TimeNs next_wake = kNever;
        if (!activated) {
            if (const std::string problem = link->wait_writers_reach_readers(*tick); !problem.empty()) {
                link->final_ack(tick->seq(), problem);
                std::cerr << options.node_name << ": " << problem << "\n";
                return 3;
            }
        }
        try {
            if (!activated) {
                node.activate(tick->time_ns());
                activated = true;
            }
            next_wake = node.step(tick->time_ns());
        } catch (const std::exception& error) {
            link->final_ack(tick->seq(), error.what());
            std::cerr << options.node_name << ": " << error.what() << "\n";
            return 2;
        }
        link->ack(tick->seq(), next_wake, dds.take_published_count(), "", "");
    }
}

}  // namespace rig
