// `rig` as a careless or hostile user meets it (issue 14), through the
// executable: every bad input is refused before anything runs, naming what
// and where, and nothing outside the run is touched.
//  * a case named `..` or `.` (a path component) is refused; --out keeps what it had;
//  * two cases with one name in one run are refused, naming both files;
//  * a dropout longer than the case is refused at its key;
//  * a FIFO, a directory or a device as a case file or as `rig nmea decode`'s
//    input is refused by type (never a hang, never a crash).
//  * an output directory that cannot take results (a path through a regular
//    file, a device, a read-only or full file system) is refused before any case
//    runs; a disk that fills during the run ends it with a clean error (exit 4),
//    never an abort, and what it wrote stays a readable trace.
// Every refusal comes before the first case; only the full-disk runs start
// DDS, in a network namespace of their own with only loopback up.
#include <gtest/gtest.h>

#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

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

// `unshare -m` (a mount namespace of the test's own, so a small tmpfs can be
// mounted without touching the machine) needs root; without it the checks that
// need a file system of a chosen size or mode are skipped, and say so.
bool can_mount_privately() { return ::geteuid() == 0 && std::system("unshare -m -n true > /dev/null 2>&1") == 0; }

// `rig ARGS` with a tmpfs of `tmpfs_options` mounted on DIR/fs first, in a
// mount and network namespace of its own (loopback only: the runs start DDS).
Outcome rig_on_tmpfs(const std::string& tmpfs_options, const std::string& before, const std::string& args,
                     const fs::path& dir) {
    fs::create_directories(dir / "fs");
    const std::string script = "ip link set lo up && mount -t tmpfs -o " + tmpfs_options + " tmpfs " +
                               quoted(dir / "fs") + " && " + before + "exec timeout -k 5 120 '" RIG_BINARY_DIR
                               "/bin/rig' " + args + " > " + quoted(dir / "rig.log") + " 2>&1 < /dev/null";
    std::ofstream(dir / "run.sh") << script << "\n";
    const int status = std::system(("unshare -m -n sh " + quoted(dir / "run.sh")).c_str());
    return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, read_all(dir / "rig.log")};
}

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

// Numbers on the command line: a seed that is not an unsigned 64-bit decimal
// integer (negative, past 2^64 - 1, written as a float) is refused, never
// wrapped or rounded into another seed; `rig emulate gnss --seed` alike.
TEST(HostileInput, SeedsOutsideUnsigned64BitIntegersAreRefused) {
    const fs::path dir = rig::testing::fresh_dir("hostile-seed");
    const std::string case_file = quoted(RIG_SOURCE_DIR "/tests/data/short-fusion.yaml");
    const std::vector<std::pair<std::string, std::string>> bad = {
        {"-1", "must be a non-negative integer in decimal digits, got '-1'"},
        {"18446744073709551616", "must be at most 18446744073709551615, got 18446744073709551616"},
        {"1e3", "must be a non-negative integer in decimal digits, got '1e3'"},
        {"0x10", "must be a non-negative integer in decimal digits, got '0x10'"},
    };
    for (const auto& [seed, problem] : bad) {
        SCOPED_TRACE(seed);
        for (const std::string& command : {"run " + case_file + " --out " + quoted(dir / "out"),
                                           "emulate gnss " + case_file + " --pty"}) {
            const Outcome outcome = rig(command + " --seed " + seed, dir);
            EXPECT_NE(outcome.exit_code, 0) << outcome.log;
            EXPECT_NE(outcome.log.find("--seed: " + problem), std::string::npos) << command << "\n" << outcome.log;
        }
    }
    EXPECT_FALSE(fs::exists(dir / "out"));
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

// In a suite folder, a FIFO, a link to a device or a link loop with a case
// file's name is refused by type, naming it (it was skipped unsaid before), and
// the good case beside them does not run either.
TEST(HostileInput, SpecialFilesInASuiteFolderAreRefusedByTypeNotSkipped) {
    const fs::path dir = rig::testing::fresh_dir("hostile-special-suite");
    const fs::path suite = dir / "suite";
    fs::create_directories(suite / "nested.yaml");  // a folder with a case's name is walked into
    std::ofstream(suite / "nested.yaml" / "good.yaml") << short_case_named("name: good");
    ASSERT_EQ(::mkfifo((suite / "a-fifo.yaml").c_str(), 0600), 0);
    fs::create_symlink("/dev/zero", suite / "zero.yml");
    fs::create_symlink("loop.yaml", suite / "loop.yaml");
    const Outcome outcome = rig("run " + quoted(suite) + " --out " + quoted(dir / "out"), dir);
    EXPECT_EQ(outcome.exit_code, 2) << outcome.log;
    for (const std::string& expected :
         {(suite / "a-fifo.yaml").string() + ": (file): is a FIFO (named pipe), expected a regular file",
          (suite / "zero.yml").string() + ": (file): is a character device, expected a regular file",
          (suite / "loop.yaml").string() + ": (file): cannot examine: Too many levels of symbolic links",
          std::string("rig: 3 case file error(s); nothing was run")}) {
        EXPECT_NE(outcome.log.find(expected), std::string::npos) << expected << "\n" << outcome.log;
    }
    EXPECT_FALSE(fs::exists(dir / "out"));
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

TEST(HostileInput, OutputDirectoriesThatCannotTakeResultsAreRefusedBeforeAnyCaseRuns) {
    const fs::path dir = rig::testing::fresh_dir("hostile-out");
    std::ofstream(dir / "a-file") << "not a directory\n";
    const fs::path case_file = RIG_SOURCE_DIR "/tests/data/short-fusion.yaml";
    struct Bad {
        fs::path out;
        std::string problem;
    };
    const std::vector<Bad> bad = {
        {dir / "a-file", (dir / "a-file").string() + " is a regular file, expected a directory"},
        {dir / "a-file" / "out", (dir / "a-file").string() + " is a regular file, expected a directory"},
        {dir / "a-file" / "deeper" / "out", (dir / "a-file").string() + " is a regular file, expected a directory"},
        {"/dev/null", "/dev/null is a character device, expected a directory"},
        {"/dev/null/out", "/dev/null is a character device, expected a directory"},
    };
    for (const Bad& out : bad) {
        SCOPED_TRACE(out.out.string());
        const Outcome outcome = rig("run " + quoted(case_file) + " --out " + quoted(out.out), dir);
        EXPECT_EQ(outcome.exit_code, 2) << outcome.log;
        EXPECT_NE(outcome.log.find("rig: --out " + out.out.string() + ": " + out.problem), std::string::npos)
            << outcome.log;
        EXPECT_NE(outcome.log.find("; nothing was run"), std::string::npos) << outcome.log;
        EXPECT_EQ(outcome.log.find("short-fusion"), std::string::npos) << "no case may start: " << outcome.log;
    }
    EXPECT_EQ(read_all(dir / "a-file"), "not a directory\n");
    // `rig bench` writes its runs under --out too: checked before its minutes of runs.
    for (const Bad& out : {bad[1], bad[3]}) {
        const Outcome outcome = rig("bench " + quoted(case_file) + " --repeat 1 --out " + quoted(out.out), dir);
        EXPECT_EQ(outcome.exit_code, 2) << outcome.log;
        EXPECT_EQ(outcome.log, "rig bench: --out " + out.out.string() + ": " + out.problem +
                                   " (or a path where one can be made); nothing was run\n");
    }

    // Read-only: as a user, a directory without write permission; as root (who
    // writes through permissions) a read-only mount.
    if (::geteuid() != 0) {
        fs::create_directories(dir / "read-only");
        fs::permissions(dir / "read-only", fs::perms::owner_read | fs::perms::owner_exec);
        for (const fs::path& out : {dir / "read-only", dir / "read-only" / "out"}) {
            const Outcome outcome = rig("run " + quoted(case_file) + " --out " + quoted(out), dir);
            EXPECT_EQ(outcome.exit_code, 2) << outcome.log;
            EXPECT_NE(outcome.log.find("Permission denied; nothing was run"), std::string::npos) << outcome.log;
        }
        fs::permissions(dir / "read-only", fs::perms::owner_all);
    } else if (!can_mount_privately()) {
        GTEST_SKIP() << "root without unshare -m: no read-only or full file system to try";
    } else {
        for (const std::string& out : {std::string("fs"), std::string("fs/out")}) {
            SCOPED_TRACE("read-only " + out);
            const Outcome outcome =
                rig_on_tmpfs("size=1m,ro", "", "run " + quoted(case_file) + " --out " + quoted(dir / out), dir);
            EXPECT_EQ(outcome.exit_code, 2) << outcome.log;
            EXPECT_NE(outcome.log.find("rig: --out " + (dir / out).string() + ": "), std::string::npos) << outcome.log;
            EXPECT_NE(outcome.log.find("Read-only file system; nothing was run"), std::string::npos) << outcome.log;
        }
        // Already full (room for less than one trace): refused as well, and an
        // earlier run's results there are left as they were.
        const Outcome full = rig_on_tmpfs("size=16k", "mkdir " + quoted(dir / "fs/out") + " && echo earlier > " +
                                                          quoted(dir / "fs/out/results.json") + " && ",
                                          "run " + quoted(case_file) + " --out " + quoted(dir / "fs/out"), dir);
        EXPECT_EQ(full.exit_code, 2) << full.log;
        EXPECT_NE(full.log.find("No space left on device; nothing was run"), std::string::npos) << full.log;
    }
}

// A disk that fills while the cases run: at every point it can fill (before the
// first trace row, inside the trace, at the results) the run ends with a clean
// error naming what could not be written, never SIGABRT; the trace left behind
// is a sound database; results.json of an earlier run is removed rather than
// left to be taken for this run's.
TEST(HostileInput, ADiskThatFillsDuringTheRunEndsItCleanly) {
    if (!can_mount_privately()) GTEST_SKIP() << "needs root and unshare -m for a small tmpfs";
    for (const std::string& size : {std::string("80k"), std::string("512k"), std::string("2m")}) {
        SCOPED_TRACE("tmpfs size " + size);
        const fs::path dir = rig::testing::fresh_dir("hostile-full-" + size);
        const fs::path out = dir / "fs" / "out";
        const fs::path trace = out / "cases" / "short-fusion" / "trace.sqlite";
        // After the run, in the namespace: what the trace holds, while the mount is still there.
        const std::string check = "; status=$?; sqlite3 " + quoted(trace) + " 'pragma integrity_check' > " +
                                  quoted(dir / "integrity.txt") + " 2>&1; ls " + quoted(out) + " > " +
                                  quoted(dir / "listing.txt") + "; exit $status";
        fs::create_directories(dir / "fs");
        const std::string script =
            "ip link set lo up && mount -t tmpfs -o size=" + size + " tmpfs " + quoted(dir / "fs") + " && mkdir " +
            quoted(out) + " && echo earlier > " + quoted(out / "results.json") + " && timeout -k 5 120 '" RIG_BINARY_DIR
            "/bin/rig' run '" RIG_SOURCE_DIR "/tests/data/short-fusion.yaml' --out " + quoted(out) + " > " +
            quoted(dir / "rig.log") + " 2>&1 < /dev/null" + check;
        std::ofstream(dir / "run.sh") << script << "\n";
        const int status = std::system(("unshare -m -n sh " + quoted(dir / "run.sh")).c_str());
        const int exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
        const std::string log = read_all(dir / "rig.log");
        EXPECT_EQ(log.find("terminate called"), std::string::npos) << log;
        const bool no_space = log.find("No space left on device") != std::string::npos ||
                              log.find("database or disk is full") != std::string::npos;
        EXPECT_TRUE(no_space) << "the error must say why: " << log;
        // The case's own error is the disk, not a symptom (a digest that no longer matches its rows).
        EXPECT_NE(log.find("error: harness_error: trace " + trace.string() + ": database or disk is full"),
                  std::string::npos)
            << log;
        const std::string listing = read_all(dir / "listing.txt");
        if (exit_code == 4) {
            EXPECT_NE(log.find("rig: results not written: "), std::string::npos) << log;
            EXPECT_EQ(listing.find("results.json"), std::string::npos) << "the earlier run's results stay: " << listing;
        } else {
            // The probe passed and the trace filled, but the results still fit.
            EXPECT_EQ(exit_code, 1) << log;
            EXPECT_NE(listing.find("results.json"), std::string::npos) << listing;
        }
        const std::string integrity = read_all(dir / "integrity.txt");
        if (integrity.find("unable to open") == std::string::npos) {
            EXPECT_EQ(integrity, "ok\n") << "the trace left behind must be a sound database";
        }
    }
}

}  // namespace
