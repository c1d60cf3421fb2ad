#pragma once
// The table of systems the rig tests, by the name a case file's `system:`
// gives (seed 000's `breakpoint`, the default, and seed 001's `boundary`): a
// new system is a folder beside these and a row in systems.cpp. And the three
// things only the table can do: read a case file whole (its system's
// sections by its `system:`), judge a trace (by its meta `system`), and name
// the systems there are, and say which signals of a trace show what its run did.
#include <filesystem>
#include <span>
#include <string_view>
#include <vector>

#include "harness/judge/judge_trace.h"
#include "harness/spec/case_spec.h"
#include "harness/systems/system.h"
#include "harness/trace/trace_reader.h"

namespace rig::harness {

// Every system, in the table's order.
const std::vector<const System*>& all_systems();
// The system of that name; throws std::invalid_argument naming the ones there are.
const System& system_named(std::string_view name);
// The system of a case (its `system:`).
const System& system_of(const CaseSpec& spec);

// The table as the case loader takes it (harness/spec/case_spec.h).
std::vector<SystemSectionsReader> system_section_readers();

// Parses and validates a case file (the sections every case has, then its
// system's), with `settings` in place of the file's values (`rig run --set`);
// throws rig::ConfigError naming file, line and key.
CaseSpec load_case_file(const std::filesystem::path& path, std::span<const KeySetting> settings = {});
// The same from text in memory; `file_name` is what errors call it.
CaseSpec parse_case(std::string_view yaml_text, const std::filesystem::path& file_name);

// Judges a recorded trace with its system's judge (meta `system`; a trace
// without one is seed 000's, as every trace was before seed 001). A trace
// naming a system this rig does not know is an error of the result, not an
// exception. Never throws for a trace read_trace accepted.
CaseRun judge_trace(const RecordedTrace& trace);

// The key signals of a recorded trace (System::key_signals) of its system
// (meta `system`, as judge_trace). Throws std::runtime_error for a trace of a
// system this rig does not know, or whose samples lack what its system reads.
std::vector<KeySignal> key_signals(const RecordedTrace& trace);

}  // namespace rig::harness
