#pragma once
// The case's `board:` section: how the rig treats a board on real wires
// (docs/modbus-register-map.md "External boards"). Parsed with the case file;
// no DDS and no I/O here, so the fuzzed case-file loader links it.
//
//   board:
//     attach_timeout_s: 60     # controller: external — wait this long for the board before time starts
//     silence_timeout_s: 2     # a Modbus master quiet this long fails the case (board_silent)
//     failsafe_timeout_s: 1    # the rig's I/O watchdog: coils go to `failsafe` this long after the last request
//     failsafe: safe           # safe (every coil de-energised) or hold
//     line_noise:              # Modbus RTU only: the line damages the slave's responses (emulators/wire_faults.h)
//       corrupt_response_pct: 2  #   of responses with a byte hit (the master sees a bad CRC)
//       noise_burst_pct: 1       #   of responses followed by 1-8 random bytes on the line
#include "rig/config/yaml_fields.h"
#include "rig/wire/modbus_protocol.h"

namespace rig::harness {

struct BoardSpec {
    // Wall time from the attach line to the board's first valid Modbus request
    // (and its opening of the NMEA pty); 0.5 s .. 1 h. 60 s: time for a person
    // to start a board's firmware or a bench script after reading the line.
    double attach_timeout_s = 60.0;
    // Longest wall-time gap between valid Modbus requests during the case;
    // 0.05 .. 600 s. 2 s: ten times the slowest poll a controller of a 0.2 s
    // GNSS epoch can use and still act on each fix.
    double silence_timeout_s = 2.0;
    // The rig's comms-loss watchdog (rig/wire/modbus_protocol.h CommsFailsafe);
    // 0 = off, else 0.05 .. 600 s. 1 s: common I/O-module default (a few
    // hundred ms to seconds), and shorter than silence_timeout_s, so the plant
    // is already safe when the case fails on the silence.
    double failsafe_timeout_s = 1.0;
    modbus::FailsafeMode failsafe = modbus::FailsafeMode::safe;
    // Noise on the RTU line, percent of the slave's responses, each [0, 100],
    // 0 = off (the default): drawn from the case seed on its own stream.
    struct LineNoise {
        double corrupt_response_pct = 0.0;
        double noise_burst_pct = 0.0;
        bool any() const { return corrupt_response_pct > 0.0 || noise_burst_pct > 0.0; }
    } line_noise;
};

BoardSpec read_board_spec(const YamlSection& section);

}  // namespace rig::harness
