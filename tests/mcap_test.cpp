// MCAP (harness/trace/trace_mcap.h, harness/trace/mcap_writer.h): `rig mcap` writes a run's
// traces as MCAP, and the official reader (@mcap/core, tests/js/, installed by
// scripts/setup) reads them both ways a tool does, indexed as Foxglove opens a
// file and streamed with every CRC checked; every sample of the trace, the
// forged ones included, is there with its time, topic and JSON. Plus the
// writer's CRC and schema inference, and bad inputs.
#include <gtest/gtest.h>
#include <sqlite3.h>
#include <sys/wait.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "harness/trace/mcap_writer.h"
#include "harness/trace/trace_mcap.h"
#include "run_support.h"
#include "tool_support.h"

namespace fs = std::filesystem;
using rig::testing::fresh_dir;
using rig::testing::read_all;

namespace {

rig::testing::ShellResult shell(const std::string& command) { return rig::testing::run_shell(command + " 2>&1"); }

std::string quoted(const fs::path& path) { return "'" + path.string() + "'"; }

// Every sample of the trace (and every forged one, on its foreign channel) as
// `t_ns<TAB>channel<TAB>json` lines, sorted.
std::vector<std::string> trace_lines(const fs::path& trace) {
    std::vector<std::string> lines;
    sqlite3* db = nullptr;
    EXPECT_EQ(sqlite3_open_v2(trace.c_str(), &db, SQLITE_OPEN_READONLY, nullptr), SQLITE_OK);
    const auto collect = [&](const char* sql) {
        sqlite3_stmt* statement = nullptr;
        ASSERT_EQ(sqlite3_prepare_v2(db, sql, -1, &statement, nullptr), SQLITE_OK) << sqlite3_errmsg(db);
        while (sqlite3_step(statement) == SQLITE_ROW) {
            std::string line = std::to_string(sqlite3_column_int64(statement, 0));
            for (int column = 1; column <= 2; ++column) {
                line += '\t';
                line += reinterpret_cast<const char*>(sqlite3_column_text(statement, column));
            }
            lines.push_back(std::move(line));
        }
        sqlite3_finalize(statement);
    };
    collect("select t_ns, topic, json from samples");
    collect("select t_ns, 'foreign/' || participant || '/' || topic, json from foreign_samples");
    sqlite3_close(db);
    std::sort(lines.begin(), lines.end());
    return lines;
}

std::vector<std::string> sorted_lines(const std::string& text) {
    std::vector<std::string> lines;
    std::istringstream in(text);
    for (std::string line; std::getline(in, line);) lines.push_back(line);
    std::sort(lines.begin(), lines.end());
    return lines;
}

// One meta value of a trace, as the sqlite3 shell prints it.
std::string meta_value(const fs::path& trace, const std::string& key) {
    std::string text = shell("sqlite3 " + quoted(trace) + " \"select value from meta where key = '" + key + "'\"").output;
    while (!text.empty() && text.back() == '\n') text.pop_back();
    return text;
}

// The forging case never records a forged sample: the rig refuses the forger
// at t = 0, when its hello or discovery shows its truth/hydraulics writer,
// before any sample of it arrives. So the test adds two to the trace, as the
// recorder would have written them (TraceFile::append_foreign): from node
// 'controller', the participant the case's error names (with a made-up GUID
// prefix, as discovery may not have seen it), each a copy of one of the
// plant's own truth/hydraulics samples in `donor` (the forger sends the
// plant's type). Forged samples are outside the trace's digest, which stays
// valid. Returns how many were added.
int forge_samples(const fs::path& trace, const fs::path& donor) {
    sqlite3* db = nullptr;
    EXPECT_EQ(sqlite3_open_v2(trace.c_str(), &db, SQLITE_OPEN_READWRITE, nullptr), SQLITE_OK);
    char* sql = sqlite3_mprintf(
        "ATTACH DATABASE %Q AS donor;"
        "INSERT INTO foreign_samples (t_ns, round, topic, participant, guid_prefix, json)"
        " SELECT t_ns, round, topic, 'controller', '0f0f0f0f0f0f0f0f0f0f0f0f', json FROM donor.samples"
        " WHERE topic = 'truth/hydraulics' ORDER BY t_ns LIMIT 2;",
        donor.c_str());
    char* error = nullptr;
    EXPECT_EQ(sqlite3_exec(db, sql, nullptr, nullptr, &error), SQLITE_OK) << (error ? error : "");
    sqlite3_free(error);
    sqlite3_free(sql);
    const int added = sqlite3_changes(db);
    sqlite3_close(db);
    return added;
}

}  // namespace

TEST(McapWriter, Crc32IsTheIeeeCrcOfTheSpecification) {
    // The check value of CRC-32/ISO-HDLC (zlib's crc32) over "123456789".
    const std::string check = "123456789";
    EXPECT_EQ(rig::harness::crc32_update(0, check.data(), check.size()), 0xCBF43926u);
    // Continued over two parts, the same.
    const std::uint32_t first = rig::harness::crc32_update(0, check.data(), 4);
    EXPECT_EQ(rig::harness::crc32_update(first, check.data() + 4, 5), 0xCBF43926u);
}

TEST(McapWriter, TheSchemaCoversEveryShapeASampleTook) {
    const nlohmann::json schema = nlohmann::json::parse(rig::harness::json_schema_of(
        {R"({"flow":null,"n":1,"name":"a","on":true,"list":[1]})",
         R"({"flow":20.5,"n":2,"name":"b","on":false,"list":[1.5],"extra":{"x":1}})"},
        "rig::msg::Example"));
    EXPECT_EQ(schema["title"], "rig::msg::Example");
    EXPECT_EQ(schema["type"], "object");
    const nlohmann::json& fields = schema["properties"];
    EXPECT_EQ(fields["flow"]["type"], nlohmann::json({"null", "number"}));
    EXPECT_EQ(fields["n"]["type"], "integer");
    EXPECT_EQ(fields["name"]["type"], "string");
    EXPECT_EQ(fields["on"]["type"], "boolean");
    EXPECT_EQ(fields["list"]["items"]["type"], "number");  // 1 and 1.5 on one field
    EXPECT_EQ(fields["extra"]["properties"]["x"]["type"], "integer");
}

// A run with many samples and a run with a forger: the official reader
// finds every sample, in time order, on a channel with a JSON schema, the
// forged ones on a channel of their own; the summary's statistics and the
// streamed read agree; the trace's meta is there.
TEST(McapOfficialReader, ReadsEverySampleOfTheTraces) {
    ASSERT_TRUE(rig::testing::tool_installed("node", "nodejs"));
    ASSERT_TRUE(rig::testing::tool_installed("sqlite3", "sqlite3"));
    const fs::path dir = fresh_dir("mcap-official-reader");
    const fs::path out = dir / "out";
    const auto run = shell(quoted(RIG_BINARY_DIR "/bin/rig") + " run " +
                            quoted(RIG_SOURCE_DIR "/cases/table5-6-continuation/continuation-6kmh.yaml") + " " +
                            quoted(RIG_SOURCE_DIR "/cases/faulty-controllers/forges-truth-topic.yaml") +
                            " --out " + quoted(out));
    ASSERT_EQ(run.exit_code, 0) << run.output;
    const fs::path forged_trace = out / "cases" / "forges-truth-topic-seed1" / "trace.sqlite";
    ASSERT_EQ(forge_samples(forged_trace, out / "cases" / "continuation-6kmh" / "trace.sqlite"), 2);
    const auto mcap = shell(quoted(RIG_BINARY_DIR "/bin/rig") + " mcap " + quoted(out));
    ASSERT_EQ(mcap.exit_code, 0) << mcap.output;

    std::size_t traces = 0;
    std::size_t forged_in_trace = 0, forged_in_mcap = 0;
    for (const std::string name : {"continuation-6kmh", "forges-truth-topic-seed1"}) {
        SCOPED_TRACE(name);
        const fs::path case_dir = out / "cases" / name;
        const fs::path trace = case_dir / "trace.sqlite";
        const fs::path file = case_dir / "trace.mcap";
        ASSERT_TRUE(fs::exists(file)) << mcap.output;
        EXPECT_NE(mcap.output.find(file.string() + ": "), std::string::npos) << mcap.output;
        EXPECT_FALSE(fs::exists(file.string() + ".partial"));
        ++traces;

        const fs::path lines_file = dir / (name + ".lines");
        const auto read = shell("cd " + quoted(RIG_JS_TOOLS_DIR) + " && node read_mcap.mjs " + quoted(file) + " " +
                                 quoted(lines_file));
        ASSERT_EQ(read.exit_code, 0) << "the official reader failed (is @mcap/core installed? scripts/setup runs npm ci "
                                        "in " RIG_JS_TOOLS_DIR "):\n"
                                     << read.output;
        const nlohmann::json summary = nlohmann::json::parse(read.output);
        const std::vector<std::string> expected = trace_lines(trace);
        // The forging case ends at t = 0 (see forge_samples): its trace holds the forged samples alone.
        if (name == "continuation-6kmh") {
            ASSERT_GT(expected.size(), 20000u);
        }
        for (const std::string& line : expected) {
            if (line.find("\tforeign/") != std::string::npos) ++forged_in_trace;
        }
        const std::vector<std::string> got = sorted_lines(read_all(lines_file));
        EXPECT_EQ(got.size(), expected.size());
        EXPECT_TRUE(got == expected) << "the MCAP's messages differ from the trace's samples";
        const auto& indexed = summary["indexed"];
        EXPECT_EQ(indexed["messages"].get<std::size_t>(), expected.size());
        EXPECT_EQ(indexed["statisticsMessageCount"].get<std::size_t>(), expected.size());
        EXPECT_EQ(indexed["outOfOrder"], 0) << "messages out of log-time order";
        EXPECT_EQ(indexed["chunks"].get<int>() >= 1, !expected.empty());
        EXPECT_EQ(summary["streamed"]["messages"].get<std::size_t>(), expected.size());
        EXPECT_TRUE(summary["streamed"]["dataEnd"].get<bool>());
        EXPECT_TRUE(summary["streamed"]["done"].get<bool>());
        EXPECT_EQ(summary["metadata"]["rig.trace.meta"]["trace_sha256"], meta_value(trace, "trace_sha256"));
        for (const auto& [topic, count] : indexed["byTopic"].items()) {
            if (topic.rfind("foreign/", 0) == 0) forged_in_mcap += count.get<std::size_t>();
        }
        if (name == "forges-truth-topic-seed1") {
            EXPECT_GE(indexed["byTopic"].value("foreign/controller/truth/hydraulics", 0), 2) << indexed.dump(2);
        }
    }
    EXPECT_EQ(traces, 2u);
    // Forged samples in the trace, and each in the MCAP on its foreign channel.
    EXPECT_GE(forged_in_trace, 2u);
    EXPECT_EQ(forged_in_mcap, forged_in_trace) << "a forged sample's channel";
}

// Not a trace, a missing file, --out with several traces: clear errors naming
// the input, nothing left behind.
TEST(McapCommand, BadInputsAreClearErrors) {
    const fs::path dir = fresh_dir("mcap-bad-inputs");
    const fs::path not_a_trace = dir / "notes.sqlite";
    std::ofstream(not_a_trace) << "not a database\n";
    const std::string rig = quoted(RIG_BINARY_DIR "/bin/rig");

    auto result = shell(rig + " mcap " + quoted(not_a_trace));
    EXPECT_EQ(result.exit_code, 1) << result.output;
    EXPECT_NE(result.output.find("rig mcap: trace " + not_a_trace.string()), std::string::npos) << result.output;
    EXPECT_FALSE(fs::exists(dir / "trace.mcap"));
    EXPECT_FALSE(fs::exists(dir / "trace.mcap.partial"));

    result = shell(rig + " mcap " + quoted(dir / "missing.sqlite"));
    EXPECT_EQ(result.exit_code, 1) << result.output;
    EXPECT_NE(result.output.find("missing.sqlite: no such file"), std::string::npos) << result.output;

    result = shell(rig + " mcap " + quoted(dir));  // a directory without cases/*/trace.sqlite
    EXPECT_EQ(result.exit_code, 2) << result.output;
    EXPECT_NE(result.output.find("no cases/*/trace.sqlite in it"), std::string::npos) << result.output;

    // --out is one file: refused for two traces, before anything is written.
    result = shell(rig + " mcap " + quoted(not_a_trace) + " " + quoted(not_a_trace) + " --out " + quoted(dir / "x.mcap"));
    EXPECT_EQ(result.exit_code, 2) << result.output;
    EXPECT_NE(result.output.find("--out names one file, but 2 traces were given"), std::string::npos) << result.output;
    EXPECT_FALSE(fs::exists(dir / "x.mcap"));
}
