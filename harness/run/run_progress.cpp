#include "harness/run/run_progress.h"

#include <sys/ioctl.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <numeric>
#include <sstream>

#include "harness/judge/verdict.h"
#include "harness/systems/systems.h"
#include "rig/text/number_text.h"

namespace rig::harness {

namespace {

// How often the status line is redrawn: often enough that a real-time case's
// clock reads as running, rarely enough to cost nothing.
constexpr std::chrono::milliseconds kRedrawInterval{250};


// "0:41", "12:05", "1:02:03".
std::string minutes_seconds(double seconds) {
    const long total = std::lround(std::max(0.0, seconds));
    char text[32];
    if (total >= 3600) {
        std::snprintf(text, sizeof text, "%ld:%02ld:%02ld", total / 3600, total / 60 % 60, total % 60);
    } else {
        std::snprintf(text, sizeof text, "%ld:%02ld", total / 60, total % 60);
    }
    return text;
}

std::string one_decimal(double value) { return fixed_text(value, 1); }

double mean(const std::vector<double>& values) {
    return std::accumulate(values.begin(), values.end(), 0.0) / static_cast<double>(values.size());
}

std::string start_line(const CaseInstance& run, const CaseSpec& spec) {
    return "rig: start " + run.name + " (seed " + std::to_string(run.seed) + ", " + std::string(to_string(spec.mode)) +
           ", " + spec.source_path.string() + ")\n";
}

}  // namespace

bool colour_wanted(int fd) {
    const char* no_color = std::getenv("NO_COLOR");
    return isatty(fd) != 0 && (no_color == nullptr || no_color[0] == '\0');
}

std::size_t terminal_width(int fd) {
    winsize size{};
    if (ioctl(fd, TIOCGWINSZ, &size) == 0 && size.ws_col > 0) return size.ws_col;
    return 80;
}

std::string case_finished_line(const CaseResult& result) {
    std::ostringstream line;
    line << "rig: [" << verdict_word(result) << "] " << result.name << " (" << result.wall_seconds << " s wall)\n";
    return line.str();
}

// ---------------------------------------------------------------- lines

void CaseLineLog::runs_planned(const std::vector<CaseInstance>& runs, const std::vector<CaseSpec>& specs) {
    for (const CaseInstance& run : runs) start_lines_.push_back(start_line(run, specs[run.spec_index]));
}

void CaseLineLog::case_started(std::size_t index) {
    if (verbosity_ != Verbosity::verbose) return;
    const std::lock_guard lock(mutex_);
    out_ << start_lines_.at(index) << std::flush;
}

void CaseLineLog::case_finished(std::size_t, const CaseResult& result) {
    if (verbosity_ == Verbosity::quiet) return;
    const std::lock_guard lock(mutex_);
    out_ << case_finished_line(result) << std::flush;
}

// ---------------------------------------------------------------- status line

std::string progress_status_line(const ProgressSnapshot& snapshot, std::size_t width) {
    std::string line = "rig: ";
    if (snapshot.running.empty()) {
        line += std::to_string(snapshot.finished) + "/" + std::to_string(snapshot.total) + " done";
    } else {
        const ProgressSnapshot::Running& first = snapshot.running.front();
        line += "[" + std::to_string(first.ordinal) + "/" + std::to_string(snapshot.total) + "] " + first.name;
        if (first.realtime) line += " (real time)";
        if (first.clock_s > 0.0 && first.end_s > 0.0) {
            line += " t " + one_decimal(first.clock_s) + "/" + one_decimal(first.end_s) + " s";
        } else {
            line += " " + minutes_seconds(first.elapsed_s);
        }
        if (snapshot.running.size() > 1) line += " (+" + std::to_string(snapshot.running.size() - 1) + " running)";
    }
    line += " | " + minutes_seconds(snapshot.elapsed_s) + " elapsed";
    line += snapshot.left_s ? ", about " + minutes_seconds(*snapshot.left_s) + " left" : ", no estimate yet";
    if (line.size() > width && width > 0) line.resize(width);
    return line;
}

std::optional<double> estimate_seconds_left(const std::vector<CaseToCome>& cases, const std::vector<double>& lockstep_walls,
                                            const std::vector<double>& realtime_walls, int jobs) {
    double lockstep_left = 0.0;
    double realtime_left = 0.0;
    std::size_t lockstep_to_come = 0;
    for (const CaseToCome& one : cases) {
        if (!one.realtime) {
            if (lockstep_walls.empty()) return std::nullopt;
            const double per_case = mean(lockstep_walls);
            lockstep_left += one.running ? std::max(0.0, per_case - one.elapsed_s) : per_case;
            ++lockstep_to_come;
            continue;
        }
        // A real-time case lasts its length on the wall clock, plus start-up;
        // when neither its length nor another's wall time is known, nothing can be said.
        double length = one.length_s;
        if (length <= 0.0) {
            if (realtime_walls.empty()) return std::nullopt;
            length = mean(realtime_walls);
        }
        realtime_left += one.running ? std::max(0.0, length - (one.clock_s > 0.0 ? one.clock_s : one.elapsed_s))
                                     : length;
    }
    const double parallel = static_cast<double>(std::clamp<std::size_t>(lockstep_to_come, 1, std::max(1, jobs)));
    return lockstep_left / parallel + realtime_left;
}

TerminalProgress::TerminalProgress(std::ostream& out, Verbosity verbosity, int jobs, std::size_t width,
                                   bool redraw_on_timer)
    : out_(out), verbosity_(verbosity), jobs_(jobs), width_(width), redraw_on_timer_(redraw_on_timer) {}

TerminalProgress::~TerminalProgress() { finish(); }

void TerminalProgress::runs_planned(const std::vector<CaseInstance>& runs, const std::vector<CaseSpec>& specs) {
    {
        const std::lock_guard lock(mutex_);
        for (const CaseInstance& instance : runs) {
            const CaseSpec& spec = specs[instance.spec_index];
            Run run;
            run.name = instance.name;
            run.realtime = spec.mode == ClockMode::realtime;
            // A real-time case lasts its route on the wall clock: known before it runs.
            if (run.realtime) {
                try {
                    run.length_s = ns_to_seconds(system_of(spec).plan_run(spec, instance.seed)->end_ns());
                } catch (const std::exception&) {
                    run.length_s = 0.0;  // the run itself will say what is wrong
                }
            }
            runs_.push_back(std::move(run));
            clocks_.emplace_back();
        }
        run_wall_ = WallStopwatch();
    }
    if (!redraw_on_timer_) return;
    ticker_ = std::thread([this] {
        for (;;) {
            {
                const std::lock_guard lock(mutex_);
                if (stopping_) return;
                redraw_locked();
            }
            pause_between_polls(kRedrawInterval);
        }
    });
}

void TerminalProgress::case_started(std::size_t index) {
    const std::lock_guard lock(mutex_);
    Run& run = runs_.at(index);
    run.started = WallStopwatch();
    run.ordinal = ++started_;
    if (verbosity_ == Verbosity::verbose) {
        clear_locked();
        out_ << "rig: start " << run.name << (run.realtime ? " (real time)" : "") << "\n";
    }
    redraw_locked();
}

void TerminalProgress::case_finished(std::size_t index, const CaseResult& result) {
    const std::lock_guard lock(mutex_);
    Run& run = runs_.at(index);
    run.finished = true;
    ++finished_;
    if (result.error_kind != "interrupted") (run.realtime ? realtime_walls_ : lockstep_walls_).push_back(result.wall_seconds);
    clear_locked();
    if (verbosity_ != Verbosity::quiet) out_ << case_finished_line(result);
    redraw_locked();
}

CaseClock* TerminalProgress::case_clock(std::size_t index) {
    const std::lock_guard lock(mutex_);
    return &clocks_.at(index);
}

void TerminalProgress::finish() {
    {
        const std::lock_guard lock(mutex_);
        if (stopping_) return;
        stopping_ = true;
    }
    if (ticker_.joinable()) ticker_.join();
    const std::lock_guard lock(mutex_);
    clear_locked();
}

ProgressSnapshot TerminalProgress::snapshot_locked() const {
    ProgressSnapshot snapshot;
    snapshot.total = runs_.size();
    snapshot.finished = finished_;
    snapshot.elapsed_s = run_wall_.elapsed_s();
    std::vector<CaseToCome> to_come;
    for (std::size_t i = 0; i < runs_.size(); ++i) {
        const Run& run = runs_[i];
        if (run.finished) continue;
        CaseToCome one{run.realtime, run.started.has_value(), 0.0, 0.0, run.length_s};
        if (run.started) {
            ProgressSnapshot::Running running;
            running.name = run.name;
            running.ordinal = run.ordinal;
            running.elapsed_s = run.started->elapsed_s();
            running.clock_s = ns_to_seconds(clocks_[i].now_ns.load(std::memory_order_relaxed));
            running.end_s = ns_to_seconds(clocks_[i].end_ns.load(std::memory_order_relaxed));
            running.realtime = run.realtime;
            one.elapsed_s = running.elapsed_s;
            one.clock_s = running.clock_s;
            if (running.end_s > 0.0) one.length_s = running.end_s;
            snapshot.running.push_back(std::move(running));
        }
        to_come.push_back(one);
    }
    std::sort(snapshot.running.begin(), snapshot.running.end(),
              [](const auto& a, const auto& b) { return a.ordinal < b.ordinal; });
    snapshot.left_s = estimate_seconds_left(to_come, lockstep_walls_, realtime_walls_, jobs_);
    return snapshot;
}

void TerminalProgress::redraw_locked() {
    if (stopping_) return;
    // One column short of the width: a line that fills the last column wraps on some terminals.
    const std::string line = progress_status_line(snapshot_locked(), width_ > 1 ? width_ - 1 : width_);
    // Back to the line's start and over the old text (spaces, not an escape
    // sequence, cover what a longer previous line left).
    out_ << '\r' << line;
    if (drawn_width_ > line.size()) out_ << std::string(drawn_width_ - line.size(), ' ') << '\r' << line;
    out_ << std::flush;
    drawn_width_ = line.size();
}

void TerminalProgress::clear_locked() {
    if (drawn_width_ == 0) return;
    out_ << '\r' << std::string(drawn_width_, ' ') << '\r' << std::flush;
    drawn_width_ = 0;
}

}  // namespace rig::harness
