#include "harness/commands/diff_command.h"

#include <CLI/CLI.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <iostream>
#include <limits>
#include <map>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <tuple>

#include <nlohmann/json.hpp>

#include "harness/judge/verdict.h"
#include "harness/output/atomic_file.h"
#include "harness/report/diff_page.h"
#include "harness/systems/systems.h"
#include "harness/trace/trace_diff.h"
#include "rig/text/number_text.h"

namespace rig::harness {

namespace {

namespace fs = std::filesystem;

// A sample longer than this is shown by the fields that differ, or cut.
constexpr std::size_t kShownSampleChars = 200;

// One of the two runs: its trace and, from a run directory, what the run wrote of it.
struct Side {
    std::string label;  // "A" or "B"
    std::string origin;  // what the command line named: the trace, or "DIR, case NAME"
    fs::path trace_file;
    std::optional<nlohmann::json> recorded;  // its entry in the run's results.json
    std::string rig;  // the rig's version and commit from results.json; empty for a bare trace
    RecordedTrace trace;
};

// A `rig run` or `rig sweep` --out directory: the cases it holds, and its
// results.json when it has one (a sweep's, or an interrupted run's, has none).
struct RunDirectory {
    fs::path dir;
    std::optional<nlohmann::json> results;
    std::vector<std::string> case_names;
};

RunDirectory run_directory(const fs::path& dir) {
    RunDirectory run{dir, std::nullopt, {}};
    const fs::path file = dir / "results.json";
    if (fs::exists(file)) {
        std::ifstream in(file);
        nlohmann::json results = nlohmann::json::parse(in, nullptr, /*allow_exceptions=*/false);
        if (results.is_discarded() || !results.is_object() || !results.contains("cases") || !results["cases"].is_array()) {
            throw std::runtime_error(file.string() + ": not a results.json of rig run (no cases list)");
        }
        for (const nlohmann::json& one : results["cases"]) {
            if (one.is_object() && one.contains("name") && one["name"].is_string()) run.case_names.push_back(one["name"]);
        }
        run.results = std::move(results);
        return run;
    }
    if (!fs::is_directory(dir / "cases")) {
        throw std::runtime_error(dir.string() + ": neither a case's directory (trace.sqlite) nor a rig run or sweep "
                                 "--out directory (results.json, cases/)");
    }
    for (const fs::directory_entry& entry : fs::directory_iterator(dir / "cases")) {
        if (fs::is_regular_file(entry.path() / "trace.sqlite")) run.case_names.push_back(entry.path().filename().string());
    }
    std::sort(run.case_names.begin(), run.case_names.end());
    return run;
}

std::string listed(const std::vector<std::string>& names) {
    std::string text;
    for (const std::string& name : names) text += (text.empty() ? "" : ", ") + name;
    return text.empty() ? "none" : text;
}

// The case `name` of a run directory: its trace, and its results.json entry
// and rig when there is one.
Side side_of_run(const std::string& label, const RunDirectory& run, const std::string& name) {
    if (std::find(run.case_names.begin(), run.case_names.end(), name) == run.case_names.end()) {
        throw std::runtime_error(run.dir.string() + ": no case " + name + " in it (its cases: " + listed(run.case_names) +
                                 ")");
    }
    Side side;
    side.label = label;
    side.origin = run.dir.string() + ", case " + name;
    side.trace_file = run.dir / "cases" / name / "trace.sqlite";
    if (!run.results) return side;
    const nlohmann::json& results = *run.results;
    for (const nlohmann::json& one : results["cases"]) {
        if (!one.is_object() || one.value("name", "") != name) continue;
        const std::string relative = one.value("trace_path", "");
        if (!relative.empty()) side.trace_file = run.dir / relative;
        side.recorded = one;
        break;
    }
    if (results.contains("rig") && results["rig"].is_object()) {
        side.rig = results["rig"].value("version", "?") + " (commit " + results["rig"].value("commit", "?") + ")";
    }
    return side;
}

// A trace named directly: a file, or a case's directory holding trace.sqlite.
std::optional<fs::path> trace_named_by(const fs::path& argument) {
    if (!fs::is_directory(argument)) return argument;
    if (fs::exists(argument / "trace.sqlite")) return argument / "trace.sqlite";
    return std::nullopt;
}

// The two sides the command line names, their traces read. Throws
// std::runtime_error naming the argument at fault.
std::pair<Side, Side> sides_of(const std::vector<std::string>& inputs) {
    if (inputs.size() < 2 || inputs.size() > 3) {
        throw std::runtime_error("give two trace files, or two run directories and a case name");
    }
    for (std::size_t i = 0; i < 2; ++i) {
        if (!fs::exists(inputs[i])) throw std::runtime_error(inputs[i] + ": no such file or directory");
    }
    const std::optional<fs::path> a_trace = trace_named_by(inputs[0]);
    const std::optional<fs::path> b_trace = trace_named_by(inputs[1]);
    std::pair<Side, Side> sides;
    if (a_trace && b_trace) {
        if (inputs.size() == 3) {
            throw std::runtime_error("a case name (" + inputs[2] + ") goes with two run directories, not traces");
        }
        sides.first = Side{"A", inputs[0], *a_trace, std::nullopt, "", {}};
        sides.second = Side{"B", inputs[1], *b_trace, std::nullopt, "", {}};
    } else if (!a_trace && !b_trace) {
        const RunDirectory a_run = run_directory(inputs[0]);
        const RunDirectory b_run = run_directory(inputs[1]);
        std::string name = inputs.size() == 3 ? inputs[2] : "";
        if (name.empty()) {
            // Without a name, a run of one case names it.
            if (a_run.case_names.size() == 1) {
                name = a_run.case_names.front();
            } else if (b_run.case_names.size() == 1) {
                name = b_run.case_names.front();
            } else {
                throw std::runtime_error(inputs[0] + " holds the cases " + listed(a_run.case_names) +
                                         ": name the one to compare (rig diff A B CASE)");
            }
        }
        sides.first = side_of_run("A", a_run, name);
        sides.second = side_of_run("B", b_run, name);
    } else {
        throw std::runtime_error((a_trace ? inputs[1] : inputs[0]) + " is a run directory and " +
                                 (a_trace ? inputs[0] : inputs[1]) +
                                 " a trace: give two traces, or two run directories and a case name");
    }
    sides.first.trace = read_trace(sides.first.trace_file);
    sides.second.trace = read_trace(sides.second.trace_file);
    return sides;
}

// Simulated time, exact to the nanosecond and no longer than it needs: "31.42 s".
std::string seconds(TimeNs t_ns) {
    std::string text = fixed_text(static_cast<double>(t_ns) / 1e9, 9);
    while (text.back() == '0') text.pop_back();
    if (text.back() == '.') text.pop_back();
    return text + " s";
}

std::string quoted(const std::string& text) { return "\"" + text + "\""; }

// One fact of both runs: "seed: 2 in both" or "seed: A 2, B 3".
std::string fact_line(const std::string& what, const std::string& a, const std::string& b) {
    if (a == b) return what + ": " + a + " in both\n";
    return what + ": A " + a + ", B " + b + "\n";
}

// The controller a run ran ("/build/bin/rig-controller", "in process: PLUGIN"):
// its command line up to its first option, which leaves out what differs in
// every run (its DDS domain, its case directory).
std::string controller_program(const RecordedTrace& trace) {
    const std::string command = trace.meta_or("controller_command", "?");
    return command.substr(0, command.find(" -"));
}

// What the two runs were: case file, seed, mode, controller, rig. Sets
// `why_different` to the facts that would make the devices or plant part.
std::string facts_text(const Side& a, const Side& b, std::vector<std::string>& why_different) {
    std::string text;
    const RecordedTrace& x = a.trace;
    const RecordedTrace& y = b.trace;
    if (const auto difference = first_case_file_difference(x.meta_or("case_yaml"), y.meta_or("case_yaml"))) {
        text += "case file: differs first at line " + std::to_string(difference->line) +
                (difference->section.empty() ? "" : " (in " + difference->section + ":)") + ": A " +
                quoted(difference->a_line) + ", B " + quoted(difference->b_line) + "\n";
        why_different.push_back("the case files differ");
    } else {
        text += "case file: the same text in both\n";
    }
    if (x.meta_or("case_file") != y.meta_or("case_file")) {
        text += "  (read from " + x.meta_or("case_file") + " and " + y.meta_or("case_file") + ")\n";
    }
    text += fact_line("seed", x.meta_or("seed", "?"), y.meta_or("seed", "?"));
    if (x.meta_or("seed") != y.meta_or("seed")) why_different.push_back("the seeds differ");
    text += fact_line("mode", x.meta_or("mode", "?"), y.meta_or("mode", "?"));
    if (x.meta_or("mode") != y.meta_or("mode")) why_different.push_back("the modes differ");
    if (x.meta_or("mode") == "realtime" || y.meta_or("mode") == "realtime") {
        text += "  (a real-time run's sample times follow the wall clock: two real-time runs part with nothing changed)\n";
    }
    text += fact_line("controller", controller_program(x), controller_program(y));
    if (a.rig.empty() || b.rig.empty()) {
        text += "rig: not known for a bare trace (a run directory's results.json names it)\n";
    } else {
        text += fact_line("rig", a.rig, b.rig);
        if (a.rig != b.rig) why_different.push_back("the rigs differ");
    }
    text += fact_line("outcome", x.meta_or("outcome", "?"), y.meta_or("outcome", "?"));
    return text;
}

std::string role_name(TopicRole role) { return std::string(to_string(role)); }

// Rows of four columns, indented, each column as wide as its widest cell (the
// last one as it is).
std::string table_text(const std::vector<std::array<std::string, 4>>& rows) {
    std::array<std::size_t, 3> widths{};
    for (const auto& row : rows) {
        for (std::size_t column = 0; column < widths.size(); ++column) {
            widths[column] = std::max(widths[column], row[column].size());
        }
    }
    std::string text;
    for (const auto& row : rows) {
        std::string line = " ";
        for (std::size_t column = 0; column < widths.size(); ++column) {
            line += " " + row[column] + std::string(widths[column] - row[column].size() + 1, ' ');
        }
        line += " " + row[3];
        while (line.back() == ' ') line.pop_back();
        text += line + "\n";
    }
    return text;
}

// The first sample where the runs part, who changed, and every topic that parts.
std::string parting_text(const TraceDiff& diff, const std::vector<std::string>& why_different) {
    std::string text;
    const TopicParting* first = diff.first();
    if (first != nullptr) {
        text += "the runs part at t = " + seconds(first->t_ns) + " on " + first->topic + " (" + role_name(first->role) +
                "), its sample " + std::to_string(first->index + 1) + " (A has " + std::to_string(first->a_samples) +
                ", B " + std::to_string(first->b_samples) + ")\n";
        for (const auto& [label, row, run] : {std::tuple{"A", &first->a, Run::a}, std::tuple{"B", &first->b, Run::b}}) {
            if (!*row) {
                text += std::string("  ") + label + ": no more samples of this topic\n";
                continue;
            }
            const ShownSample shown = shown_sample((*row)->json_text, first->differing_fields, run, kShownSampleChars);
            text += std::string("  ") + label + " at t = " + seconds((*row)->t_ns) + ": " + shown.text +
                    (shown.note.empty() ? "" : "  (" + shown.note + ")") + "\n";
        }
        if (!first->differing_fields.empty()) {
            std::string fields;
            for (const FieldDifference& field : first->differing_fields) {
                fields += (fields.empty() ? "" : ", ") + (field.path.empty() ? "the whole value" : field.path);
            }
            if (first->more_differing_fields > 0) fields += " and " + std::to_string(first->more_differing_fields) + " more";
            text += "  differs in: " + fields + "\n";
        } else if (first->a && first->b && first->a->json_text == first->b->json_text) {
            text += "  the same value at another time\n";
        }
    }
    switch (parting_cause(diff)) {
        case PartingCause::none: break;
        case PartingCause::controller:
            text += "who changed: the controller (its " + role_name(first->role) +
                    " topic parts before any device or truth topic)\n";
            break;
        case PartingCause::case_or_rig: {
            std::string because;
            for (const std::string& why : why_different) because += (because.empty() ? "" : ", ") + why;
            text += first != nullptr ? "who changed: the case or the rig, not the controller (a " + role_name(first->role) +
                                           " topic parts before any actuator or controller topic"
                                     : "who changed: the case or the rig, not the controller (every sample agrees, "
                                       "the spray on the ground does not";
            text += because.empty() ? "; case file, seed and mode are the same: the rig changed)\n" : "; " + because + ")\n";
            break;
        }
        case PartingCause::unknown:
            text += "who changed: unknown (the first topic to part is neither the controller's nor the devices' or "
                    "plant's)\n";
            break;
    }
    if (!diff.partings.empty()) {
        const TopicParting* actuator = diff.first_with_role(TopicRole::actuator);
        text += actuator != nullptr
                    ? "first actuator topic to part: " + actuator->topic + " at t = " + seconds(actuator->t_ns) + "\n"
                    : "first actuator topic to part: none (every actuator command is the same)\n";
        text += "topics that part, in order (" + std::to_string(diff.partings.size()) + "):\n";
        std::vector<std::array<std::string, 4>> rows;
        for (const TopicParting& parting : diff.partings) {
            rows.push_back({"t = " + seconds(parting.t_ns), role_name(parting.role), parting.topic,
                            "sample " + std::to_string(parting.index + 1)});
        }
        text += table_text(rows);
        text += "topics the same in both: " + std::to_string(diff.same_topics.size()) + "\n";
    }
    if (diff.deposition_differs || diff.landing_edges_differ) {
        text += std::string("the spray on the ground: ") + (diff.deposition_differs ? "its deposition differs" : "") +
                (diff.deposition_differs && diff.landing_edges_differ ? ", " : "") +
                (diff.landing_edges_differ ? "its landing edges differ" : "") + "\n";
    }
    return text;
}

// A run's metrics: its results.json's when it came from a run directory,
// else judged from the trace as `rig judge` does.
struct RunMetrics {
    std::map<std::string, double> values;  // NaN: not measured
    std::string verdict;
    std::string source;
};

RunMetrics metrics_of(const Side& side) {
    RunMetrics metrics;
    constexpr double kNone = std::numeric_limits<double>::quiet_NaN();
    if (side.recorded) {
        metrics.source = "its results.json";
        const nlohmann::json& entry = *side.recorded;
        if (entry.contains("metrics") && entry["metrics"].is_object()) {
            for (const auto& [name, value] : entry["metrics"].items()) {
                metrics.values[name] = value.is_number() ? value.get<double>() : kNone;
            }
        }
        if (entry.contains("not_measured") && entry["not_measured"].is_object()) {
            for (const auto& item : entry["not_measured"].items()) metrics.values.emplace(item.key(), kNone);
        }
        metrics.verdict = entry.value("verdict", "?");
        return metrics;
    }
    metrics.source = "judged from its trace";
    const CaseRun run = judge_trace(side.trace);
    metrics.values = run.result.metrics;
    for (const auto& item : run.result.not_measured) metrics.values.emplace(item.first, kNone);
    metrics.verdict = case_passed(run.result) ? "passed" : case_invalid(run.result) ? "invalid" : "failed";
    return metrics;
}

std::string metric_text(double value, double other) {
    if (std::isnan(value)) return "not measured";
    if (!std::isfinite(other)) return significant_text(value, 6);
    return significant_text_against(value, other, 6);
}


// Both runs' metrics side by side, each one that differs marked.
std::string metrics_text(const RunMetrics& a, const RunMetrics& b) {
    std::vector<std::array<std::string, 4>> rows{{"metric", "A", "B", ""}};
    std::map<std::string, std::pair<double, double>> both;
    constexpr double kAbsent = std::numeric_limits<double>::quiet_NaN();
    for (const auto& [name, value] : a.values) both[name] = {value, kAbsent};
    for (const auto& [name, value] : b.values) {
        both.emplace(name, std::pair{kAbsent, value}).first->second.second = value;
    }
    for (const auto& [name, values] : both) {
        const auto [x, y] = values;
        const bool same = x == y || (std::isnan(x) && std::isnan(y));
        rows.push_back({name, metric_text(x, y), metric_text(y, x), same ? "" : "differs"});
    }
    rows.push_back({"verdict", a.verdict, b.verdict, a.verdict == b.verdict ? "" : "differs"});
    return "metrics (A: " + a.source + "; B: " + b.source + "):\n" + table_text(rows);
}

// Whether two traces are runs of one case: one system, and the run's name
// or the case file it was read from in common (two seeds of a case with
// `seeds:` run under NAME-seedN).
bool one_case(const RecordedTrace& a, const RecordedTrace& b) {
    if (a.meta_or("system", std::string(kDefaultSystem)) != b.meta_or("system", std::string(kDefaultSystem))) return false;
    return a.meta_or("case") == b.meta_or("case") || a.meta_or("case_file") == b.meta_or("case_file");
}

// When a run's last sample was taken (s).
double last_sample_s(const RecordedTrace& trace) {
    TimeNs last_ns = 0;
    for (const auto& [topic, rows] : trace.rows) {
        if (!rows.empty()) last_ns = std::max(last_ns, rows.back().t_ns);
    }
    return static_cast<double>(last_ns) / 1e9;
}

void write_page(const DiffCommandOptions& options, const Side& a, const Side& b, const TraceDiff& diff,
                const std::string& report_text, std::ostream& out, std::ostream& err) {
    DiffPage page;
    page.case_name = a.trace.meta_or("case");
    page.report_text = report_text;
    page.a_label = a.origin;
    page.b_label = b.origin;
    page.a_signals = key_signals(a.trace);
    page.b_signals = key_signals(b.trace);
    page.a_end_s = last_sample_s(a.trace);
    page.b_end_s = last_sample_s(b.trace);
    if (const TopicParting* first = diff.first()) {
        const double at_s = static_cast<double>(first->t_ns) / 1e9;
        page.parted_at_s = at_s;
        page.parted_topic = first->topic;
        page.from_s = std::max(0.0, at_s - options.window_s);
        page.to_s = at_s + options.window_s;
    } else {
        // Nothing parts: the whole run.
        for (const std::vector<KeySignal>* signals : {&page.a_signals, &page.b_signals}) {
            for (const KeySignal& signal : *signals) {
                if (!signal.points.empty()) page.to_s = std::max(page.to_s, signal.points.back().x);
            }
        }
    }
    const HtmlReport rendered = render_diff_page(page, GnuplotOptions{});
    write_file_atomically(options.html_file, rendered.html);
    for (const std::string& problem : rendered.problems) err << "rig diff: page: " << problem << "\n";
    out << "page: " << options.html_file.string() << "\n";
}

}  // namespace

int run_diff_command(const DiffCommandOptions& options, std::ostream& out, std::ostream& err) {
    std::pair<Side, Side> sides;
    try {
        sides = sides_of(options.inputs);
    } catch (const std::exception& error) {
        err << "rig diff: " << error.what() << "\n";
        return 2;
    }
    const Side& a = sides.first;
    const Side& b = sides.second;
    if (!one_case(a.trace, b.trace)) {
        err << "rig diff: A (" << a.trace_file.string() << ") is a run of case " << a.trace.meta_or("case", "?") << " ("
            << a.trace.meta_or("system", std::string(kDefaultSystem)) << ", " << a.trace.meta_or("case_file", "?")
            << "), B (" << b.trace_file.string() << ") of case " << b.trace.meta_or("case", "?") << " ("
            << b.trace.meta_or("system", std::string(kDefaultSystem)) << ", " << b.trace.meta_or("case_file", "?")
            << "): rig diff compares two runs of one case\n";
        return 2;
    }

    std::string text = "rig diff: case " + a.trace.meta_or("case") + " (" +
                       a.trace.meta_or("system", std::string(kDefaultSystem)) + ")\n";
    text += "  A: " + a.trace_file.string() + "\n  B: " + b.trace_file.string() + "\n";
    std::vector<std::string> why_different;
    text += facts_text(a, b, why_different);
    const TraceDiff diff = diff_traces(a.trace, b.trace);
    if (diff.same()) {
        std::size_t topics = diff.same_topics.size();
        text += "same behaviour: all " + std::to_string(diff.agreeing_samples) + " samples of " + std::to_string(topics) +
                " topics, the spray on the ground and its landing edges are the same in A and B\n";
        if (a.trace.recomputed_sha256 != b.trace.recomputed_sha256) {
            text += "  (the digests differ all the same: the lockstep rounds that delivered the samples differ)\n";
        }
    } else {
        text += parting_text(diff, why_different);
    }
    try {
        text += metrics_text(metrics_of(a), metrics_of(b));
    } catch (const std::exception& error) {
        text += "metrics: not read (" + std::string(error.what()) + ")\n";
    }
    out << text;
    if (!options.html_file.empty()) {
        try {
            write_page(options, a, b, diff, text, out, err);
        } catch (const std::exception& error) {
            err << "rig diff: cannot write the page " << options.html_file.string() << ": " << error.what() << "\n";
            return 2;
        }
    }
    return diff.same() ? 0 : 1;
}

DiffCommand::DiffCommand(CLI::App& app) {
    command_ = app.add_subcommand(
        "diff", "two runs of one case: where they first part (time, topic, values), who changed, and both runs' metrics");
    command_->add_option("a_b_case", options_.inputs, "two trace.sqlite files, or two rig run --out directories and a case name")
        ->required()
        ->expected(2, 3);
    command_->add_option("--html", options_.html_file,
                         "also write this page: the key signals of both runs over each other where they part");
    command_->add_option("--window", options_.window_s, "seconds drawn on either side of that instant (default 5)")
        ->check(CLI::Validator(
            [](std::string& text) -> std::string {
                double seconds = 0.0;
                std::istringstream in(text);
                in >> seconds;
                if (in.fail() || !in.eof() || !(seconds > 0.0) || !std::isfinite(seconds)) {
                    return "must be a number of seconds above 0, got '" + text + "'";
                }
                return {};
            },
            "SECONDS"));
}

bool DiffCommand::parsed() const { return command_->parsed(); }

int DiffCommand::run() { return run_diff_command(options_, std::cout, std::cerr); }

}  // namespace rig::harness
