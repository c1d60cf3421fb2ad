// Serial ports and pseudo-terminals: settings and wire time, error text for bad
// paths, raw byte-exact transfer through a PtyLink both ways (with
// backpressure), line reading, and a closed peer turning into a clear "port
// closed" error instead of a hang or a spin.
#include <gtest/gtest.h>

#include <fcntl.h>
#include <termios.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "rig/wire/pty_pair.h"
#include "rig/wire/serial_port.h"

namespace rig {
namespace {

namespace fs = std::filesystem;
using std::chrono::milliseconds;

// Generous: these tests must not flake on a loaded 2-core machine. They bound a
// failure, they are never waited out on success.
constexpr milliseconds kGenerous{10'000};

fs::path fresh_dir(const std::string& name) {
    const fs::path dir = fs::path(::testing::TempDir()) / ("serial-port-" + name);
    fs::remove_all(dir);
    fs::create_directories(dir);
    return dir;
}

// Reads until `count` bytes arrived (or the generous bound passed).
std::string read_exactly(SerialPort& port, std::size_t count) {
    std::string received;
    while (received.size() < count) {
        const std::string chunk = port.read_some(kGenerous, count - received.size());
        if (chunk.empty()) break;  // timed out: the caller's comparison fails
        received += chunk;
    }
    return received;
}

template <class Action>
SerialError expect_serial_error(Action action) {
    try {
        action();
    } catch (const SerialError& error) {
        return error;
    }
    ADD_FAILURE() << "no SerialError thrown";
    return SerialError(SerialError::Kind::io, "-", "-");
}

TEST(SerialSettings, BitsPerCharacterAndWireTime) {
    SerialSettings settings;  // 115200 8N1
    EXPECT_EQ(describe(settings), "115200 8N1");
    EXPECT_EQ(bits_per_character(settings), 10);
    apply_frame_format("7E1", settings);
    EXPECT_EQ(bits_per_character(settings), 10);
    apply_frame_format("8o2", settings);
    EXPECT_EQ(bits_per_character(settings), 12);
    EXPECT_EQ(describe(settings), "115200 8O2");
    apply_frame_format("5N1", settings);
    EXPECT_EQ(bits_per_character(settings), 7);

    SerialSettings nmea{9600, 8, Parity::none, 1};
    EXPECT_EQ(wire_time_ns(82, nmea), 85'416'667);  // 820 bits / 9600 baud
    EXPECT_EQ(wire_time_ns(0, nmea), 0);
    EXPECT_EQ(wire_time_ns(1, SerialSettings{}), 86'806);       // 10 / 115200 s
    EXPECT_EQ(wire_time_ns(11'520, SerialSettings{}), 1'000'000'000);
}

TEST(SerialSettings, EveryRequiredBaudIsSupported) {
    const auto bauds = supported_bauds();
    for (int baud : {4800, 9600, 19200, 38400, 57600, 115200, 230400, 460800, 921600}) {
        EXPECT_NE(std::find(bauds.begin(), bauds.end(), baud), bauds.end()) << baud;
        EXPECT_NO_THROW(validate(SerialSettings{baud, 8, Parity::none, 1})) << baud;
    }
}

TEST(SerialSettings, BadValuesAreNamed) {
    try {
        validate(SerialSettings{12345, 8, Parity::none, 1});
        FAIL();
    } catch (const std::invalid_argument& error) {
        EXPECT_NE(std::string(error.what()).find("baud 12345 is not supported (supported: 1200,"), std::string::npos)
            << error.what();
    }
    EXPECT_THROW(validate(SerialSettings{9600, 9, Parity::none, 1}), std::invalid_argument);
    EXPECT_THROW(validate(SerialSettings{9600, 8, Parity::none, 3}), std::invalid_argument);
    SerialSettings settings;
    for (const char* bad : {"8N", "9N1", "8X1", "8N3", "8N1x", ""}) {
        try {
            apply_frame_format(bad, settings);
            ADD_FAILURE() << bad;
        } catch (const std::invalid_argument& error) {
            EXPECT_NE(std::string(error.what()).find(std::string("'") + bad + "'"), std::string::npos) << error.what();
        }
    }
}

TEST(SerialPortErrors, MissingDeviceNamesPathAndCause) {
    const SerialError error = expect_serial_error([] { SerialPort port("/dev/ttyRIG-does-not-exist"); });
    EXPECT_EQ(error.kind(), SerialError::Kind::not_found);
    EXPECT_EQ(std::string(error.what()),
              "serial port /dev/ttyRIG-does-not-exist: no such file or device (is the adapter plugged in? is the "
              "path right?)");
}

TEST(SerialPortErrors, NotATerminal) {
    const SerialError null_device = expect_serial_error([] { SerialPort port("/dev/null"); });
    EXPECT_EQ(null_device.kind(), SerialError::Kind::not_a_tty);
    EXPECT_NE(std::string(null_device.what()).find("serial port /dev/null: not a terminal device"), std::string::npos)
        << null_device.what();

    const fs::path dir = fresh_dir("not-a-tty");
    const fs::path file = dir / "plain-file";
    std::ofstream(file) << "not a tty";
    const SerialError plain = expect_serial_error([&] { SerialPort port(file.string()); });
    EXPECT_EQ(plain.kind(), SerialError::Kind::not_a_tty);
    EXPECT_NE(std::string(plain.what()).find(file.string()), std::string::npos);

    const SerialError directory = expect_serial_error([&] { SerialPort port(dir.string()); });
    EXPECT_EQ(directory.kind(), SerialError::Kind::not_a_tty);
    EXPECT_NE(std::string(directory.what()).find("is a directory"), std::string::npos) << directory.what();
}

TEST(SerialPortErrors, PermissionDenied) {
    if (::geteuid() == 0) GTEST_SKIP() << "root opens any device node; permission errors cannot be produced";
    PtyPair pty;
    ASSERT_EQ(::chmod(pty.slave_path().c_str(), 0), 0);
    const SerialError error = expect_serial_error([&] { SerialPort port(pty.slave_path()); });
    EXPECT_EQ(error.kind(), SerialError::Kind::permission_denied);
    EXPECT_NE(std::string(error.what()).find(pty.slave_path() + ": permission denied"), std::string::npos)
        << error.what();
}

TEST(SerialPortErrors, UnsupportedBaud) {
    PtyPair pty;
    const SerialError error =
        expect_serial_error([&] { SerialPort port(pty.slave_path(), SerialSettings{12345, 8, Parity::none, 1}); });
    EXPECT_EQ(error.kind(), SerialError::Kind::unsupported);
    EXPECT_NE(std::string(error.what()).find("baud 12345"), std::string::npos) << error.what();
}

TEST(SerialPort, AppliesEachBaudAndFrameRaw) {
    PtyPair pty;
    for (int baud : {4800, 9600, 19200, 38400, 57600, 115200, 230400, 460800, 921600}) {
        for (const char* frame : {"8N1", "7E1", "8O2"}) {
            SerialSettings settings{baud, 8, Parity::none, 1};
            apply_frame_format(frame, settings);
            SerialPort port(pty.slave_path(), settings);
            termios applied{};
            ASSERT_EQ(::tcgetattr(port.native_handle(), &applied), 0);
            EXPECT_EQ(::cfgetospeed(&applied), ::cfgetispeed(&applied));
            EXPECT_EQ(applied.c_lflag & (ECHO | ICANON | ISIG), 0u) << baud << " " << frame;
            EXPECT_EQ(applied.c_oflag & OPOST, 0u);
            EXPECT_EQ(applied.c_iflag & (ICRNL | IXON), 0u);
            EXPECT_EQ((applied.c_cflag & CSTOPB) != 0, settings.stop_bits == 2);
            // A Linux pty keeps 8 data bits without parity whatever is asked:
            // the frame is nominal there, and the port reports what was asked.
            EXPECT_EQ(port.settings().baud, baud);
            EXPECT_EQ(port.settings().data_bits, settings.data_bits);
            EXPECT_EQ(port.settings().parity, settings.parity);
        }
    }
}

TEST(PtyLink, BytesPassBothWaysUnchanged) {
    PtyLink link;
    SerialPort a(link.slave_path_a());
    SerialPort b(link.slave_path_b());
    EXPECT_NE(link.slave_path_a(), link.slave_path_b());

    a.write_all("hello\r\n", kGenerous);
    EXPECT_EQ(b.read_line(kGenerous), "hello");
    b.write_all("back\n", kGenerous);
    EXPECT_EQ(a.read_line(kGenerous), "back");

    // Every byte value, CR and LF included, arrives as sent: no translation.
    std::string all_bytes;
    for (int value = 0; value < 256; ++value) all_bytes += static_cast<char>(value);
    a.write_all(all_bytes, kGenerous);
    EXPECT_EQ(read_exactly(b, all_bytes.size()), all_bytes);
    // No echo: nothing came back to the writer.
    EXPECT_EQ(a.read_some(milliseconds(200)), "");
    EXPECT_EQ(link.bytes_a_to_b(), 7u + 256u);
    EXPECT_FALSE(link.error());
}

TEST(PtyLink, LargeTransferWithBackpressureLosesNothing) {
    PtyLink link;
    SerialPort a(link.slave_path_a());
    SerialPort b(link.slave_path_b());
    std::mt19937 random(7);
    std::string payload(1 << 20, '\0');
    for (char& c : payload) c = static_cast<char>(random() & 0xFF);

    // The writer fills every buffer on the way and must wait for the reader.
    std::string received;
    std::thread reader([&] { received = read_exactly(b, payload.size()); });
    a.write_all(payload, milliseconds(60'000));
    reader.join();
    ASSERT_EQ(received.size(), payload.size());
    EXPECT_TRUE(received == payload);
}

TEST(SerialPort, ReadLineKeepsPartialLinesAndSplitsEndlessOnes) {
    PtyLink link;
    SerialPort a(link.slave_path_a());
    SerialPort b(link.slave_path_b());
    a.write_all("abc", kGenerous);
    EXPECT_EQ(b.read_line(milliseconds(300)), std::nullopt);  // incomplete: kept
    a.write_all("def\r\nsecond\nthird", kGenerous);
    EXPECT_EQ(b.read_line(kGenerous), "abcdef");
    EXPECT_EQ(b.read_line(kGenerous), "second");
    EXPECT_EQ(b.read_some(kGenerous), "third");  // read_some hands out buffered bytes first

    const std::string endless(SerialPort::kMaxLineBytes + 10, 'x');
    a.write_all(endless + "\n", kGenerous);
    EXPECT_EQ(b.read_line(kGenerous), std::string(SerialPort::kMaxLineBytes, 'x'));
    EXPECT_EQ(b.read_line(kGenerous), std::string(10, 'x'));
}

TEST(SerialPort, ReadTimesOutEmptyWhenNothingArrives) {
    PtyLink link;
    SerialPort b(link.slave_path_b());
    EXPECT_EQ(b.read_some(milliseconds(50)), "");
    EXPECT_EQ(b.read_some(milliseconds(0)), "");
    EXPECT_EQ(b.read_line(milliseconds(50)), std::nullopt);
}

TEST(SerialPort, ClosedPeerIsAClearErrorNotAHang) {
    auto link = std::make_unique<PtyLink>();
    const std::string path = link->slave_path_a();
    SerialPort a(path);
    link.reset();  // the other end of the cable is gone: both masters closed

    // The reads must fail at once with the cause; a hang would hit the
    // generous timeout and return "" instead of throwing.
    const SerialError read_error = expect_serial_error([&] { a.read_some(kGenerous); });
    EXPECT_EQ(read_error.kind(), SerialError::Kind::closed);
    EXPECT_NE(std::string(read_error.what()).find("serial port " + path + ": port closed"), std::string::npos)
        << read_error.what();
    // And keep failing the same way (no spin, no crash).
    EXPECT_EQ(expect_serial_error([&] { a.read_line(kGenerous); }).kind(), SerialError::Kind::closed);
    const SerialError write_error = expect_serial_error([&] { a.write_all("x", kGenerous); });
    EXPECT_EQ(write_error.kind(), SerialError::Kind::closed);
    EXPECT_NE(std::string(write_error.what()).find("port closed"), std::string::npos) << write_error.what();
}

TEST(SerialPort, SinglePtyPeerClosedWhileReading) {
    auto pty = std::make_unique<PtyPair>();
    SerialPort slave(pty->slave_path());
    std::vector<std::string> lines;
    std::optional<SerialError> error;
    // A reader blocked in read_line is woken by the hang-up, not by its timeout:
    // it gets the incomplete last line (if it read it before the hang-up), then
    // the error.
    std::thread reader([&] {
        try {
            while (true) {
                if (auto line = slave.read_line(milliseconds(60'000))) lines.push_back(*line);
            }
        } catch (const SerialError& caught) {
            error = caught;
        }
    });
    pty->master().write_all("partial", kGenerous);
    std::this_thread::sleep_for(milliseconds(100));  // the test's own wait, not the rig's
    pty.reset();
    reader.join();
    ASSERT_TRUE(error.has_value());
    EXPECT_EQ(error->kind(), SerialError::Kind::closed);
    EXPECT_LE(lines.size(), 1u);
    if (!lines.empty()) {
        EXPECT_EQ(lines[0], "partial");
    }
}

TEST(SerialPort, WriteTimesOutWhenNobodyReads) {
    PtyLink link;
    SerialPort a(link.slave_path_a());  // nobody reads b: buffers fill up
    const std::string chunk(4096, 'z');
    std::size_t written = 0;
    const SerialError error = expect_serial_error([&] {
        while (written < (64u << 20)) {
            a.write_all(chunk, milliseconds(200));
            written += chunk.size();
        }
    });
    EXPECT_EQ(error.kind(), SerialError::Kind::timeout);
    EXPECT_NE(std::string(error.what()).find("write timed out after 200 ms"), std::string::npos) << error.what();
    EXPECT_GT(written, 0u);
}

TEST(PtyPair, MasterAndSlaveTalkAndSymlinkComesAndGoes) {
    const fs::path dir = fresh_dir("symlink");
    const fs::path link_path = dir / "gnss0";
    std::string slave_path;
    {
        PtyPair pty(PtyOptions{SerialSettings{9600, 8, Parity::none, 1}, link_path});
        slave_path = pty.slave_path();
        EXPECT_TRUE(slave_path.starts_with("/dev/pts/")) << slave_path;
        ASSERT_TRUE(fs::is_symlink(link_path));
        EXPECT_EQ(fs::read_symlink(link_path), slave_path);
        EXPECT_EQ(pty.public_path(), link_path.string());
        EXPECT_EQ(pty.master().settings().baud, 9600);

        SerialPort other(link_path.string());  // what gpsd or a terminal would do
        pty.master().write_all("$GPGGA\r\n", kGenerous);
        EXPECT_EQ(other.read_line(kGenerous), "$GPGGA");
        other.write_all("reply\n", kGenerous);
        EXPECT_EQ(pty.master().read_line(kGenerous), "reply");
    }
    EXPECT_FALSE(fs::exists(fs::symlink_status(link_path)));
}

TEST(PtyPair, ReplacesAStaleSymlinkButNotAFile) {
    const fs::path dir = fresh_dir("stale");
    const fs::path stale = dir / "tty";
    fs::create_symlink("/dev/pts/does-not-exist", stale);
    {
        PtyPair pty(PtyOptions{{}, stale});
        EXPECT_EQ(fs::read_symlink(stale), pty.slave_path());
    }
    const fs::path file = dir / "somebodys-file";
    std::ofstream(file) << "keep me";
    try {
        PtyPair pty(PtyOptions{{}, file});
        FAIL() << "replaced a regular file";
    } catch (const std::runtime_error& error) {
        EXPECT_NE(std::string(error.what()).find(file.string() + ": the path exists and is not a symlink"),
                  std::string::npos)
            << error.what();
    }
    EXPECT_TRUE(fs::is_regular_file(file));
    try {
        PtyPair pty(PtyOptions{{}, dir / "missing-dir" / "tty"});
        FAIL() << "symlink in a missing directory";
    } catch (const std::runtime_error& error) {
        EXPECT_NE(std::string(error.what()).find("cannot make symlink"), std::string::npos) << error.what();
    }
}

TEST(PtyLink, StopsPromptlyAndTwice) {
    PtyLink link;
    SerialPort a(link.slave_path_a());
    a.write_all("in flight", kGenerous);
    link.stop();
    link.stop();  // idempotent
    EXPECT_FALSE(link.error());
}

}  // namespace
}  // namespace rig
