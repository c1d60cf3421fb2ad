#pragma once
// Results 0, 1, 2, ... of a pure function of their index, computed in order on
// one thread of their own, up to `depth` ahead of the one the caller takes next
// (a camera's frames: rendering takes tens of milliseconds and what frame k
// shows is fixed in advance, so it is rendered while the run goes on to it).
//
// Why one long-lived thread and not a thread per result: the real-time loop
// runs with its memory locked (mlockall MCL_FUTURE), so every thread it starts
// has its whole stack faulted in and locked by the starting thread, inside the
// loop's pass; and results in order on one thread need no lock around the
// work's own state (a crop map that builds its tiles on first use).
//
// The caller either waits for the next result (lockstep: a frame is published
// at its round, whatever it costs) or asks whether it is ready and comes back
// when `on_ready` says so (real time: a late result is late on its own and
// holds up nothing else). The results are the same either way: each is the
// work's function of its index alone.
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <exception>
#include <functional>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <thread>
#include <utility>

namespace rig {

template <class Result>
class WorkAhead {
public:
    using Work = std::function<Result(std::uint64_t index)>;

    // Starts the thread. `on_thread_start` runs first on it (e.g. leaving the
    // real-time loop's scheduling class, which a new thread inherits);
    // `on_ready` runs on it after each result is stored (e.g. waking the loop).
    // `depth` >= 1 results are held at most; a throwing `work` stops the
    // thread and its exception comes out of the take() of that index.
    WorkAhead(Work work, std::size_t depth, std::function<void()> on_thread_start = {},
              std::function<void()> on_ready = {})
        : work_(std::move(work)), depth_(depth), on_ready_(std::move(on_ready)) {
        if (depth_ == 0) throw std::invalid_argument("WorkAhead: depth must be at least 1");
        thread_ = std::thread([this, start = std::move(on_thread_start)] {
            if (start) start();
            run();
        });
    }
    ~WorkAhead() {
        {
            const std::lock_guard lock(mutex_);
            stopping_ = true;
        }
        changed_.notify_all();
        thread_.join();
    }
    WorkAhead(const WorkAhead&) = delete;
    WorkAhead& operator=(const WorkAhead&) = delete;

    // The index the next take() returns.
    std::uint64_t next_index() const {
        const std::lock_guard lock(mutex_);
        return next_take_;
    }
    // Whether take() would return (or throw) at once.
    bool next_ready() const {
        const std::lock_guard lock(mutex_);
        return !done_.empty() || finished_;
    }
    // Waits until take() would return (or throw) at once.
    void wait_until_next_ready() const {
        std::unique_lock lock(mutex_);
        changed_.wait(lock, [this] { return !done_.empty() || finished_; });
    }
    // The next result, waiting for it if it is not computed yet; rethrows the
    // work's exception for the index that threw. Throws std::logic_error when
    // asked for a result past the one that threw (none will come).
    Result take() {
        std::unique_lock lock(mutex_);
        changed_.wait(lock, [this] { return !done_.empty() || finished_; });
        if (done_.empty()) throw std::logic_error("WorkAhead: no result past the one whose work threw");
        Outcome outcome = std::move(done_.front());
        done_.pop_front();
        ++next_take_;
        lock.unlock();
        changed_.notify_all();  // room for one more ahead
        if (outcome.failure) std::rethrow_exception(outcome.failure);
        return std::move(*outcome.result);
    }

private:
    struct Outcome {
        std::optional<Result> result;
        std::exception_ptr failure;
    };

    void run() {
        for (std::uint64_t index = 0;; ++index) {
            {
                std::unique_lock lock(mutex_);
                changed_.wait(lock, [this] { return stopping_ || done_.size() < depth_; });
                if (stopping_) return;
            }
            Outcome outcome;
            try {
                outcome.result.emplace(work_(index));
            } catch (...) {
                outcome.failure = std::current_exception();
            }
            const bool failed = outcome.failure != nullptr;
            {
                const std::lock_guard lock(mutex_);
                done_.push_back(std::move(outcome));
                finished_ = failed;
            }
            changed_.notify_all();
            if (on_ready_) on_ready_();
            if (failed) return;  // nothing after a failed index is wanted
        }
    }

    Work work_;
    std::size_t depth_;
    std::function<void()> on_ready_;
    mutable std::mutex mutex_;
    mutable std::condition_variable changed_;
    std::deque<Outcome> done_;  // computed, not yet taken, in index order
    std::uint64_t next_take_ = 0;
    bool stopping_ = false;
    bool finished_ = false;  // the work threw: the thread computes nothing more
    std::thread thread_;  // last: started once everything it uses is built
};

}  // namespace rig
