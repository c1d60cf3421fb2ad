// `rig run --shard I/N` and `rig merge` (harness/run/shard.h, harness/commands/judge_command.h):
// every case lands in exactly one shard, by its name alone; the shards of a
// suite, merged, are the suite run at once: the same cases with the same trace
// digests, metrics and verdicts; merges that cannot be right are refused.
// `rig sweep --shard I/N` deals the sweep's runs out in turn, and its shards,
// merged, are the sweep run at once (harness/report/sweep_shard.h).
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <string>
#include <vector>

#include "harness/run/shard.h"
#include "run_support.h"
#include "tool_support.h"

namespace fs = std::filesystem;
using rig::harness::parse_shard;
using rig::harness::shard_of;
using rig::harness::shard_of_run;
using rig::testing::fresh_dir;
using rig::testing::read_all;
using rig::testing::run_shell;

namespace {

std::string quoted(const fs::path& path) { return "'" + path.string() + "'"; }

std::map<std::string, nlohmann::json> cases_by_name(const fs::path& out) {
    std::map<std::string, nlohmann::json> cases;
    const std::string text = read_all(out / "results.json");
    if (text.empty()) return cases;
    const nlohmann::json results = nlohmann::json::parse(text);
    for (const nlohmann::json& one : results.at("cases")) cases[one.at("name").get<std::string>()] = one;
    return cases;
}

const std::string kRig = quoted(RIG_BINARY_DIR "/bin/rig");

// Every file under `dir`, relative to it.
std::set<std::string> files_under(const fs::path& dir) {
    std::set<std::string> files;
    if (!fs::is_directory(dir)) return files;
    for (const auto& entry : fs::recursive_directory_iterator(dir)) {
        if (entry.is_regular_file()) files.insert(fs::relative(entry.path(), dir).string());
    }
    return files;
}

// A sweep's text without what only the wall clock gives: the wall time and the start.
std::string without_wall_clock(const std::string& text) {
    const std::string no_wall = std::regex_replace(text, std::regex(R"(in \S+ s wall)"), "in (wall) s wall");
    return std::regex_replace(no_wall, std::regex(R"(started [0-9T:-]+)"), "started (when)");
}

nlohmann::json sweep_json_of(const fs::path& out) {
    const std::string text = read_all(out / "sweep.json");
    return text.empty() ? nlohmann::json() : nlohmann::json::parse(text);
}

// Two short lockstep cases: short-fusion, and a copy with a tight limit (some
// seeds fail and keep their traces) and paper numbers (one the rig does not measure).
std::string two_short_cases(const fs::path& dir) {
    std::string tight = read_all(RIG_SOURCE_DIR "/tests/data/short-fusion.yaml");
    tight = std::regex_replace(tight, std::regex("name: short-fusion"), "name: short-fusion-tight");
    tight = std::regex_replace(tight, std::regex(R"(limits: \{ breakpoint_error_m: [0-9.]+ \})"),
                               "limits: { breakpoint_error_m: 0.005 }");
    tight += "paper: { source: \"a test's own numbers\", breakpoint_error_m: 0.004, spray_delay_s: 0.2 }\n";
    std::ofstream(dir / "tight.yaml") << tight;
    return quoted(RIG_SOURCE_DIR "/tests/data/short-fusion.yaml") + " " + quoted(dir / "tight.yaml");
}

}  // namespace

TEST(Shard, ParsesIOverNAndRefusesTheRestNamingIt) {
    EXPECT_EQ(parse_shard("2/4").index, 2);
    EXPECT_EQ(parse_shard("2/4").count, 4);
    EXPECT_EQ(parse_shard("1/1").count, 1);
    for (const char* bad : {"0/2", "3/2", "2", "a/2", "1/0", "1/1001", "1/2/3", "/2", "1/", "-1/2", " 1/2"}) {
        try {
            parse_shard(bad);
            ADD_FAILURE() << bad << " accepted";
        } catch (const std::invalid_argument& error) {
            EXPECT_NE(std::string(error.what()).find(std::string("--shard '") + bad + "'"), std::string::npos)
                << error.what();
        }
    }
}

TEST(Shard, EveryCaseIsInExactlyOneShardByItsNameAlone) {
    std::set<std::string> names;
    for (int i = 0; i < 200; ++i) names.insert("case-" + std::to_string(i));
    for (const int count : {1, 2, 3, 7}) {
        std::map<int, int> per_shard;
        for (const std::string& name : names) {
            const int shard = shard_of(name, count);
            ASSERT_GE(shard, 1);
            ASSERT_LE(shard, count);
            EXPECT_EQ(shard_of(name, count), shard);  // the name alone decides
            ++per_shard[shard];
        }
        int total = 0;
        for (const auto& [shard, n] : per_shard) total += n;
        EXPECT_EQ(total, 200);
    }
    // FNV-1a 64 of the name: fixed across machines and builds.
    EXPECT_EQ(shard_of("continuation-6kmh", 1000), shard_of(std::string("continuation-") + "6kmh", 1000));
}

// A suite in two shards, merged, is the suite run at once.
TEST(ShardAndMerge, TheMergedShardsAreTheSuiteRunAtOnce) {
    const fs::path dir = fresh_dir("shard-merge");
    const std::string rig = quoted(RIG_BINARY_DIR "/bin/rig");
    const std::string suite = quoted(RIG_SOURCE_DIR "/cases/table5-6-continuation") + " " +
                              quoted(RIG_SOURCE_DIR "/cases/table2-flow-adjust") + " " +
                              quoted(RIG_SOURCE_DIR "/cases/faulty-controllers/never-resumes.yaml");
    const auto all = run_shell(rig + " run " + suite + " --in-process --out " + quoted(dir / "all") + " 2>&1");
    ASSERT_TRUE(all.exit_code == 0) << all.output;
    for (const char* shard : {"1/2", "2/2"}) {
        const fs::path out = dir / (std::string("shard-") + shard[0]);
        const auto run = run_shell(rig + " run " + suite + " --in-process --shard " + shard + " --out " + quoted(out) + " 2>&1");
        ASSERT_EQ(run.exit_code, 0) << run.output;
        EXPECT_NE(run.output.find(std::string("rig: shard ") + shard + ": "), std::string::npos) << run.output;
    }
    const auto merged = run_shell(rig + " merge " + quoted(dir / "shard-1") + " " + quoted(dir / "shard-2") + " --out " +
                                  quoted(dir / "merged") + " 2>&1");
    ASSERT_EQ(merged.exit_code, 0) << merged.output;
    EXPECT_NE(merged.output.find("every metric, verdict and digest as the shards recorded"), std::string::npos)
        << merged.output;

    const auto whole = cases_by_name(dir / "all");
    const auto joined = cases_by_name(dir / "merged");
    const auto first = cases_by_name(dir / "shard-1");
    const auto second = cases_by_name(dir / "shard-2");
    ASSERT_GE(whole.size(), 10u);
    EXPECT_EQ(first.size() + second.size(), whole.size());
    EXPECT_FALSE(first.empty());
    EXPECT_FALSE(second.empty());
    ASSERT_EQ(joined.size(), whole.size());
    for (const auto& [name, one] : whole) {
        SCOPED_TRACE(name);
        ASSERT_TRUE(joined.count(name));
        const nlohmann::json& other = joined.at(name);
        EXPECT_EQ(other.at("trace_sha256"), one.at("trace_sha256"));
        EXPECT_EQ(other.at("metrics"), one.at("metrics"));
        EXPECT_EQ(other.at("passed"), one.at("passed"));
        EXPECT_EQ(other.at("failures"), one.at("failures"));
        // The merged run directory holds its own traces.
        EXPECT_TRUE(fs::exists(dir / "merged" / "cases" / name / "trace.sqlite"));
    }
    for (const char* file : {"junit.xml", "report.txt", "report.html"}) EXPECT_TRUE(fs::exists(dir / "merged" / file)) << file;
    // The merged junit.xml is CI-grade like a run's (ci_outputs_test holds the run's).
    ASSERT_TRUE(rig::testing::tool_installed("xmllint", "libxml2-utils"));
    const auto schema = run_shell("xmllint --noout --schema " + quoted(RIG_SOURCE_DIR "/tests/data/jenkins-junit-10.xsd") +
                                  " " + quoted(dir / "merged" / "junit.xml") + " 2>&1");
    EXPECT_EQ(schema.exit_code, 0) << schema.output;

    // A shard whose recorded number its trace does not give: exit status 5
    // (the judging or the shard changed, not the controller), said last.
    nlohmann::json shard_results = nlohmann::json::parse(read_all(dir / "shard-2" / "results.json"));
    nlohmann::json& changed = shard_results.at("cases").at(0);
    ASSERT_FALSE(changed.at("metrics").empty()) << changed.dump(2);
    changed.at("metrics").begin().value() = 1e9;
    std::ofstream(dir / "shard-2" / "results.json") << shard_results.dump(1);
    const auto differing = run_shell(rig + " merge " + quoted(dir / "shard-1") + " " + quoted(dir / "shard-2") +
                                     " --out " + quoted(dir / "merged-differing") + " 2>&1");
    EXPECT_EQ(differing.exit_code, 5) << differing.output;
    EXPECT_NE(differing.output.find("differs: " + changed.at("name").get<std::string>()), std::string::npos)
        << differing.output;
    EXPECT_NE(differing.output.find("difference(s) from the results the shards recorded: the judging changed, whatever "
                                    "the verdicts (exit status 5)\n"),
              std::string::npos)
        << differing.output;
}

TEST(ShardAndMerge, MergesThatCannotBeRightAreRefusedBeforeWriting) {
    const fs::path dir = fresh_dir("shard-merge-refused");
    const std::string rig = quoted(RIG_BINARY_DIR "/bin/rig");
    const auto run = run_shell(rig + " run " + quoted(RIG_SOURCE_DIR "/cases/table1-spray-timing") +
                               " --in-process --out " + quoted(dir / "a") + " 2>&1");
    ASSERT_EQ(run.exit_code, 0) << run.output;

    // One suite's output twice: its cases would be judged twice.
    auto merged = run_shell(rig + " merge " + quoted(dir / "a") + " " + quoted(dir / "a") + " --out " + quoted(dir / "m") + " 2>&1");
    EXPECT_EQ(merged.exit_code, 2) << merged.output;
    EXPECT_NE(merged.output.find("is in both"), std::string::npos) << merged.output;
    EXPECT_FALSE(fs::exists(dir / "m"));

    // Into a directory that already holds something.
    fs::create_directories(dir / "full");
    std::ofstream(dir / "full" / "keep.txt") << "mine\n";
    merged = run_shell(rig + " merge " + quoted(dir / "a") + " --out " + quoted(dir / "full") + " 2>&1");
    EXPECT_EQ(merged.exit_code, 2) << merged.output;
    EXPECT_NE(merged.output.find("exists and is not an empty directory"), std::string::npos) << merged.output;
    EXPECT_EQ(read_all(dir / "full" / "keep.txt"), "mine\n");

    // Not a run directory.
    merged = run_shell(rig + " merge " + quoted(dir / "nothing-here") + " --out " + quoted(dir / "m2") + " 2>&1");
    EXPECT_EQ(merged.exit_code, 2) << merged.output;
    EXPECT_NE(merged.output.find("nothing-here: not a rig run --out directory"), std::string::npos) << merged.output;

    // A bad shard is a usage error, before any case runs.
    const auto bad = run_shell(rig + " run " + quoted(RIG_SOURCE_DIR "/cases/table1-spray-timing") + " --shard 3/2 --out " +
                               quoted(dir / "b") + " 2>&1");
    EXPECT_EQ(bad.exit_code, 2) << bad.output;
    EXPECT_NE(bad.output.find("--shard '3/2': needs 1 <= I <= N <= 1000"), std::string::npos) << bad.output;
    EXPECT_FALSE(fs::exists(dir / "b" / "results.json"));
}

TEST(SweepShard, RunsAreDealtInTurnSoShardsDifferByOneRunAtMost) {
    // 3 cases over 7 seeds, run k being case k / 7's seed k % 7.
    for (const int count : {1, 2, 4, 5, 30}) {
        std::map<int, int> per_shard;
        std::map<std::pair<int, int>, int> per_case_and_shard;
        for (std::size_t k = 0; k < 21; ++k) {
            const int shard = shard_of_run(k, count);
            ASSERT_GE(shard, 1);
            ASSERT_LE(shard, count);
            ++per_shard[shard];
            ++per_case_and_shard[{static_cast<int>(k / 7), shard}];
        }
        int least = 21, most = 0;
        for (int shard = 1; shard <= count; ++shard) {
            least = std::min(least, per_shard[shard]);
            most = std::max(most, per_shard[shard]);
        }
        EXPECT_LE(most - least, 1) << count << " shards";
        // Each case's seeds spread over the shards too (its runs are alike in length).
        for (const auto& [case_and_shard, runs] : per_case_and_shard) EXPECT_LE(runs, (7 + count - 1) / count);
    }
}

// A sweep in two shards, merged, is the sweep run at once: sweep.json but for
// its wall-clock fields, sweep.txt and sweep.html but for the wall time, and
// the runs' kept files.
TEST(SweepShard, TheMergedShardsAreTheSweepRunAtOnce) {
    const fs::path dir = fresh_dir("sweep-shard-merge");
    const std::string cases = two_short_cases(dir);
    const std::string sweep = kRig + " sweep " + cases + " --seeds 5 --first-seed 3 --in-process";
    const auto all = run_shell(sweep + " --out " + quoted(dir / "all") + " 2>&1");
    const nlohmann::json whole = sweep_json_of(dir / "all");
    ASSERT_TRUE(whole.is_object()) << all.output;
    // What the test stands on: runs that passed and runs that did not (and kept their traces).
    const nlohmann::json& tight = whole.at("cases").at(1);
    ASSERT_EQ(tight.at("name"), "short-fusion-tight");
    ASSERT_GT(tight.at("passed").get<int>(), 0) << all.output;
    ASSERT_LT(tight.at("passed").get<int>(), 5) << all.output;
    EXPECT_EQ(all.exit_code, 1) << all.output;
    EXPECT_EQ(tight.at("paper_unmatched"), nlohmann::json::array({"spray_delay_s"}));

    std::vector<nlohmann::json> shards;
    for (const char* shard : {"1/2", "2/2"}) {
        const fs::path out = dir / (std::string("shard-") + shard[0]);
        const auto run = run_shell(sweep + " --shard " + shard + " --out " + quoted(out) + " 2>&1");
        EXPECT_NE(run.output.find(std::string("rig sweep: shard ") + shard + ": 5 of 10 runs"), std::string::npos)
            << run.output;
        shards.push_back(sweep_json_of(out));
        ASSERT_TRUE(shards.back().is_object()) << run.output;
        EXPECT_EQ(shards.back().at("shard").at("runs").size(), 5u);
        EXPECT_EQ(shards.back().at("seeds"), whole.at("seeds"));  // the whole sweep's seeds, whatever the shard holds
    }
    const auto merged = run_shell(kRig + " merge " + quoted(dir / "shard-1") + " " + quoted(dir / "shard-2") +
                                  " --out " + quoted(dir / "merged") + " 2>&1");
    EXPECT_EQ(merged.exit_code, all.exit_code) << merged.output;
    EXPECT_NE(merged.output.find("merged 10 runs from 2 shards"), std::string::npos) << merged.output;

    nlohmann::json joined = sweep_json_of(dir / "merged");
    ASSERT_TRUE(joined.is_object()) << merged.output;
    // The wall-clock fields: the earliest start, the machine time summed.
    EXPECT_EQ(joined.at("started_utc"),
              std::min(shards[0].at("started_utc").get<std::string>(), shards[1].at("started_utc").get<std::string>()));
    EXPECT_EQ(joined.at("wall_seconds").get<double>(),
              shards[0].at("wall_seconds").get<double>() + shards[1].at("wall_seconds").get<double>());
    nlohmann::json at_once = whole;
    for (nlohmann::json* json : {&at_once, &joined}) {
        json->erase("started_utc");
        json->erase("wall_seconds");
    }
    EXPECT_EQ(joined, at_once) << "merged:\n" << joined.dump(1) << "\nat once:\n" << at_once.dump(1);
    EXPECT_FALSE(joined.contains("shard"));
    EXPECT_EQ(without_wall_clock(read_all(dir / "merged" / "sweep.txt")), without_wall_clock(read_all(dir / "all" / "sweep.txt")));
    EXPECT_EQ(without_wall_clock(read_all(dir / "merged" / "sweep.html")),
              without_wall_clock(read_all(dir / "all" / "sweep.html")));
    // Every run's directory, with the traces the failed runs kept, as one machine left them.
    const std::set<std::string> kept = files_under(dir / "all" / "cases");
    EXPECT_EQ(files_under(dir / "merged" / "cases"), kept);
    for (const nlohmann::json& seed : tight.at("failed_seeds")) {
        EXPECT_TRUE(kept.count("short-fusion-tight-seed" + seed.dump() + "/trace.sqlite")) << seed;
    }
}

// Shards that are not every shard of one sweep, once, are refused before
// anything is written, naming the directory.
TEST(SweepShard, MergesThatCannotBeRightAreRefusedBeforeWriting) {
    const fs::path dir = fresh_dir("sweep-shard-refused");
    const std::string short_case = quoted(RIG_SOURCE_DIR "/tests/data/short-fusion.yaml");
    const std::string sweep = kRig + " sweep " + short_case + " --in-process --keep-traces none -q";
    for (const auto& [args, out] : std::vector<std::pair<std::string, std::string>>{{" --seeds 2 --shard 1/2", "s1"},
                                                                                     {" --seeds 2 --shard 2/2", "s2"},
                                                                                     {" --seeds 3 --shard 2/2", "other-seeds"},
                                                                                     {" --seeds 2", "unsharded"}}) {
        const auto run = run_shell(sweep + args + " --out " + quoted(dir / out) + " 2>&1");
        ASSERT_EQ(run.exit_code, 0) << args << ":\n" << run.output;
    }
    const auto run = run_shell(kRig + " run " + short_case + " --in-process --out " + quoted(dir / "a-run") + " 2>&1");
    ASSERT_EQ(run.exit_code, 0) << run.output;

    int attempt = 0;
    auto refused = [&](const std::vector<std::string>& shards, const std::string& said) {
        const fs::path out = dir / ("merged-" + std::to_string(++attempt));
        std::string command = kRig + " merge";
        for (const std::string& shard : shards) command += " " + quoted(dir / shard);
        const auto merged = run_shell(command + " --out " + quoted(out) + " 2>&1");
        EXPECT_EQ(merged.exit_code, 2) << merged.output;
        EXPECT_NE(merged.output.find(said), std::string::npos) << "wanted: " << said << "\n" << merged.output;
        EXPECT_FALSE(fs::exists(out)) << merged.output;
    };
    refused({"s1"}, "shard 2/2 is missing");
    refused({"s1", "s1"}, (dir / "s1").string() + " and " + (dir / "s1").string() + " are both shard 1/2");
    refused({"s1", "other-seeds"}, (dir / "other-seeds").string() + " is not a shard of the sweep in " +
                                       (dir / "s1").string() + ": its seeds [1,2,3], not [1,2]");
    refused({"s1", "unsharded"}, (dir / "unsharded" / "sweep.json").string() + ": a sweep without --shard");
    refused({"s1", "no-such-dir"}, (dir / "no-such-dir").string() + ": not a rig run --out directory, nor a rig sweep one");
    refused({"s1", "a-run"}, (dir / "s1").string() + " is the output of rig sweep, " + (dir / "a-run").string() + " is not");

    // The two that belong together do merge; the shards are left as they were.
    const std::set<std::string> before = files_under(dir / "s1");
    const auto merged = run_shell(kRig + " merge " + quoted(dir / "s2") + " " + quoted(dir / "s1") + " --out " +
                                  quoted(dir / "merged") + " 2>&1");
    EXPECT_EQ(merged.exit_code, 0) << merged.output;
    EXPECT_EQ(sweep_json_of(dir / "merged").at("cases").at(0).at("runs"), 2);
    EXPECT_EQ(files_under(dir / "s1"), before);

    // A bad --shard is a usage error, before any run.
    const auto bad = run_shell(sweep + " --seeds 2 --shard 0/2 --out " + quoted(dir / "bad") + " 2>&1");
    EXPECT_EQ(bad.exit_code, 2) << bad.output;
    EXPECT_NE(bad.output.find("rig sweep: --shard '0/2': needs 1 <= I <= N <= 1000"), std::string::npos) << bad.output;
    EXPECT_FALSE(fs::exists(dir / "bad" / "sweep.json"));
}
