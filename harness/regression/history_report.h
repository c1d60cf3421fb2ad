#pragma once
// What `rig history report` writes and `rig history check` says, from a
// history read whole (harness/regression/history_store.h) and its change
// points (harness/regression/history_change_points.h). docs/history.md.
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "harness/regression/history_change_points.h"
#include "harness/regression/history_store.h"

namespace rig::harness {

struct AnalysedSeries {
    const HistorySeries* series = nullptr;
    SeriesChangePoints judged;
};
struct AnalysedBranch {
    const BranchHistory* branch = nullptr;
    std::vector<AnalysedSeries> series;  // as the branch's series
};

// Every series of every branch with its change points (pointers into `history`).
std::vector<AnalysedBranch> analyse_history(const History& history, const ChangePointOptions& options);

// history.json: per branch its commits, and per case and metric every seed's
// value at every commit, the limit, the median, and the change points.
nlohmann::json history_json(const History& history, const std::vector<AnalysedBranch>& analysed,
                            const ChangePointOptions& options);

// history.html: one self-contained page (inline SVG, no script): per branch,
// case and metric with a value, each commit's seeds as points, their median
// as a line, the limit as a red line and the change points marked.
std::string history_html(const History& history, const std::vector<AnalysedBranch>& analysed,
                         const ChangePointOptions& options);

// A change point at the newest commit of a branch, of a metric that can get worse.
struct NewestChange {
    std::string case_name, metric;
    WorseDirection worse = WorseDirection::none;
    ChangePoint change;
    double min_effect = 0.0;
    std::string min_effect_from;
    std::optional<double> limit;  // the case's limit at the newest commit
};

struct HistoryCheck {
    std::string branch;
    HistoryCommit newest;
    std::vector<std::string> checked;     // "case: metric", every metric at the newest commit that can get worse
    std::vector<std::string> never_judged;  // metrics there declared neither better nor worse, or undeclared
    std::vector<NewestChange> worse;      // change points for the worse at the newest commit
    std::vector<NewestChange> other;      // change points at it that are not for the worse
};

// The newest commit of `branch` (empty: the branch of the entry added last)
// judged. Throws std::invalid_argument naming the branches when it has none.
HistoryCheck check_history(const History& history, const std::string& branch, const ChangePointOptions& options);

// The check as text for the terminal: the commit, what was checked, and each
// change point at it with its medians before and after, min effect and limit.
std::string history_check_text(const HistoryCheck& check);

}  // namespace rig::harness
