// NMEA on a tty: the sink puts encoder output on a pty byte for byte, accounts
// wire time at the port's baud, refuses unframed input without writing
// anything, and turns a full output buffer into a bounded error.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "rig/nmea/nmea_encoder.h"
#include "emulators/nmea_serial_sink.h"
#include "rig/wire/pty_pair.h"
#include "rig/wire/serial_port.h"

namespace rig::emulators {
namespace {

using std::chrono::milliseconds;
constexpr milliseconds kGenerous{10'000};

nmea::GnssFix rtk_fix() {
    nmea::GnssFix fix;
    fix.year = 2023;
    fix.month = 7;
    fix.day = 15;
    fix.utc_seconds_of_day = 7200.2;
    fix.lat_deg = 40.18;
    fix.lon_deg = 116.44;
    fix.altitude_msl_m = 50.0;
    fix.geoid_separation_m = -8.0;
    fix.fix_quality = 4;
    fix.satellites = 14;
    fix.hdop = 0.8;
    fix.speed_m_s = 1.667;
    fix.course_deg = 90.0;
    fix.differential_age_s = 1.0;
    fix.station_id = 1;
    return fix;
}

std::string read_exactly(SerialPort& port, std::size_t count) {
    std::string received;
    while (received.size() < count) {
        const std::string chunk = port.read_some(kGenerous, count - received.size());
        if (chunk.empty()) break;
        received += chunk;
    }
    return received;
}

TEST(NmeaSerialSink, PutsSentencesOnTheWireByteForByte) {
    PtyPair pty(PtyOptions{SerialSettings{9600, 8, Parity::none, 1}, {}});
    SerialPort receiver(pty.slave_path());  // the controller's side of the RS232 line
    NmeaSerialSink sink(pty.master());

    const std::string gga = nmea::encode_gga("GP", rtk_fix());
    const std::string rmc = nmea::encode_rmc("GP", rtk_fix());
    const TimeNs gga_wire_ns = sink.write_sentence(gga);
    EXPECT_EQ(gga_wire_ns, wire_time_ns(gga.size(), pty.master().settings()));
    // 10 bits per byte at 9600 baud: about 1.04 ms per byte.
    EXPECT_EQ(gga_wire_ns, static_cast<TimeNs>((gga.size() * 10 * 1'000'000'000ull + 4800) / 9600));
    EXPECT_EQ(read_exactly(receiver, gga.size()), gga);

    const std::vector<std::string> epoch{gga, rmc};
    const TimeNs epoch_wire_ns = sink.write_epoch(epoch);
    EXPECT_EQ(epoch_wire_ns, sink.wire_time_ns(gga.size() + rmc.size()));
    EXPECT_EQ(read_exactly(receiver, gga.size() + rmc.size()), gga + rmc);
    EXPECT_EQ(sink.sentences_written(), 3u);
    EXPECT_EQ(sink.bytes_written(), 2 * gga.size() + rmc.size());
}

TEST(NmeaSerialSink, WireTimeFollowsBaudAndFrame) {
    PtyPair fast(PtyOptions{SerialSettings{115200, 8, Parity::none, 1}, {}});
    PtyPair even(PtyOptions{SerialSettings{9600, 8, Parity::even, 1}, {}});
    NmeaSerialSink fast_sink(fast.master());
    NmeaSerialSink even_sink(even.master());
    EXPECT_EQ(fast_sink.wire_time_ns(82), 7'118'056);   // 820 bits / 115200
    EXPECT_EQ(even_sink.wire_time_ns(82), 93'958'333);  // 82 * 11 bits / 9600
}

TEST(NmeaSerialSink, RefusesUnframedSentencesWithoutWriting) {
    PtyPair pty;
    SerialPort receiver(pty.slave_path());
    NmeaSerialSink sink(pty.master());
    const std::string good = nmea::with_checksum("GPHDT,,T");
    struct Case {
        std::string sentence;
        std::string reason;  // expected in the error
    };
    const std::vector<Case> cases{
        {"", "empty sentence"},
        {"GPHDT,,T*1B\r\n", "does not start with '$' or '!'"},
        {"$GPHDT,,T*1B", "does not end with CR LF"},
        {"$GPHDT,,T*1B\n", "does not end with CR LF"},
        {"$GPHDT,,T\r\n", "no '*HH' checksum before CR LF"},
        {"$GPHDT,,T*1G\r\n", "no '*HH' checksum before CR LF"},
        {"$GPHDT\r\n,,T*1B\r\n", "CR or LF inside the sentence"},
    };
    for (const auto& bad : cases) {
        try {
            sink.write_sentence(bad.sentence);
            ADD_FAILURE() << "accepted " << bad.sentence;
        } catch (const std::invalid_argument& error) {
            const std::string text = error.what();
            EXPECT_NE(text.find(bad.reason), std::string::npos) << text;
            EXPECT_NE(text.find(pty.master().path()), std::string::npos) << text;
        }
    }
    // An epoch with one bad sentence is refused whole: not even the good one goes out.
    const std::vector<std::string> epoch{good, "$GPRMC,broken"};
    try {
        sink.write_epoch(epoch);
        ADD_FAILURE() << "accepted a broken epoch";
    } catch (const std::invalid_argument& error) {
        EXPECT_NE(std::string(error.what()).find("sentence 2 of 2"), std::string::npos) << error.what();
    }
    EXPECT_EQ(receiver.read_some(milliseconds(200)), "");
    EXPECT_EQ(sink.sentences_written(), 0u);

    // A wrong checksum value is a fault a case may inject: framed, so written.
    sink.write_sentence("$GPHDT,,T*00\r\n");
    EXPECT_EQ(receiver.read_line(kGenerous), "$GPHDT,,T*00");
    // write_raw puts anything on the wire, unchecked.
    EXPECT_EQ(sink.write_raw("$GPGGA,12"), sink.wire_time_ns(9));
    EXPECT_EQ(read_exactly(receiver, 9), "$GPGGA,12");
}

TEST(NmeaSerialSink, FullOutputBufferIsABoundedError) {
    PtyPair pty;  // nobody reads the slave: the queue fills up
    NmeaSerialSink sink(pty.master(), milliseconds(100));
    const std::string gga = nmea::encode_gga("GP", rtk_fix());
    std::size_t written = 0;
    try {
        while (written < 1'000'000) {
            sink.write_sentence(gga);
            ++written;
        }
        FAIL() << "a pty nobody reads took a million sentences";
    } catch (const SerialError& error) {
        EXPECT_EQ(error.kind(), SerialError::Kind::timeout) << error.what();
    }
    EXPECT_GT(written, 0u);
}

}  // namespace
}  // namespace rig::emulators
