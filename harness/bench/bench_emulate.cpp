#include "harness/bench/bench_emulate.h"

#include <CLI/CLI.hpp>

#include <iostream>
#include <memory>

#include "harness/cli/cli_checks.h"
#include "emulators/gnss_g970.h"
#include "harness/systems/breakpoint/breakpoint_world.h"
#include "harness/systems/systems.h"
#include "rig/host/domain_lease.h"
#include "rig/wire/pty_pair.h"
#include "rig/runtime/realtime.h"
#include "rig/host/stop_signals.h"
#include "rig/wire/wire_adapters.h"

namespace rig::harness {

int run_emulate_gnss(const EmulateGnssOptions& options, std::ostream& out, std::ostream& err) {
    if (options.pty == !options.port.empty()) {
        err << "rig emulate gnss: give exactly one of --port DEVICE and --pty\n";
        return 2;
    }
    try {
        const CaseSpec spec = load_case_file(options.case_file);
        const StopSignals stop;  // before any thread starts (DDS, pty forwarding)
        // The G970II of a seed-000 case (a seed-001 case is refused, naming its file).
        const BreakpointSections& own = breakpoint_sections(spec);
        BreakpointWorld world = build_case_world(own, options.seed.value_or(spec.seed));
        check_case_timeline(spec, ns_to_seconds(world.end_ns), world.breakpoint_crossing_s);

        SerialSettings line;
        line.baud = options.baud;
        std::unique_ptr<PtyPair> pty;
        std::unique_ptr<SerialPort> device;
        SerialPort* port = nullptr;
        std::string where;
        if (options.pty) {
            pty = std::make_unique<PtyPair>(PtyOptions{line, options.link});
            port = &pty->master();
            where = pty->public_path();
        } else {
            device = std::make_unique<SerialPort>(options.port, line);
            port = device.get();
            where = options.port;
        }

        const DomainLease lease = DomainLease::acquire();
        DdsContext dds(lease.domain_id(), "emulate-gnss", /*watch_discovery=*/false, ReliabilityTimers::prompt_repair);
        emulators::GnssG970 gnss(world.plant, world.gnss);
        NmeaSerialAdapter adapter(*port);
        RealtimeMaster master(dds, LockstepTimeouts{});
        master.add_local_node(gnss);
        master.add_local_node(adapter);
        out << "rig emulate gnss: " << spec.name << ": G970II talker " << world.gnss.talker << " at "
            << world.gnss.rate_hz << " Hz on " << where << " (" << describe(line)
            << "); the vehicle drives the case's route in real time; Ctrl-C stops\n"
            << std::flush;
        master.start();
        const TimeNs end_ns = options.seconds ? seconds_to_ns(*options.seconds) : world.end_ns;
        std::string stopped_by = "the end of the route";
        for (TimeNs slice_end = 0; slice_end < end_ns;) {
            slice_end = std::min(end_ns, master.clock().now_ns() + seconds_to_ns(0.2));
            master.run_until(slice_end);
            if (stop.pending()) {
                stopped_by = stop.take();
                break;
            }
        }
        master.shutdown();
        out << "rig emulate gnss: " << adapter.sentences_written() << " sentences written to " << where
            << "; stopped by " << stopped_by << "\n";
        return 0;
    } catch (const ConfigError& error) {
        err << "rig emulate gnss: " << error.what() << "\n";
        return 2;
    } catch (const std::exception& error) {
        err << "rig emulate gnss: " << error.what() << "\n";
        return 1;
    }
}

EmulateBenchCommand::EmulateBenchCommand(CLI::App& app) {
    auto* emulate = app.add_subcommand("emulate", "emulate one device onto a real port, in real time");
    emulate->require_subcommand(1);
    gnss_ = emulate->add_subcommand("gnss", "the G970II RTK-GNSS NMEA stream of a case's vehicle on a serial port");
    gnss_->add_option("case", options_.case_file, "case file whose vehicle and receiver to emulate")->required();
    gnss_->add_option("--port", options_.port, "serial device to write to, e.g. /dev/ttyUSB0");
    gnss_->add_flag("--pty", options_.pty, "create a pseudo-terminal and write there (its path is printed)");
    gnss_->add_option("--link", options_.link, "with --pty: a symlink to it, e.g. /tmp/gnss0");
    gnss_->add_option("--baud", options_.baud, "baud rate (8N1)")->capture_default_str();
    gnss_->add_option("--seed", seed_, "override the case's seed")->check(rig::harness::unsigned_decimal_check());
    gnss_->add_option("--seconds", seconds_, "stop after this many seconds (default: the route's end)");
}

bool EmulateBenchCommand::parsed() const { return gnss_->parsed(); }

int EmulateBenchCommand::run() {
    EmulateGnssOptions options = options_;
    if (gnss_->count("--seed") > 0) options.seed = seed_;
    if (gnss_->count("--seconds") > 0) options.seconds = seconds_;
    return run_emulate_gnss(options, std::cout, std::cerr);
}

}  // namespace rig::harness
