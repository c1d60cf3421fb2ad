#pragma once
// A case file (docs/design.md "Case files") as plain structs, and its strict
// loader. Every mistake in a case file is a rig::ConfigError at
// `file:line:col: key: message`, raised before anything starts.
//
// Here are the sections every case has, whatever its system: its name and
// seeds, the time mode, the wires, the board, the controller, the limits and
// expectations, the timeouts. The rest of the file is its system's (the
// `system:` key, seed 000's breakpoint sprayer by default): read by the
// system (harness/systems/) into a SystemSections object of its own.
//
// Member names carry their unit, like the YAML keys they come from. Adding a
// common section is one struct here, one `read_...(const YamlSection&)`
// function in case_spec.cpp, and one line in the loader that calls it.
#include <array>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "harness/spec/board_spec.h"
#include "harness/spec/case_settings.h"
#include "harness/spec/realtime_spec.h"
#include "rig/config/config_error.h"
#include "rig/config/yaml_fields.h"
#include "rig/runtime/clock.h"

namespace rig::harness {

// The spelling used in case files ("lockstep", "realtime").
std::string_view to_string(ClockMode mode);

// Positions along a route stay within this of the field origin: no field row
// is 10 km long, and with the speed at least 0.5 km/h the longest route lasts
// well under a day of simulated time.
inline constexpr double kMaxAlongM = 10'000.0;
// Times of events in a case (dropouts, episodes, lifts, stalls) are at most
// this; the timeline checks then hold them to the case's length.
inline constexpr double kMaxEventS = 86'400.0;

// Which wire carries what (issue: plug in a real controller). DDS for
// everything by default; serial, Modbus and HID are bench wires and need
// `mode: realtime`. Ports are "pty" (the rig makes a pseudo-terminal pair and
// hands the other end to the controller) or a device path for a real board.
enum class GnssWire { dds, serial };
enum class BoardIoWireKind { dds, modbus_rtu, modbus_tcp, hid };
struct WiringSpec {
    GnssWire gnss = GnssWire::dds;
    BoardIoWireKind board_io = BoardIoWireKind::dds;
    std::string gnss_port = "pty";      // serial: pty or /dev/tty... (at most 255 characters)
    int nmea_baud = 115200;
    std::string modbus_port = "pty";    // modbus_rtu: pty or /dev/tty...
    int modbus_baud = 115200;
    std::string modbus_tcp = "127.0.0.1:0";  // modbus_tcp: where the rig's slave listens (port 0 = any free)
    std::uint16_t hid_vid = 0x1209;
    std::uint16_t hid_pid = 0x0001;
    double board_update_hz = 200.0;     // how often the board's inputs are refreshed
    // process: the harness starts the controller command with the wire's ports;
    // external: a real board is wired up and running; the harness starts nothing.
    bool external_controller = false;
    // A system with a laser height sensor on a line of its own (seed 001's
    // L4; SystemSections::reads_laser_line): its line, like the GNSS's (dds, or
    // serial on `laser_port` at `laser_baud`: 115200 8N1, assumed as the
    // AD300's; the paper gives neither).
    GnssWire laser = GnssWire::dds;
    std::string laser_port = "pty";
    int laser_baud = 115200;
    bool uses_bench_wire() const {
        return gnss != GnssWire::dds || laser != GnssWire::dds || board_io != BoardIoWireKind::dds;
    }
};
std::string_view to_string(GnssWire wire);
std::string_view to_string(BoardIoWireKind wire);

std::string_view to_string(GnssWire wire);
std::string_view to_string(BoardIoWireKind wire);

struct ControllerSpec {
    // argv of the controller executable; empty = the reference controller.
    std::vector<std::string> command;  // at most 64 arguments of at most 4096 characters
    // The whole `controller:` section as written, with its location, for the
    // controller to validate. It includes `command`, which belongs to the rig:
    // a controller checking its keys must allow it (kControllerRigKeys).
    RawYaml params;
    // Software-in-the-loop (rig/runtime/node_plugin.h): `plugin`, the controller
    // built as a shared library (relative to the case file; empty = the
    // reference controller's, or none for a `command` without one);
    // `in_process`, whether to run it in the harness's process (unset: as
    // `rig run --in-process` says). Lockstep cases on DDS wires only.
    std::filesystem::path plugin;
    std::optional<bool> in_process;
};
// Keys of the controller section that the rig reads itself (not written into
// the controller's configuration file).
inline constexpr std::array<std::string_view, 3> kControllerRigKeys = {"command", "plugin", "in_process"};

struct ExpectSpec {
    // Metrics that must break their limits (a negative case): the case passes
    // only when exactly these fail. Each must have a limit (file or default).
    std::vector<std::string> fail;
    // Or: the run must end in this kind of failure (rig::FailureKind names, e.g.
    // node_exited, node_unresponsive, topic_role_violation, malformed_command); the case passes
    // only when it does. Exclusive with `fail`.
    std::string error;
    // Whose behaviour the expectation describes: `reference` (the default), the
    // rig's reference controller, so it is set aside when the case runs another
    // controller (`controller.command` or `.plugin`, or an external board): a team that puts its own
    // controller into a paper case the reference controller fails (Table 2's
    // 16 L/min) is judged on the limits, not against the reference's failure;
    // `any`, whatever runs (a negative case written for the team's own
    // controller or stand-in).
    bool any_controller = false;
};

struct TimeoutsSpec {
    double node_ack_s = 10.0;    // wall time for a node to acknowledge a tick, (0, 600]
    double case_wall_s = 600.0;  // wall time for the whole case, (0, 86400]
};

// Case names name a directory (cases/NAME/ under --out), so they are plain
// file names: [A-Za-z0-9._-]+, not starting with '.', at most this long.
inline constexpr std::size_t kMaxCaseNameLength = 100;
// Free text, printed in reports.
inline constexpr std::size_t kMaxDescriptionLength = 2000;

// The paper's numbers for a case (`paper: { source: "Table 2, 20 L/min", flow_adjust_time_s: 1.286 }`):
// where they come from, and a value per metric, under the metrics' own names.
struct PaperPoints {
    std::string source;                    // e.g. "Table 2 (20 L/min group)"; required when values are given
    std::map<std::string, double> values;  // metric name -> the paper's value, in the metric's unit
};

struct CaseSpec;

// A case file's own sections, those of its system (harness/systems/system.h
// reads them): opaque to the loader but for what it asks here. Each system
// derives its own.
class SystemSections {
public:
    virtual ~SystemSections() = default;
    // The system's name, as the case file's `system:` says it.
    virtual std::string_view system_name() const = 0;
    // What the vehicle and operator do in this case (the trace's meta `scenario`).
    virtual std::string scenario() const = 0;
    // The limits the case gets when its file gives none (docs/metrics.md):
    // those its system measures in this case.
    virtual std::map<std::string, double> default_limits() const = 0;
    // Whether the case's wiring may carry a laser height sensor's line.
    virtual bool reads_laser_line() const { return false; }
    // The checks between the system's sections and the common ones, once the
    // whole file is read (`root`: the file, for the locations).
    virtual void check_with(const CaseSpec& spec, const YamlSection& root) const = 0;
};

struct CaseSpec {
    std::filesystem::path source_path;
    std::string name;  // required, see kMaxCaseNameLength
    SourceLocation name_location;  // where `name` is written (duplicate names are reported there)
    std::string description;
    std::uint64_t seed = 1;  // `rig run --seed` overrides
    // The DDS domain the case runs on; by default each case takes a free one.
    // Fixed (or `rig run --domain`), an observer (a Cyclone DDS reader, a
    // debugger) knows where to look. [0, 232]: Fast DDS's ports end there.
    std::optional<std::uint32_t> domain;
    // `seeds: [..]` instead of `seed`: the case runs once per seed, as NAME-seedN
    // (a faulty controller must be caught on every one).
    std::vector<std::uint64_t> seeds;
    std::string source_text;  // the file as written, with `settings` applied (kept in the trace)
    // `rig run --set KEY=VALUE`: values given on the command line in place of
    // the file's (harness/spec/case_settings.h), in the order given; recorded
    // in the trace (meta `case_settings`) and results.json.
    std::vector<KeySetting> settings;
    ClockMode mode = ClockMode::lockstep;
    // The system's own sections (`system:`; harness/systems/ reads them). Set by
    // the loader for every case it returns.
    std::shared_ptr<const SystemSections> system;
    WiringSpec wiring;
    BoardSpec board;  // harness/spec/board_spec.h: attach, silence and fail-safe of a wired board
    // harness/spec/realtime_spec.h (`mode: realtime` only): the bound on the rig's own
    // emission lateness, and the self-test faults of the rig itself.
    LatenessBound realtime;
    std::optional<RigFaultsSpec> rig_faults;
    ControllerSpec controller;
    // Limits as written in the file (metric name -> max allowed value, |v| <= 1e6); the
    // harness judges against effective_limits(), i.e. these over the system's defaults.
    std::map<std::string, double> limits;
    ExpectSpec expect;
    TimeoutsSpec timeouts;
    // `paper:` the paper's own numbers for this case's metrics, as data: a rig
    // sweep draws them over the rig's bands (harness/report/sweep.h). Not a limit and
    // never part of the verdict.
    PaperPoints paper;
    // `compare: { min_effect: {metric: shift} }`: this case's minimum effects for
    // `rig compare` / `rig history`, over the declared defaults (docs/regression.md).
    std::map<std::string, double> min_effects;
};

// Unit suffixes a metric (limit) name may end with, as `_<suffix>`.
// Names are snake_case: [a-z][a-z0-9]*(_[a-z0-9]+)*, with at least one word
// before the unit (`overlap_m`, `flow_error_pct`, `flow_l_min`, `missed_count`).
inline constexpr std::array<std::string_view, 24> kMetricUnitSuffixes = {
    "m",   "cm",  "mm",  "km",    "m2",    "ha",     "s",   "ms",   "hz", "pct", "count", "l",
    "ml",  "l_min", "l_ha", "ul_cm2", "deg", "rad", "kpa", "mpa", "v", "ma",  "km_h",  "m_s",
};
// Empty when `name` is a valid metric name, else why not.
std::string metric_name_problem(std::string_view name);

// The expectation the case is judged with: spec.expect, or none when it
// describes the reference controller and the case runs another; then
// `set_aside` (if given) says so, naming the controller.
ExpectSpec applied_expectation(const CaseSpec& spec, std::string* set_aside = nullptr);

// The case's limits over its system's defaults (the file wins).
std::map<std::string, double> effective_limits(const CaseSpec& spec);

// How the loader reads a system's own sections of `root` (not finish()ed
// there): one per system, found by the file's `system:` (harness/systems/systems.h
// gives the table). Throws rig::ConfigError naming file, line and key.
struct SystemSectionsReader {
    std::string_view name;
    std::function<std::shared_ptr<const SystemSections>(const YamlSection& root)> read;
};
// The system a case file names without a `system:` key.
inline constexpr std::string_view kDefaultSystem = "breakpoint";

// Parses and validates a case file; throws rig::ConfigError. The sections of
// its system are read by the reader of that name in `systems`. `settings`
// replace values of the file before it is read (harness/spec/case_settings.h):
// an error at a set key says the value came from the command line.
CaseSpec read_case_file(const std::filesystem::path& path, std::span<const SystemSectionsReader> systems,
                        std::span<const KeySetting> settings = {});
// The same from text in memory; `file_name` is what errors call it.
CaseSpec read_case_text(std::string_view yaml_text, const std::filesystem::path& file_name,
                        std::span<const SystemSectionsReader> systems, std::span<const KeySetting> settings = {});

// Two cases of one run with one name would share cases/NAME/ (trace, log,
// controller state): one line per later case whose name an earlier one has,
//   FILE:LINE:COL: name: case name 'x' is also the name of EARLIER_FILE:LINE:COL; ...
// Empty when the names are distinct.
std::vector<std::string> duplicate_case_name_errors(const std::vector<CaseSpec>& specs);

// An event's start and length against a case of `case_end_s` seconds: one
// that starts before 0 or at/after the end, or lasts longer than the whole
// case, is a ConfigError at its key (`what` names it: "the dropout"). An event
// that starts inside and runs past the end is cut by the end.
void check_event_in_case(double at_s, double for_s, const SourceLocation& at_where, const SourceLocation& for_where,
                         const char* what, double case_end_s);
// The common part of a case's timeline: the rig's own stall (rig_faults).
void check_common_timeline(const CaseSpec& spec, double case_end_s);

// `rig falsify`'s search files (docs/falsify.md) sit beside their cases and
// are named NAME.search.yaml: they describe a search, not a case.
inline constexpr std::string_view kSearchFileSuffix = ".search.yaml";
bool is_search_file(const std::filesystem::path& path);

// Command-line case arguments to files: a file stays as given; a directory
// becomes the `*.yaml` / `*.yml` files anywhere below it (hidden files,
// folders and search files skipped), sorted by path relative to it. A missing path, or a directory with no case files, is
// a rig::ConfigError naming it.
std::vector<std::filesystem::path> expand_case_paths(const std::vector<std::string>& args);

}  // namespace rig::harness
