#pragma once
// What `rig run` says while cases run (docs/running-cases.md "Exit status and progress"):
//  * CaseLineLog: one line per case as it ends, "rig: [PASS] NAME (1.2 s wall)",
//    what CI logs and pipes get (and, with --verbose, a line as each starts);
//  * TerminalProgress: on a terminal, the same lines plus a status line kept
//    below them and redrawn in place: which case runs, N of M, the time since
//    the start and an estimate of what is left; a case that publishes its
//    clock (a real-time case runs on it) shows it, "t 12.3/50.0 s".
// And whether to colour: only on a terminal, never when NO_COLOR is set.
#include <cstddef>
#include <deque>
#include <mutex>
#include <optional>
#include <ostream>
#include <string>
#include <thread>
#include <vector>

#include "harness/run/case_runner.h"
#include "rig/runtime/clock.h"

namespace rig::harness {

enum class Verbosity { quiet, normal, verbose };

// Colour (ANSI) on file descriptor `fd`: only when it is a terminal and the
// NO_COLOR environment variable is unset or empty (https://no-color.org).
bool colour_wanted(int fd);

// A line per case as it ends (and with Verbosity::verbose one as it starts);
// Verbosity::quiet says nothing.
class CaseLineLog final : public RunObserver {
public:
    CaseLineLog(std::ostream& out, Verbosity verbosity) : out_(out), verbosity_(verbosity) {}
    void runs_planned(const std::vector<CaseInstance>& runs, const std::vector<CaseSpec>& specs) override;
    void case_started(std::size_t index) override;
    void case_finished(std::size_t index, const CaseResult& result) override;
    CaseClock* case_clock(std::size_t) override { return nullptr; }

private:
    std::ostream& out_;
    Verbosity verbosity_;
    std::mutex mutex_;
    std::vector<std::string> start_lines_;
};

// The line CaseLineLog prints when a case ends.
std::string case_finished_line(const CaseResult& result);

// What the status line shows, at one moment.
struct ProgressSnapshot {
    struct Running {
        std::string name;
        std::size_t ordinal = 0;     // 1-based, in the order cases started
        double elapsed_s = 0.0;      // wall time since it started
        double clock_s = 0.0;        // its published simulated time (0: none yet)
        double end_s = 0.0;          // its length (0: not known)
        bool realtime = false;
    };
    std::size_t total = 0;
    std::size_t finished = 0;
    std::vector<Running> running;  // in start order
    double elapsed_s = 0.0;        // since the run started
    std::optional<double> left_s;  // estimate; none before there is anything to base it on
};

// "rig: [3/12] table2-20lmin-opening93 t 12.3/50.0 s (+1 running) | 0:41 elapsed, about 1:20 left"
// ([N/M]: the case running longest is the Nth to start, of M; t: its clock
// and length; "2/12 done" between cases; "no estimate yet" before one ended),
// cut to `width` characters.
std::string progress_status_line(const ProgressSnapshot& snapshot, std::size_t width);

// What is left, from what ran: each lockstep case still to run or running is
// taken to cost the mean wall time of the lockstep cases that ended (shared by
// `jobs` at once), each real-time case its length on its own clock (they run
// one at a time, and in real time), less what the running ones have done.
// None while a kind that is still to run has nothing to go by yet.
struct CaseToCome {
    bool realtime = false;
    bool running = false;
    double elapsed_s = 0.0;   // running: wall time so far
    double clock_s = 0.0;     // running: its clock
    double length_s = 0.0;    // real time: its length when known (0: not known)
};
std::optional<double> estimate_seconds_left(const std::vector<CaseToCome>& cases, const std::vector<double>& lockstep_walls,
                                            const std::vector<double>& realtime_walls, int jobs);

// The status line on a terminal, redrawn a few times a second by a thread of
// its own, with CaseLineLog's lines printed above it. Stopped and cleared by
// finish() (or the destructor) before the result table is printed.
class TerminalProgress final : public RunObserver {
public:
    // `width`: the terminal's columns; `redraw_on_timer` false draws only when
    // a case starts or ends (for tests: no thread writing to `out`).
    TerminalProgress(std::ostream& out, Verbosity verbosity, int jobs, std::size_t width, bool redraw_on_timer = true);
    ~TerminalProgress() override;
    TerminalProgress(const TerminalProgress&) = delete;
    TerminalProgress& operator=(const TerminalProgress&) = delete;

    void runs_planned(const std::vector<CaseInstance>& runs, const std::vector<CaseSpec>& specs) override;
    void case_started(std::size_t index) override;
    void case_finished(std::size_t index, const CaseResult& result) override;
    CaseClock* case_clock(std::size_t index) override;
    void finish();

private:
    struct Run {
        std::string name;
        bool realtime = false;
        double length_s = 0.0;  // a real-time case's length, known before it runs
        std::optional<WallStopwatch> started;  // wall time since it started
        std::size_t ordinal = 0;
        bool finished = false;
    };
    ProgressSnapshot snapshot_locked() const;
    void redraw_locked();
    void clear_locked();

    std::ostream& out_;
    Verbosity verbosity_;
    int jobs_;
    std::size_t width_;
    bool redraw_on_timer_;
    mutable std::mutex mutex_;
    std::vector<Run> runs_;
    std::deque<CaseClock> clocks_;  // one per run; deque: CaseClock cannot move
    std::vector<double> lockstep_walls_, realtime_walls_;
    std::size_t started_ = 0;
    std::size_t finished_ = 0;
    std::size_t drawn_width_ = 0;
    WallStopwatch run_wall_;
    bool stopping_ = false;
    std::thread ticker_;
};

// The terminal's width in columns (80 when it does not say).
std::size_t terminal_width(int fd);

}  // namespace rig::harness
