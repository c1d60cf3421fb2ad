// `rig nmea decode FILE|-`: decodes a stream of NMEA lines (a receiver capture,
// a gpsd regression log) into one JSON object per line, for people and scripts.
#pragma once

#include <filesystem>
#include <iosfwd>
#include <string>

#include "harness/cli/subcommand.h"

namespace rig::nmea {

// Reads `in` line by line and writes one JSON object per input line to `out`:
// the decoded sentence, e.g.
//   {"talker":"GP","type":"GGA","decoded":true,"utc_time":"12:35:19.000",...}
// (only the fields present in the sentence; undecoded types carry "fields"), or
//   {"error":"<message>","code":"<ParseErrorCode>","line":N}   (N is 1-based).
// Blank lines and lines starting with '#' (comments in the gpsd logs) produce
// nothing.  Lines of any length and any bytes are fine.
// Returns 0 if every non-skipped line decoded, 1 otherwise.
int decode_stream(std::istream& in, std::ostream& out);

// `rig nmea decode FILE`: decode_stream() over a regular file. A directory, a
// FIFO, a device or a missing file is refused with one line on `err` naming
// the path and what it is ("rig nmea decode: x: is a directory, expected a
// regular file (NMEA capture)"), exit status 2; a FIFO would otherwise block
// and a device never end. Standard input ("-") is decode_stream(std::cin, ...).
int decode_file(const std::filesystem::path& file, std::ostream& out, std::ostream& err);

}  // namespace rig::nmea

namespace rig::harness {

// `rig nmea decode FILE|-`.
class NmeaCommand final : public Subcommand {
public:
    explicit NmeaCommand(CLI::App& app);
    NmeaCommand(const NmeaCommand&) = delete;  // CLI11 holds pointers into input_
    NmeaCommand& operator=(const NmeaCommand&) = delete;
    bool parsed() const override;
    int run() override;

private:
    CLI::App* decode_ = nullptr;
    std::string input_;
};

}  // namespace rig::harness
