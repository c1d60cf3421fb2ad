#pragma once
// `rig history`: a controller's metrics over its commits (docs/history.md).
//   rig history add RESULTS --commit SHA [--branch B] [--order N] [--date D] [--replace] --db FILE
//       the runs of a `rig run` or `rig sweep` output (results.json, sweep.json
//       or their directory) as the entry of the commit on the branch (default
//       main), in one SQLite transaction; FILE is made when it does not exist.
//       Exit 0 added, 1 refused (the commit or order is taken on the branch;
//       --replace replaces the commit's entry) or not written (a full disk),
//       the database unchanged; 2 usage or unreadable input.
//   rig history report --db FILE --out DIR
//       DIR/history.html (per branch, case and metric the series over commits,
//       its limit and change points, as inline SVG) and DIR/history.json.
//       Exit 0 written, 1 not written, 2 usage or unreadable database.
//   rig history check --db FILE [--branch B]
//       Exit 1 when the branch's newest commit (default: of the branch added
//       to last) is a change point for the worse of a metric, naming the case,
//       the metric, the medians before and at it and the limit; 0 when it is
//       not, naming the metrics checked; 2 usage or unreadable database.
// report and check take --alpha and --permutations (the change-point test,
// harness/regression/history_change_points.h).
#include <cstdint>
#include <iosfwd>
#include <optional>
#include <string>

#include "harness/cli/subcommand.h"
#include "harness/regression/history_change_points.h"

namespace rig::harness {

struct HistoryAddOptions {
    std::string results;
    std::string database;
    std::string commit;
    std::string branch = "main";
    std::optional<std::int64_t> order;
    std::string date;
    bool replace = false;
};
struct HistoryReportOptions {
    std::string database;
    std::string out_dir;
    ChangePointOptions change_points;
};
struct HistoryCheckOptions {
    std::string database;
    std::string branch;  // empty: the branch of the entry added last
    ChangePointOptions change_points;
};

int run_history_add(const HistoryAddOptions& options, std::ostream& out, std::ostream& err);
int run_history_report(const HistoryReportOptions& options, std::ostream& out, std::ostream& err);
int run_history_check(const HistoryCheckOptions& options, std::ostream& out, std::ostream& err);

class HistoryCommand final : public Subcommand {
public:
    explicit HistoryCommand(CLI::App& app);
    HistoryCommand(const HistoryCommand&) = delete;  // CLI11 holds pointers into the options
    HistoryCommand& operator=(const HistoryCommand&) = delete;
    bool parsed() const override;
    int run() override;

private:
    CLI::App* command_ = nullptr;
    CLI::App* add_ = nullptr;
    CLI::App* report_ = nullptr;
    CLI::App* check_ = nullptr;
    HistoryAddOptions add_options_;
    std::int64_t order_ = -1;
    HistoryReportOptions report_options_;
    HistoryCheckOptions check_options_;
};

}  // namespace rig::harness
