// `rig run --shard I/N` and `rig merge` (harness/run/shard.h, harness/commands/judge_command.h):
// every case lands in exactly one shard, by its name alone; the shards of a
// suite, merged, are the suite run at once: the same cases with the same trace
// digests, metrics and verdicts; merges that cannot be right are refused.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <string>

#include "harness/run/shard.h"
#include "run_support.h"
#include "tool_support.h"

namespace fs = std::filesystem;
using rig::harness::parse_shard;
using rig::harness::shard_of;
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
