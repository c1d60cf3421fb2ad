// `rig pty` as a person or a script uses it: it prints the two paths (and
// symlinks), bytes cross between them, SIGTERM ends it with status 0 and the
// symlinks go away; `--single` connects one pty to the rig's stdout.
#include <gtest/gtest.h>

#include <signal.h>

#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>
#include <thread>

#include "rig/host/child_process.h"
#include "rig/runtime/clock.h"
#include "rig/wire/serial_port.h"

namespace rig {
namespace {

namespace fs = std::filesystem;
using std::chrono::milliseconds;
constexpr milliseconds kGenerous{30'000};

fs::path fresh_dir(const std::string& name) {
    const fs::path dir = fs::path(::testing::TempDir()) / ("bench-serial-" + name);
    fs::remove_all(dir);
    fs::create_directories(dir);
    return dir;
}

std::string read_file(const fs::path& path) {
    std::ifstream in(path);
    std::stringstream text;
    text << in.rdbuf();
    return text.str();
}

// The rest of the line after `label` in `text` ("pty a: " -> "/dev/pts/5 (symlink /tmp/a)"),
// or nullopt while no complete such line is there.
std::optional<std::string> line_after(const std::string& text, const std::string& label) {
    const std::size_t start = text.find(label);
    if (start == std::string::npos) return std::nullopt;
    const std::size_t end = text.find('\n', start);
    if (end == std::string::npos) return std::nullopt;
    return text.substr(start + label.size(), end - start - label.size());
}

// Waits (bounded) until the log holds a complete line starting with `label`.
std::optional<std::string> wait_for_line(const fs::path& log, const std::string& label, std::string& text) {
    const WallStopwatch waited;
    while (waited.elapsed() < kGenerous) {
        text = read_file(log);
        if (auto line = line_after(text, label)) return line;
        std::this_thread::sleep_for(milliseconds(50));
    }
    return std::nullopt;
}

std::string stop_with_sigterm(ChildProcess& process) {
    ::kill(process.pid(), SIGTERM);
    return process.stop(milliseconds(10'000));
}

TEST(RigPty, LinkedPairCarriesBytesAndStopsCleanly) {
    const fs::path dir = fresh_dir("linked");
    const fs::path log = dir / "rig-pty.log";
    const fs::path link_a = dir / "controller-tty";
    const fs::path link_b = dir / "rig-tty";
    ChildProcess rig_pty({RIG_BINARY_DIR "/bin/rig", "pty", "--link-a", link_a.string(), "--link-b", link_b.string(),
                          "--baud", "9600"},
                         log);
    std::string text;
    const auto line_a = wait_for_line(log, "pty a: ", text);
    const auto line_b = wait_for_line(log, "pty b: ", text);
    ASSERT_TRUE(line_a && line_b) << "rig pty did not print its paths:\n" << text;
    // "/dev/pts/N (symlink PATH)"
    const std::string slave_a = line_a->substr(0, line_a->find(' '));
    const std::string slave_b = line_b->substr(0, line_b->find(' '));
    EXPECT_TRUE(slave_a.starts_with("/dev/pts/")) << *line_a;
    EXPECT_EQ(*line_a, slave_a + " (symlink " + link_a.string() + ")");
    EXPECT_EQ(*line_b, slave_b + " (symlink " + link_b.string() + ")");
    EXPECT_EQ(fs::read_symlink(link_a).string(), slave_a);
    EXPECT_EQ(fs::read_symlink(link_b).string(), slave_b);
    {
        SerialPort a(link_a.string());
        SerialPort b(slave_b);
        a.write_all("$GPGGA,hello*00\r\n", kGenerous);
        EXPECT_EQ(b.read_line(kGenerous), "$GPGGA,hello*00");
        b.write_all("back\n", kGenerous);
        EXPECT_EQ(a.read_line(kGenerous), "back");
    }
    EXPECT_EQ(stop_with_sigterm(rig_pty), "process exited with status 0");
    text = read_file(log);
    EXPECT_NE(text.find("stopped by SIGTERM: a->b 17 bytes, b->a 5 bytes"), std::string::npos) << text;
    EXPECT_FALSE(fs::exists(fs::symlink_status(link_a)));
    EXPECT_FALSE(fs::exists(fs::symlink_status(link_b)));
}

TEST(RigPty, SinglePtyGoesToStandardOutput) {
    const fs::path dir = fresh_dir("single");
    const fs::path log = dir / "rig-pty.log";
    ChildProcess rig_pty({RIG_BINARY_DIR "/bin/rig", "pty", "--single"}, log);
    std::string text;
    const auto slave = wait_for_line(log, "pty: ", text);
    ASSERT_TRUE(slave) << text;
    EXPECT_TRUE(slave->starts_with("/dev/pts/")) << *slave;
    {
        SerialPort controller(*slave);
        controller.write_all("from the controller\n", kGenerous);
        EXPECT_EQ(wait_for_line(log, "from the controller", text), "") << text;
    }
    EXPECT_EQ(stop_with_sigterm(rig_pty), "process exited with status 0");
}

TEST(RigPty, BadOptionsAreRefused) {
    const fs::path dir = fresh_dir("bad");
    for (const auto& [args, expected] :
         std::vector<std::pair<std::vector<std::string>, std::string>>{
             {{"--frame", "9Z1"}, "rig pty: serial frame format '9Z1'"},
             {{"--baud", "12345"}, "rig pty: baud 12345 is not supported"},
             {{"--single", "--link-b", (dir / "b").string()}, "--link-b needs two ptys"},
             {{"--link-a", (dir / "no-such-dir" / "a").string()}, "cannot make symlink"},
         }) {
        std::vector<std::string> argv{RIG_BINARY_DIR "/bin/rig", "pty"};
        argv.insert(argv.end(), args.begin(), args.end());
        const fs::path log = dir / "rig-pty.log";
        ChildProcess rig_pty(argv, log);
        const std::string how = rig_pty.stop(kGenerous);  // ends by itself
        EXPECT_NE(how, "process exited with status 0") << expected;
        EXPECT_NE(read_file(log).find(expected), std::string::npos) << read_file(log);
    }
}

}  // namespace
}  // namespace rig
