#include "harness/spec/case_spec.h"

#include "rig/config/file_access.h"
#include "rig/runtime/failure_kind.h"
#include "rig/text/number_text.h"
#include "rig/wire/modbus_protocol.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <unordered_map>
#include <optional>
#include <system_error>

namespace rig::harness {

namespace {

constexpr EnumChoice<ClockMode> kClockModes[] = {
    {"lockstep", ClockMode::lockstep},
    {"realtime", ClockMode::realtime},
};
constexpr EnumChoice<GnssWire> kGnssWires[] = {
    {"dds", GnssWire::dds},
    {"serial", GnssWire::serial},
};
constexpr EnumChoice<BoardIoWireKind> kBoardIoWires[] = {
    {"dds", BoardIoWireKind::dds},
    {"modbus_rtu", BoardIoWireKind::modbus_rtu},
    {"modbus_tcp", BoardIoWireKind::modbus_tcp},
    {"hid", BoardIoWireKind::hid},
};
constexpr EnumChoice<bool> kControllerPlaces[] = {
    {"process", false},
    {"external", true},
};

template <class E, std::size_t N>
std::string_view name_of(const EnumChoice<E> (&choices)[N], E value) {
    for (const EnumChoice<E>& choice : choices) {
        if (choice.value == value) return choice.name;
    }
    return "?";
}

// ---------------------------------------------------------------- sections
//
// Every number has a range, each with its physical reason: a finite value far
// outside physics (1e300 m, a 1e-300 Hz rate) would pass a sign check and then
// overflow simulated time (int64 ns) or allocate without end at run time.

// A device path or "pty"; PATH_MAX-style limits are far above any real port name.
std::string read_port(const YamlSection& section, std::string_view key, const std::string& fallback) {
    std::string port = section.optional<std::string>(key, fallback);
    if (port.empty()) section.fail(key, "must be 'pty' or a serial device path");
    if (port.size() > 255) section.fail(key, "is " + std::to_string(port.size()) + " characters long, at most 255");
    return port;
}

WiringSpec read_wiring(const YamlSection& section, bool laser_line) {
    WiringSpec wiring;
    if (laser_line) {
        wiring.laser = section.optional_enum<GnssWire>("laser", kGnssWires, wiring.laser);
        wiring.laser_port = read_port(section, "laser_port", wiring.laser_port);
        wiring.laser_baud = section.optional_in_range<int>("laser_baud", wiring.laser_baud, Bounds::closed(1200, 4000000));
    }
    wiring.gnss = section.optional_enum<GnssWire>("gnss", kGnssWires, wiring.gnss);
    wiring.board_io = section.optional_enum<BoardIoWireKind>("board_io", kBoardIoWires, wiring.board_io);
    wiring.gnss_port = read_port(section, "gnss_port", wiring.gnss_port);
    // Serial lines: 1200 baud to 4 Mbaud (the fastest USB-serial adapters).
    wiring.nmea_baud = section.optional_in_range<int>("nmea_baud", wiring.nmea_baud, Bounds::closed(1200, 4000000));
    wiring.modbus_port = read_port(section, "modbus_port", wiring.modbus_port);
    wiring.modbus_baud = section.optional_in_range<int>("modbus_baud", wiring.modbus_baud, Bounds::closed(1200, 4000000));
    wiring.modbus_tcp = read_port(section, "modbus_tcp", wiring.modbus_tcp);
    wiring.hid_vid = static_cast<std::uint16_t>(
        section.optional_in_range<std::uint32_t>("hid_vid", wiring.hid_vid, Bounds::closed(0, 0xFFFF)));
    wiring.hid_pid = static_cast<std::uint16_t>(
        section.optional_in_range<std::uint32_t>("hid_pid", wiring.hid_pid, Bounds::closed(0, 0xFFFF)));
    // The board's input refresh: a timer, 1 Hz to 2 kHz.
    wiring.board_update_hz =
        section.optional_in_range<double>("board_update_hz", wiring.board_update_hz, Bounds::closed(1, 2000));
    wiring.external_controller = section.optional_enum<bool>("controller", kControllerPlaces, wiring.external_controller);
    return wiring;
}

// The section stays raw for the controller; only `command` is the rig's. It is
// read through a separate YamlSection (never finish()ed) so the controller's
// own keys are not reported as unknown here.
ControllerSpec read_controller(const YamlSection& root) {
    ControllerSpec controller;
    controller.params = root.raw("controller");
    if (controller.params.present && !controller.params.node.IsNull() && !controller.params.node.IsMap()) {
        root.fail("controller", "expected a mapping (key: value), got " + describe_node(controller.params.node));
    }
    const YamlSection section(controller.params);
    if (section.has("command")) {
        controller.command = section.string_list("command");
        if (controller.command.empty()) {
            section.fail("command", "must name the controller executable, e.g. [ \"rig-controller\" ]");
        }
        // An argv, not a data channel: bounded like a shell command line.
        if (controller.command.size() > 64) section.fail("command", "at most 64 arguments");
        for (std::size_t i = 0; i < controller.command.size(); ++i) {
            if (controller.command[i].size() > 4096) {
                throw ConfigError(section.item_location("command", i), "an argument of at most 4096 characters");
            }
        }
    }
    if (section.has("plugin")) {
        const std::string plugin = section.required<std::string>("plugin");
        if (plugin.empty() || plugin.size() > 4096) section.fail("plugin", "the path of a controller plugin (.so)");
        controller.plugin = plugin;
    }
    if (section.has("in_process")) controller.in_process = section.required<bool>("in_process");
    return controller;
}

// A metric's name as a key of `section` (limits:, paper:, compare.min_effect:):
// a few snake_case words ending with a unit; the name is repeated in every message.
void check_metric_key(const YamlSection& section, const std::string& name) {
    if (name.size() > 64) {
        throw ConfigError(section.key_location(name), "metric name of " + std::to_string(name.size()) +
                                                          " characters, at most 64");
    }
    if (const std::string problem = metric_name_problem(name); !problem.empty()) {
        throw ConfigError(section.key_location(name), problem);
    }
}

std::map<std::string, double> read_limits(const YamlSection& section) {
    std::map<std::string, double> limits;
    for (const std::string& name : section.keys()) {
        check_metric_key(section, name);
        // Limits are on metres, seconds, percent and counts of one case; no
        // metric the harness measures comes near a million of any of them.
        limits[name] = section.required_in_range<double>(name, Bounds::closed(-1e6, 1e6));
    }
    return limits;
}

// `compare: { min_effect: { overlap_m: 0.1 } }`: the smallest shift `rig
// compare` and `rig history` call news for this case's metrics, over the
// declared defaults (harness/judge/metric_direction.h). Zero calls any
// significant shift news; the range is a limit's.
std::map<std::string, double> read_compare(const YamlSection& root) {
    std::map<std::string, double> min_effects;
    const YamlSection section = root.section("compare").section("min_effect");
    for (const std::string& name : section.keys()) {
        check_metric_key(section, name);
        min_effects[name] = section.required_in_range<double>(name, Bounds::closed(0, 1e6));
    }
    return min_effects;
}

PaperPoints read_paper(const YamlSection& section) {
    PaperPoints paper;
    for (const std::string& name : section.keys()) {
        if (name == "source") continue;
        check_metric_key(section, name);
        // The same range as a limit: the paper's numbers are of the same metrics.
        paper.values[name] = section.required_in_range<double>(name, Bounds::closed(-1e6, 1e6));
    }
    if (section.has("source")) {
        paper.source = section.required<std::string>("source");
        if (paper.source.empty() || paper.source.size() > 200) {
            section.fail("source", "where in the paper the numbers are, in at most 200 characters (e.g. \"Table 2\")");
        }
    }
    if (!paper.values.empty() && paper.source.empty()) {
        throw ConfigError(section.key_location(paper.values.begin()->first),
                          "the paper's numbers need a source: where in the paper they are (paper.source)");
    }
    return paper;
}

ExpectSpec read_expect(const YamlSection& section) {
    ExpectSpec expect;
    expect.fail = section.string_list("fail");
    if (section.has("error")) {
        expect.error = section.required<std::string>("error");
        if (!failure_kind_from_string(expect.error)) {
            section.fail("error", "'" + expect.error + "' is not a kind of run failure; one of: " + failure_kind_names());
        }
        if (!expect.fail.empty()) {
            section.fail("error", "a case that must end in an error cannot also expect metrics to break (`fail`): "
                                  "an errored case is not judged on its metrics");
        }
    }
    if (section.has("controller")) {
        const std::string whose = section.required<std::string>("controller");
        if (whose != "reference" && whose != "any") {
            section.fail("controller", "'" + whose +
                                           "' is not whose behaviour an expectation can describe: reference (the "
                                           "rig's reference controller, the default) or any");
        }
        expect.any_controller = whose == "any";
    }
    return expect;
}

TimeoutsSpec read_timeouts(const YamlSection& section) {
    TimeoutsSpec timeouts;
    // Wall time: a node acks a tick in milliseconds; a case runs minutes, a day at most.
    timeouts.node_ack_s =
        section.optional_in_range<double>("node_ack_s", timeouts.node_ack_s, Bounds::open_closed(0, 600));
    timeouts.case_wall_s =
        section.optional_in_range<double>("case_wall_s", timeouts.case_wall_s, Bounds::open_closed(0, 86400));
    return timeouts;
}

// The wires, the real-time sections and the board, seed 000's and seed 001's alike.
void check_bench_wiring(const CaseSpec& spec, const YamlSection& root) {
    if (spec.wiring.uses_bench_wire() && spec.mode != ClockMode::realtime) {
        root.section("wiring").fail("serial, Modbus and HID wires have no virtual time: set `mode: realtime`");
    }
    if (spec.board.line_noise.any() && spec.wiring.board_io != BoardIoWireKind::modbus_rtu) {
        root.section("board").fail("line_noise", "line noise is injected on a Modbus RTU line: needs `wiring: { "
                                                 "board_io: modbus_rtu }`");
    }
    for (const char* section : {"realtime", "rig_faults"}) {
        if (root.has(section) && spec.mode != ClockMode::realtime) {
            root.fail(section, "bounds and faults of the rig's real-time loop: only with `mode: realtime`");
        }
    }
    if (spec.wiring.external_controller && !spec.wiring.uses_bench_wire()) {
        root.section("wiring").fail("controller", "an external controller needs a bench wire (gnss: serial, board_io: ...)");
    }
}

// Checks between the common sections; run after finish(), when every value is real.
void check_common_fields(const CaseSpec& spec, const YamlSection& root) {
    check_bench_wiring(spec, root);
    if (spec.controller.in_process.value_or(false)) {
        // In process, the controller is stepped by the lockstep master: there is
        // no process boundary, so no wall clock and no bench wire to drive it.
        const YamlSection controller(spec.controller.params);
        if (spec.mode != ClockMode::lockstep || spec.wiring.external_controller) {
            controller.fail("in_process", "a controller runs in process only in lockstep cases on DDS wires");
        }
        if (!spec.controller.command.empty() && spec.controller.plugin.empty()) {
            controller.fail("in_process", "`command` names a program; a controller runs in process from its "
                                          "shared library: give `plugin` too");
        }
    }
    if (spec.wiring.board_io == BoardIoWireKind::modbus_tcp) {
        try {
            modbus::parse_tcp_endpoint(spec.wiring.modbus_tcp);
        } catch (const std::exception& error) {
            root.section("wiring").fail("modbus_tcp", error.what());
        }
    }
    const YamlSection expect = root.section("expect");
    for (std::size_t index = 0; index < spec.expect.fail.size(); ++index) {
        const std::string& metric = spec.expect.fail[index];
        const std::string shown = metric.size() > 64 ? metric.substr(0, 64) + "..." : metric;
        if (!spec.limits.contains(metric) && !spec.system->default_limits().contains(metric)) {
            throw ConfigError(expect.item_location("fail", index),
                              "'" + shown + "' has no limit; expected failures must name limited metrics "
                              "(limits in this file or the defaults)");
        }
        for (std::size_t earlier = 0; earlier < index; ++earlier) {
            if (spec.expect.fail[earlier] == metric) {
                throw ConfigError(expect.item_location("fail", index), "'" + shown + "' is listed twice");
            }
        }
    }
}


// Which system reads the rest of the file: "must be one of breakpoint, boundary; got ...".
const SystemSectionsReader& system_reader(const YamlSection& root, std::span<const SystemSectionsReader> systems) {
    std::vector<std::string_view> names;
    for (const SystemSectionsReader& reader : systems) names.push_back(reader.name);
    const std::string name = root.optional_enum("system", names, kDefaultSystem);
    for (const SystemSectionsReader& reader : systems) {
        if (reader.name == name) return reader;
    }
    root.fail("system", "no system of this rig reads '" + name + "'");
}

CaseSpec read_case(const YamlSection& root, const std::filesystem::path& source_path,
                   std::span<const SystemSectionsReader> systems) {
    CaseSpec spec;
    spec.source_path = source_path;

    spec.name = root.required<std::string>("name");
    spec.name_location = root.location("name");
    if (root.has("name")) {
        // The name is a directory under --out: `..` would be --out itself (and
        // its removal would delete what was there), `.` would be cases/.
        if (const std::string problem = plain_file_name_problem(spec.name, kMaxCaseNameLength); !problem.empty()) {
            const std::string shown = spec.name.size() > 40 ? spec.name.substr(0, 40) + "..." : spec.name;
            root.fail("name", "case name " + problem + ", got '" + shown + "'");
        }
    }
    spec.description = root.optional<std::string>("description", "");
    if (spec.description.size() > kMaxDescriptionLength) {
        root.fail("description", "is " + std::to_string(spec.description.size()) + " characters long, at most " +
                                     std::to_string(kMaxDescriptionLength));
    }
    spec.seed = root.optional<std::uint64_t>("seed", spec.seed);
    if (root.has("seeds")) {
        if (root.has("seed")) root.fail("seeds", "give either `seed` or `seeds`, not both");
        const std::vector<std::string> seeds = root.string_list("seeds");
        if (seeds.empty()) root.fail("seeds", "must list at least one seed");
        for (std::size_t index = 0; index < seeds.size(); ++index) {
            std::uint64_t seed = 0;
            const auto [end, error] = std::from_chars(seeds[index].data(), seeds[index].data() + seeds[index].size(), seed);
            if (error != std::errc{} || end != seeds[index].data() + seeds[index].size()) {
                throw ConfigError(root.item_location("seeds", index),
                                  "a seed is a whole number >= 0, got '" + seeds[index] + "'");
            }
            if (std::find(spec.seeds.begin(), spec.seeds.end(), seed) != spec.seeds.end()) {
                throw ConfigError(root.item_location("seeds", index), "seed " + seeds[index] + " is listed twice");
            }
            spec.seeds.push_back(seed);
        }
        spec.seed = spec.seeds.front();
    }
    if (root.has("domain")) spec.domain = root.required_in_range<std::uint32_t>("domain", Bounds::closed(0, 232));
    spec.mode = root.optional_enum<ClockMode>("mode", kClockModes, spec.mode);
    const SystemSectionsReader& reader = system_reader(root, systems);
    spec.system = reader.read(root);
    spec.wiring = read_wiring(root.section("wiring"), spec.system->reads_laser_line());
    spec.board = read_board_spec(root.section("board"));
    spec.realtime = read_realtime_section(root.section("realtime"));
    spec.rig_faults = read_rig_faults(root.section("rig_faults"));
    spec.controller = read_controller(root);
    spec.limits = read_limits(root.section("limits"));
    spec.paper = read_paper(root.section("paper"));
    spec.min_effects = read_compare(root);
    spec.expect = read_expect(root.section("expect"));
    spec.timeouts = read_timeouts(root.section("timeouts"));

    root.finish();
    check_common_fields(spec, root);
    spec.system->check_with(spec, root);
    return spec;
}

}  // namespace

std::string_view to_string(ClockMode mode) { return name_of(kClockModes, mode); }
std::string_view to_string(GnssWire wire) { return name_of(kGnssWires, wire); }
std::string_view to_string(BoardIoWireKind wire) { return name_of(kBoardIoWires, wire); }

std::string metric_name_problem(std::string_view name) {
    const auto fail = [&](const std::string& why) {
        std::string suffixes;
        for (const std::string_view suffix : kMetricUnitSuffixes) {
            if (!suffixes.empty()) suffixes += ", ";
            suffixes += '_';
            suffixes += suffix;
        }
        return "metric name '" + std::string(name) + "' " + why +
               "; metric names are snake_case with a unit suffix (" + suffixes + ")";
    };
    bool snake_case = !name.empty() && std::islower(static_cast<unsigned char>(name.front())) != 0 &&
                      name.back() != '_' && name.find("__") == std::string_view::npos;
    for (const char c : name) {
        const auto byte = static_cast<unsigned char>(c);
        if (!(std::islower(byte) || std::isdigit(byte) || c == '_')) snake_case = false;
    }
    if (!snake_case) return fail("is not snake_case");
    for (const std::string_view suffix : kMetricUnitSuffixes) {
        // At least one word before `_<suffix>`.
        if (name.size() > suffix.size() + 1 && name.ends_with(suffix) && name[name.size() - suffix.size() - 1] == '_') {
            return {};
        }
    }
    return fail("has no unit suffix");
}

std::map<std::string, double> effective_limits(const CaseSpec& spec) {
    std::map<std::string, double> limits = spec.system ? spec.system->default_limits() : std::map<std::string, double>{};
    for (const auto& [name, limit] : spec.limits) limits[name] = limit;
    return limits;
}

namespace {

// The case read from `text` with `settings` applied; an error at a key a
// setting gave says so, since the file's own value there is not the culprit.
CaseSpec read_case_with_settings(std::string_view text, const std::filesystem::path& source_path,
                                 std::span<const SystemSectionsReader> systems, std::span<const KeySetting> settings) {
    const std::string applied = apply_key_settings(text, source_path.string(), settings);
    try {
        CaseSpec spec = read_case(YamlSection::load_string(applied, source_path.string()), source_path, systems);
        spec.source_text = applied;
        spec.settings.assign(settings.begin(), settings.end());
        return spec;
    } catch (const ConfigError& error) {
        for (const KeySetting& setting : settings) {
            if (setting.key != error.key_path()) continue;
            throw ConfigError(error.where(), error.message() + " (the value of --set " + setting.key + "=" +
                                                 setting.value + ")");
        }
        throw;
    }
}

}  // namespace

CaseSpec read_case_text(std::string_view yaml_text, const std::filesystem::path& file_name,
                        std::span<const SystemSectionsReader> systems, std::span<const KeySetting> settings) {
    return read_case_with_settings(yaml_text, file_name, systems, settings);
}

CaseSpec read_case_file(const std::filesystem::path& path, std::span<const SystemSectionsReader> systems,
                        std::span<const KeySetting> settings) {
    // Read once, by type and bounded (rig/config/file_access.h), then parsed from memory;
    // the text is kept for the trace.
    std::string text;
    try {
        text = read_regular_file(path, OpenOptions{.no_follow = false, .max_bytes = kMaxConfigFileBytes,
                                                   .what = "case file"});
    } catch (const FileAccessError& error) {
        throw ConfigError(SourceLocation{path.string(), 0, 0, "(file)"}, error.problem());
    }
    return read_case_with_settings(text, path, systems, settings);
}

namespace {

std::string location_text(const SourceLocation& where) {
    std::string text = where.file;
    if (where.line > 0) text += ":" + std::to_string(where.line) + ":" + std::to_string(where.column);
    return text;
}

}  // namespace

std::vector<std::string> duplicate_case_name_errors(const std::vector<CaseSpec>& specs) {
    std::vector<std::string> errors;
    std::unordered_map<std::string, std::size_t> first_with_name;
    for (std::size_t index = 0; index < specs.size(); ++index) {
        const auto [first, inserted] = first_with_name.emplace(specs[index].name, index);
        if (inserted) continue;
        const CaseSpec& earlier = specs[first->second];
        errors.push_back(ConfigError(specs[index].name_location,
                                     "case name '" + specs[index].name + "' is also the name of " +
                                         location_text(earlier.name_location) +
                                         "; one run writes each case to cases/NAME/ under --out, so the two "
                                         "would share a trace and a controller state: rename one")
                             .what());
    }
    return errors;
}

void check_event_in_case(double at_s, double for_s, const SourceLocation& at_where, const SourceLocation& for_where,
                         const char* what, double case_end_s) {
    const std::string length = shortest_text(case_end_s) + " s";
    if (at_s < 0.0) {
        throw ConfigError(at_where, std::string(what) + " would start " + shortest_text(-at_s) +
                                        " s before the case does (at " + shortest_text(at_s) + " s)");
    }
    if (at_s >= case_end_s) {
        throw ConfigError(at_where, std::string(what) + " starts at " + shortest_text(at_s) +
                                        " s, after the case ends (" + length + ")");
    }
    if (for_s > case_end_s) {
        throw ConfigError(for_where, std::string(what) + " lasts " + shortest_text(for_s) +
                                         " s, longer than the whole case (" + length + ")");
    }
}

void check_common_timeline(const CaseSpec& spec, double case_end_s) {
    if (spec.rig_faults) {
        check_event_in_case(spec.rig_faults->master_stall_at_s, spec.rig_faults->master_stall_for_s,
                            spec.rig_faults->at_location, spec.rig_faults->for_location, "the rig's stall", case_end_s);
    }
}

bool is_search_file(const std::filesystem::path& path) {
    const std::string name = path.filename().string();
    return name.size() > kSearchFileSuffix.size() && name.ends_with(kSearchFileSuffix);
}

std::vector<std::filesystem::path> expand_case_paths(const std::vector<std::string>& args) {
    namespace fs = std::filesystem;
    std::vector<fs::path> paths;
    for (const std::string& arg : args) {
        const fs::path path(arg);
        std::error_code error;
        const fs::file_status status = fs::status(path, error);
        if (status.type() == fs::file_type::not_found) {
            throw ConfigError(SourceLocation{arg, 0, 0, "(file)"}, "no such case file or directory");
        }
        if (error) throw ConfigError(SourceLocation{arg, 0, 0, "(file)"}, "cannot access: " + error.message());
        if (status.type() != fs::file_type::directory) {
            paths.push_back(path);
            continue;
        }
        // Suites are folders of cases (cases/table3-fusion/...), so walk the tree;
        // hidden files and folders (.git, editor swap files) are skipped.
        std::vector<fs::path> cases;
        for (auto it = fs::recursive_directory_iterator(path, fs::directory_options::skip_permission_denied);
             it != fs::recursive_directory_iterator(); ++it) {
            const std::string file_name = it->path().filename().string();
            if (file_name.starts_with('.')) {
                if (it->is_directory()) it.disable_recursion_pending();
                continue;
            }
            const std::string extension = it->path().extension().string();
            if (extension != ".yaml" && extension != ".yml") continue;
            if (is_search_file(it->path())) continue;
            // A folder named like a case is walked into; anything else with a case's
            // name (a FIFO, a link to a device, a link loop) is kept, for
            // load_case_file to refuse by type, naming it, rather than skipped unsaid.
            std::error_code type_error;
            if (it->is_directory(type_error) && !type_error) continue;
            cases.push_back(it->path());
        }
        if (cases.empty()) {
            throw ConfigError(SourceLocation{arg, 0, 0, "(file)"}, "directory has no *.yaml or *.yml case files");
        }
        // Sorted by path below the directory: suite folder, then file name.
        std::sort(cases.begin(), cases.end(), [&path](const fs::path& a, const fs::path& b) {
            return a.lexically_relative(path).generic_string() < b.lexically_relative(path).generic_string();
        });
        paths.insert(paths.end(), cases.begin(), cases.end());
    }
    return paths;
}

ExpectSpec applied_expectation(const CaseSpec& spec, std::string* set_aside) {
    const bool expects = !spec.expect.fail.empty() || !spec.expect.error.empty();
    const bool reference =
        spec.controller.command.empty() && spec.controller.plugin.empty() && !spec.wiring.external_controller;
    if (!expects || reference || spec.expect.any_controller) return spec.expect;
    if (set_aside != nullptr) {
        // `fail` and `error` are exclusive (read_expect).
        std::string expected = spec.expect.error.empty() ? "failures of " : "an error, " + spec.expect.error;
        for (std::size_t index = 0; index < spec.expect.fail.size(); ++index) {
            expected += (index == 0 ? "" : ", ") + spec.expect.fail[index];
        }
        const std::string controller = spec.wiring.external_controller    ? std::string("an external board")
                                       : !spec.controller.command.empty() ? spec.controller.command.front()
                                                                          : spec.controller.plugin.string();
        *set_aside = "the case expects " + expected + " of the reference controller; it ran " + controller +
                     ", which is judged on the limits alone (expect.controller: any keeps the expectation)";
    }
    return ExpectSpec{};
}

}  // namespace rig::harness
