// libFuzzer harness: the case-file loader (harness/spec/case_spec.h on top of
// rig/config/yaml_fields.h, with both systems' sections) and, as `rig run`
// does before anything starts, the reference controllers' checks of their own
// `controller:` section. The systems' section readers are listed here rather
// than taken from harness/systems/systems.h, whose table brings the systems'
// runs and DDS into a build that has neither (the loader takes any list).
// Any input must give a spec or a rig::ConfigError that names the file and
// says something; any other exception escaping is a finding.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <memory>
#include <string_view>

#include "controller/boundary/boundary_node_config.h"
#include "controller/controller_config.h"
#include "harness/spec/case_spec.h"
#include "harness/systems/boundary/boundary_case.h"
#include "harness/systems/breakpoint/breakpoint_case.h"
#include "rig/config/config_error.h"
#include "rig/config/yaml_fields.h"

namespace {

void require(bool condition) {
    if (!condition) std::abort();  // a finding: libFuzzer keeps the input
}

void require_good_error(const rig::ConfigError& error) {
    require(error.file() == "fuzz.yaml");
    require(!error.message().empty());
    // One line an editor can jump to, of bounded size however long the input.
    require(std::string_view(error.what()).size() < 4096);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string_view text(reinterpret_cast<const char*>(data), size);
    rig::harness::CaseSpec spec;
    try {
        static const rig::harness::SystemSectionsReader systems[] = {
            {"breakpoint", [](const rig::YamlSection& root) -> std::shared_ptr<const rig::harness::SystemSections> {
                 return rig::harness::read_breakpoint_sections(root);
             }},
            {"boundary", [](const rig::YamlSection& root) -> std::shared_ptr<const rig::harness::SystemSections> {
                 return rig::harness::read_boundary_sections(root);
             }},
        };
        spec = rig::harness::read_case_text(text, "fuzz.yaml", systems);
    } catch (const rig::ConfigError& error) {
        require_good_error(error);
        return 0;
    }
    require(!spec.name.empty() && spec.name_location.line > 0);
    require(rig::harness::duplicate_case_name_errors({spec, spec}).size() == 1);
    if (spec.controller.command.empty()) {
        try {
            if (spec.system->system_name() == "boundary") {
                rig::controller::boundary::check_boundary_node_config(rig::YamlSection(spec.controller.params));
            } else {
                rig::controller::parse_controller_config(rig::YamlSection(spec.controller.params));
            }
        } catch (const rig::ConfigError& error) {
            require_good_error(error);
        }
    }
    return 0;
}
