// `rig` as a careless or hostile user meets it (issue 14), through the
// executable: every bad input is refused before anything runs, naming what
// and where, and nothing outside the run is touched.
//  * a case named `..` or `.` (a path component) is refused; --out keeps what it had;
//  * two cases with one name in one run are refused, naming both files;
//  * a dropout longer than the case is refused at its key;
//  * a FIFO, a directory or a device as a case file or as `rig nmea decode`'s
//    input is refused by type (never a hang, never a crash).
// Nothing here starts DDS: every refusal comes before the first case.
#include <gtest/gtest.h>

#include <sys/stat.h>
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "run_support.h"

namespace {

namespace fs = std::filesystem;
using rig::testing::read_all;

struct Outcome {
    int exit_code = -1;
    std::string log;
};

// `rig ARGS`, output to DIR/rig.log; bounded by timeout(1) so a hang fails
// the test (exit 124) instead of stalling the suite.
Outcome rig(const std::string& args, const fs::path& dir) {
    const std::string command = "timeout -k 5 60 '" RIG_BINARY_DIR "/bin/rig' " + args + " > '" +
                                (dir / "rig.log").string() + "' 2>&1 < /dev/null";
    const int status = std::system(command.c_str());
    return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, read_all(dir / "rig.log")};
}

std::string quoted(const fs::path& path) { return "'" + path.string() + "'"; }

// tests/data/short-fusion.yaml with its name line replaced.
std::string short_case_named(const std::string& name_line) {
    std::string text = read_all(RIG_SOURCE_DIR "/tests/data/short-fusion.yaml");
    text.replace(0, text.find('\n'), name_line);
    return text;
}

TEST(HostileInput, CaseNamesThatArePathComponentsNeverTouchTheOutputDirectory) {
    for (const std::string& name : {std::string(".."), std::string("."), std::string("../../etc")}) {
        SCOPED_TRACE(name);
        const fs::path dir = rig::testing::fresh_dir("hostile-name");
        const fs::path out = dir / "out";
        fs::create_directories(out / "cases" / "earlier-case");
        std::ofstream(out / "keep.txt") << "from an earlier run\n";
        std::ofstream(out / "cases" / "earlier-case" / "trace.sqlite") << "x";
        std::ofstream(dir / "case.yaml") << short_case_named("name: \"" + name + "\"");
        const Outcome outcome = rig("run " + quoted(dir / "case.yaml") + " --out " + quoted(out), dir);
        EXPECT_EQ(outcome.exit_code, 2) << outcome.log;
        EXPECT_NE(outcome.log.find("case.yaml:1:7: name: case name "), std::string::npos) << outcome.log;
        EXPECT_NE(outcome.log.find("nothing was run"), std::string::npos) << outcome.log;
        EXPECT_EQ(read_all(out / "keep.txt"), "from an earlier run\n");
        EXPECT_TRUE(fs::exists(out / "cases" / "earlier-case" / "trace.sqlite"));
    }
}

TEST(HostileInput, TwoCasesWithOneNameAreRefusedBeforeAnythingRunsNamingBothFiles) {
    const fs::path dir = rig::testing::fresh_dir("hostile-duplicate");
    fs::create_directories(dir / "suite" / "a");
    fs::create_directories(dir / "suite" / "b");
    std::ofstream(dir / "suite" / "a" / "one.yaml") << short_case_named("name: same");
    std::ofstream(dir / "suite" / "b" / "two.yaml") << short_case_named("name: same");
    const Outcome outcome = rig("run " + quoted(dir / "suite") + " --out " + quoted(dir / "out"), dir);
    EXPECT_EQ(outcome.exit_code, 2) << outcome.log;
    const std::string expected = (dir / "suite" / "b" / "two.yaml").string() +
                                 ":1:7: name: case name 'same' is also the name of " +
                                 (dir / "suite" / "a" / "one.yaml").string() + ":1:7";
    EXPECT_NE(outcome.log.find(expected), std::string::npos) << outcome.log;
    EXPECT_FALSE(fs::exists(dir / "out")) << "nothing may run, nothing may be written";
}

TEST(HostileInput, ADropoutLongerThanTheCaseIsRefusedAtItsKey) {
    const fs::path dir = rig::testing::fresh_dir("hostile-dropout");
    std::string text = read_all(RIG_SOURCE_DIR "/tests/data/short-fusion.yaml");
    text.replace(text.find("gnss: { "), 8, "gnss: { dropouts: [ { at_s: 1, for_s: 1000 } ], ");
    std::ofstream(dir / "case.yaml") << text;
    const Outcome outcome = rig("run " + quoted(dir / "case.yaml") + " --out " + quoted(dir / "out"), dir);
    EXPECT_EQ(outcome.exit_code, 2) << outcome.log;
    EXPECT_NE(outcome.log.find("case.yaml:9:"), std::string::npos) << outcome.log;
    EXPECT_NE(outcome.log.find("gnss.dropouts[0].for_s: the dropout lasts 1000 s, longer than the whole case"),
              std::string::npos)
        << outcome.log;
    EXPECT_FALSE(fs::exists(dir / "out" / "results.json"));
}

TEST(HostileInput, SpecialFilesAsCaseFilesAreRefusedByType) {
    const fs::path dir = rig::testing::fresh_dir("hostile-special-case");
    const fs::path fifo = dir / "fifo.yaml";
    ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
    for (const auto& [path, what] : {std::pair<fs::path, std::string>{fifo, "is a FIFO (named pipe)"},
                                     std::pair<fs::path, std::string>{"/dev/zero", "is a character device"}}) {
        SCOPED_TRACE(path.string());
        const Outcome outcome = rig("run " + quoted(path) + " --out " + quoted(dir / "out"), dir);
        EXPECT_EQ(outcome.exit_code, 2) << outcome.log;
        EXPECT_NE(outcome.log.find(path.string() + ": (file): " + what), std::string::npos) << outcome.log;
    }
}

TEST(HostileInput, SpecialFilesGivenToNmeaDecodeAreRefusedByType) {
    const fs::path dir = rig::testing::fresh_dir("hostile-special-nmea");
    const fs::path fifo = dir / "capture.fifo";
    ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
    fs::create_directories(dir / "a-directory");
    const std::vector<std::pair<fs::path, std::string>> specials = {
        {dir / "a-directory", "is a directory"},
        {fifo, "is a FIFO (named pipe)"},
        {"/dev/zero", "is a character device"},
        {dir / "missing.log", "no such file"},
    };
    for (const auto& [path, what] : specials) {
        SCOPED_TRACE(path.string());
        const Outcome outcome = rig("nmea decode " + quoted(path), dir);
        EXPECT_EQ(outcome.exit_code, 2) << outcome.log;
        EXPECT_EQ(outcome.log, "rig nmea decode: " + path.string() + ": " + what +
                                   (what == "no such file" ? "" : ", expected a regular file (NMEA capture)") + "\n");
    }
    // A regular file still decodes.
    std::ofstream(dir / "ok.log") << "$GPHDT,274.07,T*03\n";
    const Outcome ok = rig("nmea decode " + quoted(dir / "ok.log"), dir);
    EXPECT_EQ(ok.exit_code, 0) << ok.log;
    EXPECT_NE(ok.log.find("\"heading_deg\":274.07"), std::string::npos) << ok.log;
}

}  // namespace
