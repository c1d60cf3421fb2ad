// `rig history` (docs/history.md): the database (add, refuse a commit twice,
// replace, never half-written, never created by a reader), the change points
// (a step of 1.5 standard deviations among 10 seeds a commit is found at its
// commit, series of noise alone give change points at most at the rate alpha
// promises), check's verdict on the newest commit, the report, and the same
// through the `rig` executable on small sweep.json files. No DDS, no clock.
#include <sqlite3.h>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <limits>
#include <numbers>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "harness/commands/history_command.h"
#include "harness/regression/history_change_points.h"
#include "harness/regression/history_report.h"
#include "harness/regression/history_store.h"
#include "run_support.h"

namespace {

namespace fs = std::filesystem;
using namespace rig::harness;
using rig::testing::fresh_dir;
using rig::testing::read_all;
using rig::testing::run_shell;

// Standard normal draws by Box and Muller from the generator's raw bits, the
// same on every standard library.
class Noise {
public:
    explicit Noise(std::uint64_t seed) : generator_(seed) {}
    double normal() {
        const double u1 = (static_cast<double>(generator_() >> 11) + 1.0) * 0x1.0p-53;
        const double u2 = static_cast<double>(generator_() >> 11) * 0x1.0p-53;
        return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * std::numbers::pi * u2);
    }

private:
    std::mt19937_64 generator_;
};

// `commits` groups of `seeds` values, mean 0 and standard deviation 1, the
// groups from `step_at` (0-based) on shifted by `step`.
std::vector<std::vector<double>> noise_series(std::uint64_t seed, std::size_t commits, std::size_t seeds,
                                              std::size_t step_at = SIZE_MAX, double step = 0.0) {
    Noise noise(seed);
    std::vector<std::vector<double>> groups(commits);
    for (std::size_t c = 0; c < commits; ++c) {
        for (std::size_t s = 0; s < seeds; ++s) groups[c].push_back(noise.normal() + (c >= step_at ? step : 0.0));
    }
    return groups;
}

constexpr const char* kTimeMetric = "flow_adjust_time_s";  // worse up, declared min effect 0.05 s
constexpr const char* kFlowMetric = "flow_mean_l_min";      // neither better nor worse

// A sweep's samples of one case: flow_adjust_time_s = 1.0 + 0.1 x values (so 0.1 s per
// standard deviation), limit 1.6 s; flow_mean_l_min steps with it but is never judged.
RunSamples sweep_samples(const std::vector<double>& values, const std::string& started_utc = "") {
    RunSamples samples;
    samples.source = "sweep.json";
    samples.kind = "sweep";
    samples.rig_version = "0.test";
    samples.rig_commit = "abc";
    samples.started_utc = started_utc;
    CaseSamples one;
    one.name = "adjust";
    one.file = "cases/adjust.yaml";
    one.limits[kTimeMetric] = 1.6;
    for (std::size_t s = 0; s < values.size(); ++s) {
        RunSample run;
        run.seed = s + 1;
        run.run = "adjust-seed" + std::to_string(s + 1);
        run.passed = true;
        run.metrics[kTimeMetric] = 1.0 + 0.1 * values[s];
        run.metrics[kFlowMetric] = 4.0 + values[s];
        run.controller_sha256 = "c0ffee";
        one.runs.push_back(run);
    }
    samples.cases.push_back(one);
    return samples;
}

std::string commit_sha(std::size_t index) {
    std::ostringstream text;
    text << std::hex << (0xa000 + index) << "0000";
    return text.str();
}

// A database of the groups as commits 1, 2, ... on branch main.
fs::path history_of(const fs::path& dir, const std::vector<std::vector<double>>& groups) {
    const fs::path database = dir / "history.sqlite";
    fs::remove(database);
    for (std::size_t c = 0; c < groups.size(); ++c) {
        HistoryEntryOptions entry;
        entry.commit = commit_sha(c + 1);
        add_to_history(database, sweep_samples(groups[c]), entry);
    }
    return database;
}

HistoryAddOptions add_options(const fs::path& results, const fs::path& database, const std::string& commit) {
    HistoryAddOptions options;
    options.results = results.string();
    options.database = database.string();
    options.commit = commit;
    return options;
}

std::int64_t entries_in(const fs::path& database) {
    sqlite3* db = nullptr;
    std::int64_t count = -1;
    if (sqlite3_open_v2(database.c_str(), &db, SQLITE_OPEN_READONLY, nullptr) == SQLITE_OK) {
        sqlite3_stmt* statement = nullptr;
        if (sqlite3_prepare_v2(db, "SELECT COUNT(*) FROM entries", -1, &statement, nullptr) == SQLITE_OK &&
            sqlite3_step(statement) == SQLITE_ROW) {
            count = sqlite3_column_int64(statement, 0);
        }
        sqlite3_finalize(statement);
    }
    sqlite3_close(db);
    return count;
}

// --- change points -----------------------------------------------------------

TEST(HistoryChangePoints, AStepOfOneAndAHalfDeviationsAtCommitEightIsFoundThere) {
    // 12 commits x 10 seeds; commit 8 (index 7) on is 1.5 standard deviations higher.
    const auto groups = noise_series(26, 12, 10, 7, 1.5);
    const auto found = find_change_points(groups, WorseDirection::up, 0.5, ChangePointOptions{});
    ASSERT_EQ(found.size(), 1u);
    EXPECT_EQ(found[0].group, 7u);
    EXPECT_TRUE(found[0].worse);
    EXPECT_LE(found[0].p_value, 0.01);
    EXPECT_EQ(found[0].before_values, 70u);
    EXPECT_EQ(found[0].after_values, 50u);
    EXPECT_GT(found[0].shift, 0.5);
    // The same step downwards is a change point, and not for the worse of a metric worse up.
    auto lower = groups;
    for (std::size_t c = 7; c < lower.size(); ++c) {
        for (double& value : lower[c]) value -= 3.0;
    }
    const auto improved = find_change_points(lower, WorseDirection::up, 0.5, ChangePointOptions{});
    ASSERT_EQ(improved.size(), 1u);
    EXPECT_EQ(improved[0].group, 7u);
    EXPECT_FALSE(improved[0].worse);
    EXPECT_TRUE(find_change_points(lower, WorseDirection::down, 0.5, ChangePointOptions{})[0].worse);
}

TEST(HistoryChangePoints, TheStepIsFoundAtItsCommitInNearlyEverySeriesOfNoise) {
    std::size_t exactly_there = 0;
    const std::size_t series = 40;
    for (std::size_t k = 0; k < series; ++k) {
        const auto found = find_change_points(noise_series(1000 + k, 12, 10, 7, 1.5), WorseDirection::up, 0.5,
                                              ChangePointOptions{});
        if (found.size() == 1 && found[0].group == 7 && found[0].worse) ++exactly_there;
    }
    EXPECT_GE(exactly_there, series - 2) << "of " << series;
}

// The newest commit has only its own seeds after the step: with 10 a commit
// the test finds it about 4 times in 5 (measured 156 of 200 series), with 30
// every time; it is found later with more commits after it (the test above).
TEST(HistoryChangePoints, AStepAtTheNewestCommitIsFoundMostlyWithTenSeedsAndAlwaysWithThirty) {
    std::size_t with_ten = 0, with_thirty = 0;
    const std::size_t series = 60;
    for (std::size_t k = 0; k < series; ++k) {
        for (const std::size_t seeds : {std::size_t{10}, std::size_t{30}}) {
            const auto found = find_change_points(noise_series(2000 + k, 8, seeds, 7, 1.5), WorseDirection::up, 0.5,
                                                  ChangePointOptions{});
            if (!found.empty() && found.back().group == 7 && found.back().worse) ++(seeds == 10 ? with_ten : with_thirty);
        }
    }
    EXPECT_GE(with_ten, series * 2 / 3) << "of " << series;
    EXPECT_EQ(with_thirty, series);
}

TEST(HistoryChangePoints, SeriesOfNoiseAloneGiveChangePointsAtMostAtTheRateAlphaPromises) {
    // 300 series of 20 commits x 10 seeds and no step. Without a min effect the
    // test alone stands between noise and a change point: alpha 0.01 promises
    // about 3 of 300 (more than 9 has probability below 0.001 at that rate).
    const std::size_t series = 300;
    std::size_t with_any = 0, with_any_above_min_effect = 0;
    for (std::size_t k = 0; k < series; ++k) {
        const auto groups = noise_series(5000 + k, 20, 10);
        if (!find_change_points(groups, WorseDirection::up, 0.0, ChangePointOptions{}).empty()) ++with_any;
        // With a min effect of half a standard deviation (flow_adjust_time_s's 0.05 s at 0.1 s of noise).
        if (!find_change_points(groups, WorseDirection::up, 0.5, ChangePointOptions{}).empty()) ++with_any_above_min_effect;
    }
    EXPECT_LE(with_any, 9u) << "of " << series;
    EXPECT_LE(with_any_above_min_effect, 3u) << "of " << series;
    // Noise over the commits is not a step at a commit: the first series has none.
    EXPECT_TRUE(find_change_points(noise_series(5000, 20, 10), WorseDirection::up, 0.0, ChangePointOptions{}).empty());
}

TEST(HistoryChangePoints, AShiftSmallerThanTheMinEffectIsNotAChangePoint) {
    const auto groups = noise_series(77, 12, 10, 7, 1.5);
    EXPECT_EQ(find_change_points(groups, WorseDirection::up, 0.5, ChangePointOptions{}).size(), 1u);
    EXPECT_TRUE(find_change_points(groups, WorseDirection::up, 5.0, ChangePointOptions{}).empty());
}

TEST(HistoryChangePoints, TwoStepsAreBothFoundAndRunsThatMeasuredNothingCountAsWorst) {
    auto groups = noise_series(31, 18, 10, 6, 2.0);
    for (std::size_t c = 12; c < groups.size(); ++c) {
        for (double& value : groups[c]) value -= 4.0;
    }
    const auto found = find_change_points(groups, WorseDirection::up, 0.5, ChangePointOptions{});
    ASSERT_EQ(found.size(), 2u);
    EXPECT_EQ(found[0].group, 6u);
    EXPECT_TRUE(found[0].worse);
    EXPECT_EQ(found[1].group, 12u);
    EXPECT_FALSE(found[1].worse);

    // From commit 9 on, every run measured nothing: the worst value for a metric worse up.
    auto unmeasured = noise_series(32, 12, 10);
    for (std::size_t c = 8; c < unmeasured.size(); ++c) {
        for (double& value : unmeasured[c]) value = std::numeric_limits<double>::infinity();
    }
    const auto lost = find_change_points(unmeasured, WorseDirection::up, 0.5, ChangePointOptions{});
    ASSERT_EQ(lost.size(), 1u);
    EXPECT_EQ(lost[0].group, 8u);
    EXPECT_TRUE(lost[0].worse);
    EXPECT_TRUE(std::isinf(lost[0].after_median));
}

TEST(HistoryChangePoints, TheSameSeriesGivesTheSameChangePointsAndIdenticalCommitsNone) {
    const auto groups = noise_series(8, 12, 10, 7, 1.5);
    const auto first = find_change_points(groups, WorseDirection::up, 0.0, ChangePointOptions{});
    const auto second = find_change_points(groups, WorseDirection::up, 0.0, ChangePointOptions{});
    ASSERT_EQ(first.size(), second.size());
    for (std::size_t i = 0; i < first.size(); ++i) {
        EXPECT_EQ(first[i].group, second[i].group);
        EXPECT_EQ(first[i].p_value, second[i].p_value);
    }
    // A deterministic rig gives every commit that left the controller alone the same values.
    const std::vector<std::vector<double>> same(15, noise_series(9, 1, 10)[0]);
    EXPECT_TRUE(find_change_points(same, WorseDirection::up, 0.0, ChangePointOptions{}).empty());
}

// --- the database and check ---------------------------------------------------

TEST(HistoryStore, AddThenAddingTheSameCommitAgainIsRefusedUnlessReplaced) {
    const fs::path dir = fresh_dir("history_store_refuse");
    const fs::path database = dir / "h.sqlite";
    HistoryEntryOptions entry;
    entry.commit = "ABCDEF1";
    const HistoryAdded added = add_to_history(database, sweep_samples({0.0, 1.0}, "2026-11-27T10:00:00Z"), entry);
    EXPECT_TRUE(added.created);
    EXPECT_EQ(added.order, 1);
    EXPECT_EQ(added.date, "2026-11-27T10:00:00Z");
    EXPECT_EQ(added.runs, 2u);
    EXPECT_EQ(added.values, 4u);
    try {
        add_to_history(database, sweep_samples({5.0, 6.0}), entry);
        FAIL() << "the same commit was added twice";
    } catch (const HistoryNotAdded& error) {
        EXPECT_NE(std::string(error.what()).find("commit abcdef1 is already in the history of branch 'main'"),
                  std::string::npos)
            << error.what();
    }
    EXPECT_EQ(entries_in(database), 1);
    // Another branch may have it; --replace keeps its order.
    entry.branch = "feature";
    EXPECT_EQ(add_to_history(database, sweep_samples({0.0}), entry).order, 1);
    entry.branch = "main";
    HistoryEntryOptions second = entry;
    second.commit = "bbbb";
    EXPECT_EQ(add_to_history(database, sweep_samples({0.0}), second).order, 2);
    entry.replace = true;
    const HistoryAdded replaced = add_to_history(database, sweep_samples({5.0, 6.0, 7.0}), entry);
    EXPECT_TRUE(replaced.replaced);
    EXPECT_EQ(replaced.order, 1);
    const History history = read_history(database);
    ASSERT_EQ(history.branches.size(), 2u);
    const BranchHistory& main = history.branches[1];
    ASSERT_EQ(main.branch, "main");
    ASSERT_EQ(main.commits.size(), 2u);
    EXPECT_EQ(main.commits[0].commit, "abcdef1");
    EXPECT_EQ(main.commits[1].commit, "bbbb");
    EXPECT_EQ(history.newest_branch, "main");
    ASSERT_EQ(main.series.size(), 2u);
    EXPECT_EQ(main.series[0].metric, kTimeMetric);
    EXPECT_EQ(main.series[0].points[0].seeds.size(), 3u);
    EXPECT_EQ(main.series[0].points[0].limit, 1.6);
    EXPECT_EQ(main.series[1].metric, kFlowMetric);
    // An order another commit holds is refused.
    HistoryEntryOptions clash;
    clash.commit = "cccc";
    clash.order = 2;
    EXPECT_THROW(add_to_history(database, sweep_samples({0.0}), clash), HistoryNotAdded);
    EXPECT_EQ(entries_in(database), 3);
}

TEST(HistoryStore, BadInputIsRefusedAndNothingIsLeftBehind) {
    const fs::path dir = fresh_dir("history_store_bad");
    HistoryEntryOptions entry;
    entry.commit = "not-a-sha";
    EXPECT_THROW(add_to_history(dir / "h.sqlite", sweep_samples({0.0}), entry), std::invalid_argument);
    entry.commit = "abcd";
    entry.date = "yesterday";
    EXPECT_THROW(add_to_history(dir / "h.sqlite", sweep_samples({0.0}), entry), std::invalid_argument);
    EXPECT_FALSE(fs::exists(dir / "h.sqlite"));
    // A file that is not SQLite, and an SQLite file that is not a history.
    std::ofstream(dir / "text.sqlite") << "just text, long enough to be read as a header by SQLite............\n";
    entry.date.clear();
    try {
        add_to_history(dir / "text.sqlite", sweep_samples({0.0}), entry);
        FAIL() << "a text file took an entry";
    } catch (const HistoryUnreadable& error) {
        EXPECT_NE(std::string(error.what()).find("text.sqlite"), std::string::npos) << error.what();
        EXPECT_NE(std::string(error.what()).find("not a database"), std::string::npos) << error.what();
    }
    {
        sqlite3* db = nullptr;
        ASSERT_EQ(sqlite3_open((dir / "other.sqlite").c_str(), &db), SQLITE_OK);
        ASSERT_EQ(sqlite3_exec(db, "CREATE TABLE t (x)", nullptr, nullptr, nullptr), SQLITE_OK);
        sqlite3_close(db);
    }
    EXPECT_THROW(read_history(dir / "other.sqlite"), HistoryUnreadable);
    EXPECT_THROW(add_to_history(dir / "other.sqlite", sweep_samples({0.0}), entry), HistoryUnreadable);
    // Reading a database that is not there neither fails silently nor makes it.
    EXPECT_THROW(read_history(dir / "missing.sqlite"), HistoryUnreadable);
    EXPECT_FALSE(fs::exists(dir / "missing.sqlite"));
    // A newer schema is refused by name.
    const fs::path database = dir / "h.sqlite";
    add_to_history(database, sweep_samples({0.0}), entry);
    {
        sqlite3* db = nullptr;
        ASSERT_EQ(sqlite3_open(database.c_str(), &db), SQLITE_OK);
        ASSERT_EQ(sqlite3_exec(db, "UPDATE history_schema SET version = 99", nullptr, nullptr, nullptr), SQLITE_OK);
        sqlite3_close(db);
    }
    try {
        read_history(database);
        FAIL() << "schema 99 was read";
    } catch (const HistoryUnreadable& error) {
        EXPECT_NE(std::string(error.what()).find("history schema version 99"), std::string::npos) << error.what();
    }
}

TEST(HistoryCheck, TheNewestCommitAtTheStepIsAChangePointForTheWorse) {
    const fs::path dir = fresh_dir("history_check_step");
    // 30 seeds a commit: one commit's seeds after the step are enough to find it.
    const auto groups = noise_series(26, 12, 30, 7, 1.5);
    // Commits 1 to 8: the newest is the step.
    const fs::path database =
        history_of(dir, std::vector<std::vector<double>>(groups.begin(), groups.begin() + 8));
    const HistoryCheck check = check_history(read_history(database), "", ChangePointOptions{});
    EXPECT_EQ(check.branch, "main");
    EXPECT_EQ(check.newest.commit, commit_sha(8));
    EXPECT_EQ(check.checked, std::vector<std::string>{std::string("adjust: ") + kTimeMetric});
    EXPECT_EQ(check.never_judged, std::vector<std::string>{std::string("adjust: ") + kFlowMetric});
    ASSERT_EQ(check.worse.size(), 1u);
    EXPECT_EQ(check.worse[0].metric, kTimeMetric);
    EXPECT_EQ(check.worse[0].limit, 1.6);
    EXPECT_NEAR(check.worse[0].change.after_median - check.worse[0].change.before_median, 0.15, 0.08);
    // flow_mean_l_min stepped too: a change point, never for the worse.
    ASSERT_EQ(check.other.size(), 1u);
    EXPECT_EQ(check.other[0].metric, kFlowMetric);

    std::ostringstream out, err;
    EXPECT_EQ(run_history_check({database.string(), "", {}}, out, err), 1) << err.str();
    EXPECT_NE(out.str().find("CHANGE POINT FOR THE WORSE at " + commit_sha(8)), std::string::npos) << out.str();
    EXPECT_NE(out.str().find("adjust: flow_adjust_time_s: median "), std::string::npos) << out.str();
    EXPECT_NE(out.str().find("limit 1.6"), std::string::npos) << out.str();

    // Commits 1 to 7 only, and all 12 (the newest is 4 commits past the step): no alarm.
    for (const std::size_t commits : {std::size_t{7}, std::size_t{12}}) {
        const fs::path before = history_of(dir, std::vector<std::vector<double>>(groups.begin(), groups.begin() + commits));
        std::ostringstream quiet_out, quiet_err;
        EXPECT_EQ(run_history_check({before.string(), "", {}}, quiet_out, quiet_err), 0) << quiet_out.str();
        EXPECT_NE(quiet_out.str().find("checked 1 metric that can get worse:\n  adjust: flow_adjust_time_s"),
                  std::string::npos)
            << quiet_out.str();
    }
}

TEST(HistoryCommands, BadInputExitsTwoNamingWhatAndWhere) {
    const fs::path dir = fresh_dir("history_commands_bad");
    std::ostringstream out, err;
    // A results file that is not one.
    std::ofstream(dir / "results.json") << "{\"not\": \"results\"}";
    EXPECT_EQ(run_history_add(add_options(dir / "results.json", dir / "h.sqlite", "abcd"), out, err), 2);
    EXPECT_NE(err.str().find((dir / "results.json").string() + ": top level: no `cases` array"), std::string::npos)
        << err.str();
    EXPECT_FALSE(fs::exists(dir / "h.sqlite"));
    err.str("");
    EXPECT_EQ(run_history_check({(dir / "none.sqlite").string(), "", {}}, out, err), 2);
    EXPECT_NE(err.str().find("none.sqlite: no such history database"), std::string::npos) << err.str();
    err.str("");
    EXPECT_EQ(run_history_report({(dir / "none.sqlite").string(), (dir / "out").string(), {}}, out, err), 2);
    EXPECT_FALSE(fs::exists(dir / "out"));
    // A branch the history does not have.
    const fs::path database = history_of(dir, noise_series(3, 3, 2));
    err.str("");
    EXPECT_EQ(run_history_check({database.string(), "release", {}}, out, err), 2);
    EXPECT_NE(err.str().find("no branch 'release' in it (branches: main)"), std::string::npos) << err.str();
    // The same commit twice exits 1, the database as it was.
    std::ofstream(dir / "sweep.json") << R"({"cases": [{"name": "c", "seeds": [{"seed": 1, "metrics": {"missed_m": 0.1}}]}]})";
    err.str("");
    EXPECT_EQ(run_history_add(add_options(dir / "sweep.json", database, commit_sha(3)), out, err), 1);
    EXPECT_NE(err.str().find("is already in the history"), std::string::npos) << err.str();
    EXPECT_EQ(entries_in(database), 3);
}

TEST(HistoryReport, WritesThePlotsAndTheSeriesTheSameEachTime) {
    const fs::path dir = fresh_dir("history_report");
    const fs::path database = history_of(dir, noise_series(26, 12, 10, 7, 1.5));
    std::ostringstream out, err;
    ASSERT_EQ(run_history_report({database.string(), (dir / "first").string(), {}}, out, err), 0) << err.str();
    ASSERT_EQ(run_history_report({database.string(), (dir / "second").string(), {}}, out, err), 0) << err.str();
    const std::string html = read_all(dir / "first" / "history.html");
    EXPECT_EQ(html, read_all(dir / "second" / "history.html"));
    EXPECT_EQ(read_all(dir / "first" / "history.json"), read_all(dir / "second" / "history.json"));
    EXPECT_EQ(html.find("<script"), std::string::npos);
    EXPECT_NE(html.find("<svg"), std::string::npos);
    EXPECT_NE(html.find("class=\"limit\""), std::string::npos);
    EXPECT_NE(html.find("class=\"change worse\""), std::string::npos);
    EXPECT_NE(html.find("Change point at " + commit_sha(8)), std::string::npos);

    const nlohmann::json json = nlohmann::json::parse(read_all(dir / "first" / "history.json"));
    const nlohmann::json& series = json["branches"][0]["series"];
    ASSERT_EQ(series.size(), 2u);
    const nlohmann::json& time = series[0];
    EXPECT_EQ(time["metric"], kTimeMetric);
    EXPECT_EQ(time["worse"], "up");
    EXPECT_EQ(time["min_effect_from"], "declared");
    EXPECT_EQ(time["points"].size(), 12u);
    EXPECT_EQ(time["points"][0]["values"].size(), 10u);
    EXPECT_EQ(time["points"][0]["limit"], 1.6);
    ASSERT_EQ(time["change_points"].size(), 1u);
    EXPECT_EQ(time["change_points"][0]["commit"], commit_sha(8));
    EXPECT_EQ(time["change_points"][0]["order"], 8);
    EXPECT_EQ(time["change_points"][0]["worse"], true);
    EXPECT_EQ(series[1]["worse"], "none");
}

// --- through the rig executable ------------------------------------------------

TEST(HistoryCommandLine, SweepsAddedCommitByCommitThenReportAndCheck) {
    const fs::path dir = fresh_dir("history_command_line");
    const std::string rig = std::string(RIG_BINARY_DIR) + "/bin/rig";
    const fs::path database = dir / "history.sqlite";
    const auto groups = noise_series(26, 8, 30, 7, 1.5);
    for (std::size_t c = 0; c < groups.size(); ++c) {
        nlohmann::json seeds = nlohmann::json::array();
        for (std::size_t s = 0; s < groups[c].size(); ++s) {
            seeds.push_back({{"seed", s + 1},
                             {"run", "adjust-seed" + std::to_string(s + 1)},
                             {"passed", true},
                             {"metrics", {{kTimeMetric, 1.0 + 0.1 * groups[c][s]}}}});
        }
        const nlohmann::json sweep = {
            {"schema_version", 1},
            {"rig", {{"version", "0.test"}, {"commit", "abc"}}},
            {"started_utc", "2026-11-" + std::to_string(10 + c) + "T08:00:00Z"},
            {"cases", {{{"name", "adjust"}, {"bands", {{kTimeMetric, {{"limit", 1.6}}}}}, {"seeds", seeds}}}}};
        const fs::path out = dir / ("sweep-" + std::to_string(c + 1));
        fs::create_directories(out);
        std::ofstream(out / "sweep.json") << sweep.dump();
        const auto added = run_shell(rig + " history add " + out.string() + " --commit " + commit_sha(c + 1) +
                                     " --db " + database.string() + " 2>&1");
        ASSERT_EQ(added.exit_code, 0) << added.output;
        EXPECT_NE(added.output.find("added commit " + commit_sha(c + 1) + " on branch main (order " +
                                    std::to_string(c + 1) + ", 2026-11-" + std::to_string(10 + c) + "T08:00:00Z)"),
                  std::string::npos)
            << added.output;
    }
    const auto again = run_shell(rig + " history add " + (dir / "sweep-8").string() + " --commit " + commit_sha(8) +
                                 " --db " + database.string() + " 2>&1");
    EXPECT_EQ(again.exit_code, 1) << again.output;
    EXPECT_NE(again.output.find("already in the history"), std::string::npos) << again.output;

    const auto check = run_shell(rig + " history check --db " + database.string() + " 2>&1");
    EXPECT_EQ(check.exit_code, 1) << check.output;
    EXPECT_NE(check.output.find("CHANGE POINT FOR THE WORSE at " + commit_sha(8)), std::string::npos) << check.output;

    const auto report = run_shell(rig + " history report --db " + database.string() + " --out " +
                                  (dir / "report").string() + " 2>&1");
    EXPECT_EQ(report.exit_code, 0) << report.output;
    EXPECT_TRUE(fs::is_regular_file(dir / "report" / "history.html"));
    EXPECT_TRUE(fs::is_regular_file(dir / "report" / "history.json"));

    const auto usage = run_shell(rig + " history check 2>&1");
    EXPECT_EQ(usage.exit_code, 2) << usage.output;
    EXPECT_NE(usage.output.find("--db"), std::string::npos) << usage.output;
    const auto corrupt = run_shell(rig + " history check --db " + (dir / "sweep-1" / "sweep.json").string() + " 2>&1");
    EXPECT_EQ(corrupt.exit_code, 2) << corrupt.output;
    EXPECT_NE(corrupt.output.find("sweep.json"), std::string::npos) << corrupt.output;
}

}  // namespace
