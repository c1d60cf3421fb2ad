#include "harness/systems/systems.h"

#include <stdexcept>

#include "harness/systems/boundary/boundary_system.h"
#include "harness/systems/breakpoint/breakpoint_system.h"

namespace rig::harness {

const std::vector<const System*>& all_systems() {
    // The table: one row per system, the default (kDefaultSystem) first.
    static const std::vector<const System*> systems = {
        &breakpoint_system(),
        &boundary_system(),
    };
    return systems;
}

const System& system_named(std::string_view name) {
    std::string names;
    for (const System* system : all_systems()) {
        if (system->name() == name) return *system;
        names += (names.empty() ? "" : ", ") + std::string(system->name());
    }
    throw std::invalid_argument("no system '" + std::string(name) + "' (this rig has " + names + ")");
}

const System& system_of(const CaseSpec& spec) {
    if (!spec.system) throw std::logic_error(spec.source_path.string() + ": a case without its system's sections");
    return system_named(spec.system->system_name());
}

std::vector<SystemSectionsReader> system_section_readers() {
    std::vector<SystemSectionsReader> readers;
    for (const System* system : all_systems()) {
        readers.push_back(SystemSectionsReader{system->name(), [system](const YamlSection& root) {
                                                   return system->read_sections(root);
                                               }});
    }
    return readers;
}

CaseSpec load_case_file(const std::filesystem::path& path, std::span<const KeySetting> settings) {
    return read_case_file(path, system_section_readers(), settings);
}

CaseSpec parse_case(std::string_view yaml_text, const std::filesystem::path& file_name) {
    return read_case_text(yaml_text, file_name, system_section_readers());
}

namespace {

// Judges nothing: the trace's system is not one of this rig's.
class UnknownSystem final : public SystemJudge {
public:
    explicit UnknownSystem(std::string why) : why_(std::move(why)) {}
    SystemJudgement judge(const RecordedTrace&, const nlohmann::json&) const override { throw std::runtime_error(why_); }

private:
    std::string why_;
};

}  // namespace

CaseRun judge_trace(const RecordedTrace& trace) {
    const std::string name = trace.meta_or("system", std::string(kDefaultSystem));
    for (const System* system : all_systems()) {
        if (system->name() == name) return harness::judge_trace(trace, *system);
    }
    return harness::judge_trace(trace, UnknownSystem("the trace's system '" + name + "' is not one this rig judges"));
}

std::vector<KeySignal> key_signals(const RecordedTrace& trace) {
    const std::string name = trace.meta_or("system", std::string(kDefaultSystem));
    for (const System* system : all_systems()) {
        if (system->name() == name) return system->key_signals(trace);
    }
    throw std::runtime_error(trace.file.string() + ": the trace's system '" + name + "' is not one this rig knows");
}

}  // namespace rig::harness
