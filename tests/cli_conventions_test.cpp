// The `rig` command line's conventions (docs/running-cases.md), through the
// built executable:
//  * `rig --version` prints the version and the commit, exit 0;
//  * a usage error names the word at fault and exits 2;
//  * `rig run` says a line per case where it is not on a terminal (a CI log),
//    nothing but failures and the count with --quiet, more with --verbose;
//  * on a terminal (a pty from `script`) a status line with N of M and an
//    estimate, and the table in colour unless NO_COLOR is set;
//  * the bash completion `cmake --install` puts beside the rig lists its subcommands.
#include <gtest/gtest.h>

#include "run_support.h"

#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>
#include <string>

namespace {

namespace fs = std::filesystem;
using rig::testing::read_all;

const std::string kRig = RIG_BINARY_DIR "/bin/rig";

struct Outcome {
    int exit_code = -1;
    std::string out;  // standard output
    std::string err;  // standard error
};

fs::path scratch() {
    static const fs::path dir = rig::testing::fresh_dir("cli-conventions-" + std::to_string(::getpid()));
    return dir;
}

// `command` through sh, its standard output and error kept apart.
Outcome shell(const std::string& command, const std::string& tag) {
    const fs::path out = scratch() / (tag + ".out");
    const fs::path err = scratch() / (tag + ".err");
    const int status = std::system(("timeout -k 10 300 " + command + " > '" + out.string() + "' 2> '" + err.string() + "'").c_str());
    return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, read_all(out), read_all(err)};
}

Outcome rig(const std::string& args, const std::string& tag) { return shell("'" + kRig + "' " + args, tag); }

// `rig ARGS` on a pseudo-terminal (util-linux `script`): what the terminal showed.
Outcome rig_on_terminal(const std::string& environment, const std::string& args, const std::string& tag) {
    return shell("env " + environment + " script -qec \"'" + kRig + "' " + args + "\" /dev/null", tag);
}

// A copy of short-fusion.yaml (a 9 s lockstep case) named `name`, with its limit replaced by `limits`.
fs::path write_case(const std::string& name, const std::string& limits = "limits: { breakpoint_error_m: 0.16 }") {
    std::string text = read_all(RIG_SOURCE_DIR "/tests/data/short-fusion.yaml");
    text.replace(text.find("name: short-fusion"), std::string("name: short-fusion").size(), "name: " + name);
    const std::string limit_line = "limits: { breakpoint_error_m: 0.16 }";
    text.replace(text.find(limit_line), limit_line.size(), limits);
    const fs::path file = scratch() / "suite" / (name + ".yaml");
    fs::create_directories(file.parent_path());
    std::ofstream(file) << text;
    return file;
}

std::string out_dir(const std::string& tag) { return " --out '" + (scratch() / tag).string() + "'"; }

// Before its cases a run removes the shared-memory segments of participants
// that were killed, and says so: the other tests running beside this one (they
// share /dev/shm) kill controllers on purpose. That note is not a case's line.
std::string without_shm_cleanup_note(const std::string& err) {
    return std::regex_replace(err, std::regex(R"(rig: removed \d+ Fast DDS shared-memory segment\(s\) [^\n]*\n)"), "");
}

TEST(CliConventions, VersionPrintsTheVersionAndCommit) {
    const Outcome version = rig("--version", "version");
    EXPECT_EQ(version.exit_code, 0) << version.err;
    EXPECT_TRUE(std::regex_match(version.out, std::regex("rig " RIG_PROJECT_VERSION
                                                         R"( \(commit ([0-9a-f]{40}(-dirty)?|unknown)\)\n)")))
        << version.out;
    EXPECT_EQ(version.err, "");
}

// Each usage error: exit 2, one line on standard error naming the word at fault, nothing on standard output.
TEST(CliConventions, UsageErrorsNameTheBadWordAndExit2) {
    const struct {
        std::string args;
        std::string says;
    } errors[] = {
        {"rnu", "rig: unknown command 'rnu' (did you mean 'run'? commands: run, judge, "},
        {"", "rig: missing command (commands: run, judge, "},
        {"--frob", "rig: unknown option '--frob'"},
        {"run --frob x.yaml", "rig run: unknown option '--frob'"},
        {"run", "rig run: cases is required"},
        {"run x.yaml --out", "rig run: --out: 1 required TEXT missing"},
        {"run x.yaml --jobs 99", "rig run: --jobs: Value 99 not in range"},
        {"run x.yaml --jobs many", "rig run: --jobs: Value many not in range"},
        {"run x.yaml --quiet --verbose", "rig run: --quiet excludes --verbose"},
        {"nmea decdoe file.nmea", "rig nmea: unknown command 'decdoe' (did you mean 'decode'? commands: decode)"},
        {"modbus", "rig modbus: missing command (commands: serve)"},
        {"dds-check extra", "rig dds-check: unexpected argument 'extra'"},
    };
    int i = 0;
    for (const auto& error : errors) {
        SCOPED_TRACE("rig " + error.args);
        const Outcome outcome = rig(error.args, "usage-" + std::to_string(i++));
        EXPECT_EQ(outcome.exit_code, 2) << outcome.err;
        EXPECT_EQ(outcome.err.rfind(error.says, 0), 0u) << outcome.err;
        EXPECT_EQ(std::count(outcome.err.begin(), outcome.err.end(), '\n'), 1) << outcome.err;
        EXPECT_EQ(outcome.out, "");
    }
    // Asking for help is not an error.
    EXPECT_EQ(rig("--help", "help").exit_code, 0);
    EXPECT_EQ(rig("run --help", "run-help").exit_code, 0);
}

// Not on a terminal (a CI log): a line per case on standard error, as each ends; the table on standard output.
TEST(CliConventions, OffATerminalALinePerCaseAndNoColour) {
    const fs::path passes = write_case("passes");
    const Outcome run = rig("run '" + passes.string() + "'" + out_dir("plain"), "plain");
    ASSERT_EQ(run.exit_code, 0) << run.err;
    EXPECT_TRUE(std::regex_match(without_shm_cleanup_note(run.err),
                                 std::regex(R"(rig: \[PASS\] passes \([0-9.e-]+ s wall\)\n)")))
        << run.err;
    EXPECT_EQ(run.err.find('\r'), std::string::npos) << run.err;
    EXPECT_NE(run.out.find("passes  PASS"), std::string::npos) << run.out;
    EXPECT_EQ(run.out.find('\033'), std::string::npos) << run.out;
    EXPECT_NE(run.out.find("results: "), std::string::npos) << run.out;
}

TEST(CliConventions, QuietSaysOnlyTheFailuresAndTheCount) {
    const fs::path passes = write_case("passes");
    const fs::path fails = write_case("fails", "limits: { breakpoint_error_m: 0.0001 }");
    const Outcome run = rig("run --quiet '" + passes.string() + "' '" + fails.string() + "'" + out_dir("quiet"), "quiet");
    EXPECT_EQ(run.exit_code, 1) << run.err;
    EXPECT_TRUE(std::regex_match(run.out, std::regex(R"(FAIL fails: breakpoint_error_m [0-9.e-]+ > 0\.0001\n1 passed, 1 failed\n)")))
        << run.out;
    EXPECT_EQ(run.err, "");
}

TEST(CliConventions, VerboseSaysEachCaseAsItStartsAndItsDetails) {
    const fs::path passes = write_case("passes");
    const Outcome run = rig("run -v '" + passes.string() + "'" + out_dir("verbose"), "verbose");
    ASSERT_EQ(run.exit_code, 0) << run.err;
    EXPECT_NE(run.err.find("rig: start passes (seed 5, lockstep, " + passes.string() + ")\n"), std::string::npos)
        << run.err;
    EXPECT_NE(run.err.find("rig: [PASS] passes ("), std::string::npos) << run.err;
    EXPECT_NE(run.out.find("passes  PASS"), std::string::npos) << run.out;
    EXPECT_NE(run.out.find("== passes (" + passes.string() + ")\n"), std::string::npos) << run.out;
    EXPECT_NE(run.out.find("metrics:\n  breakpoint_error_m = "), std::string::npos) << run.out;
}

// On a terminal: the status line (N of M, elapsed, then an estimate once a case
// has ended) above which each ended case's line scrolls; colour unless NO_COLOR.
TEST(CliConventions, OnATerminalAStatusLineAndColourUnlessNoColor) {
    const std::string cases = "'" + write_case("first").string() + "' '" + write_case("second").string() + "'";
    const Outcome coloured = rig_on_terminal("-u NO_COLOR", "run " + cases + out_dir("tty"), "tty");
    EXPECT_EQ(coloured.exit_code, 0) << coloured.out << coloured.err;
    const std::string& shown = coloured.out;
    EXPECT_NE(shown.find("\rrig: [1/2] first "), std::string::npos) << shown;
    EXPECT_NE(shown.find(" elapsed, no estimate yet"), std::string::npos) << shown;
    EXPECT_NE(shown.find("\rrig: [2/2] second "), std::string::npos) << shown;
    EXPECT_TRUE(std::regex_search(shown, std::regex(R"(elapsed, about \d+:\d\d left)"))) << shown;
    EXPECT_NE(shown.find("rig: [PASS] first ("), std::string::npos) << shown;
    EXPECT_NE(shown.find("\033[32mPASS"), std::string::npos) << shown;

    const Outcome plain = rig_on_terminal("NO_COLOR=1", "run " + cases + out_dir("tty-no-color"), "tty-no-color");
    EXPECT_EQ(plain.exit_code, 0) << plain.out << plain.err;
    EXPECT_NE(plain.out.find("\rrig: [1/2] first "), std::string::npos) << plain.out;
    EXPECT_NE(plain.out.find("PASS"), std::string::npos) << plain.out;
    EXPECT_EQ(plain.out.find('\033'), std::string::npos) << plain.out;

    // --quiet on a terminal: no status line either.
    const Outcome quiet = rig_on_terminal("-u NO_COLOR", "run -q " + cases + out_dir("tty-quiet"), "tty-quiet");
    EXPECT_EQ(quiet.exit_code, 0) << quiet.out << quiet.err;
    EXPECT_EQ(quiet.out, "2 passed, 0 failed\r\n") << quiet.out;  // the terminal shows \n as \r\n
}

// A real-time case runs on the wall clock (about 16 s here): the status line
// shows its clock against its length as it goes. Registered apart and alone
// (tests/CMakeLists.txt), like every real-time run.
TEST(CliConventionsRealTime, ARealTimeCaseShowsItsClockOnATerminal) {
    const fs::path file = write_case("real-time-clock");
    std::string text = read_all(file);
    text.replace(text.find("seed: 5"), std::string("seed: 5").size(), "seed: 5\nmode: realtime");
    text.replace(text.find("accel_m_s2: 0.5, start_m: -8"), std::string("accel_m_s2: 0.5, start_m: -8").size(),
                 "accel_m_s2: 2.0, start_m: -6");
    std::ofstream(file) << text;
    const Outcome run = rig_on_terminal("NO_COLOR=1", "run '" + file.string() + "'" + out_dir("tty-realtime"), "tty-realtime");
    EXPECT_NE(run.out.find("rig: [1/1] real-time-clock (real time) "), std::string::npos) << run.out;
    // Its clock moves: two different readings of it, each against the case's length.
    std::set<std::string> readings;
    const std::regex clock(R"(\(real time\) t (\d+\.\d)/(\d+\.\d) s \|)");
    for (auto it = std::sregex_iterator(run.out.begin(), run.out.end(), clock); it != std::sregex_iterator(); ++it) {
        EXPECT_LE(std::stod((*it)[1]), std::stod((*it)[2]) + 0.5) << (*it)[0];
        readings.insert((*it)[1]);
    }
    EXPECT_GE(readings.size(), 2u) << run.out;
}

// The subcommands in `rig [COMMAND...] --help`.
std::set<std::string> subcommands_in_help(const std::string& args, const std::string& tag) {
    const Outcome help = rig(args + " --help", tag);
    std::set<std::string> names;
    std::istringstream lines(help.out);
    std::string line;
    bool in_subcommands = false;
    while (std::getline(lines, line)) {
        if (line == "Subcommands:") {
            in_subcommands = true;
        } else if (in_subcommands && line.rfind("  ", 0) == 0) {
            names.insert(line.substr(2, line.find(' ', 2) - 2));
        } else if (in_subcommands) {
            in_subcommands = false;
        }
    }
    return names;
}

// The completion installed with the rig, asked what follows `rig WORDS...` as bash would.
std::set<std::string> completions(const fs::path& prefix, const std::string& words, const std::string& tag) {
    const fs::path script = scratch() / (tag + ".sh");
    std::ofstream(script) << "source '" << (prefix / "share/bash-completion/completions/rig").string() << "'\n"
                          << "COMP_WORDS=('" << (prefix / "bin/rig").string() << "' " << words << ")\n"
                          << "COMP_CWORD=$((${#COMP_WORDS[@]} - 1))\n"
                          << "_rig\nprintf '%s\\n' \"${COMPREPLY[@]}\"\n";
    const Outcome outcome = shell("bash '" + script.string() + "'", tag);
    EXPECT_EQ(outcome.exit_code, 0) << outcome.err;
    std::set<std::string> words_out;
    std::istringstream lines(outcome.out);
    for (std::string line; std::getline(lines, line);) {
        if (!line.empty()) words_out.insert(line);
    }
    return words_out;
}

TEST(CliConventions, TheInstalledBashCompletionListsTheSubcommandsAndOptions) {
    const fs::path prefix = scratch() / "prefix";
    const Outcome install = shell("cmake --install '" RIG_BINARY_DIR "' --prefix '" + prefix.string() + "'", "install");
    ASSERT_EQ(install.exit_code, 0) << install.out << install.err;
    ASSERT_TRUE(fs::exists(prefix / "share/bash-completion/completions/rig"));

    const std::set<std::string> commands = subcommands_in_help("", "help-top");
    for (const char* expected : {"run", "judge", "bench", "nmea", "modbus", "dds-check"}) {
        EXPECT_TRUE(commands.count(expected)) << expected;
    }
    EXPECT_EQ(completions(prefix, "''", "complete-top"), commands);
    EXPECT_EQ(completions(prefix, "ju", "complete-ju"), std::set<std::string>{"judge"});
    EXPECT_EQ(completions(prefix, "nmea ''", "complete-nmea"), subcommands_in_help("nmea", "help-nmea"));
    const std::set<std::string> run_options = completions(prefix, "run --out x --", "complete-run");
    for (const char* expected : {"--out", "--jobs", "--seed", "--quiet", "--verbose", "--in-process", "--help"}) {
        EXPECT_TRUE(run_options.count(expected)) << expected;
    }
    // A case file after `rig run`: paths.
    EXPECT_EQ(completions(prefix, "run '" RIG_SOURCE_DIR "/tests/data/short-fu'", "complete-file"),
              std::set<std::string>{RIG_SOURCE_DIR "/tests/data/short-fusion.yaml"});
}

}  // namespace
