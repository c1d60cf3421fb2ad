// libFuzzer harness: the case-file loader (harness/case_spec.h parse_case on
// top of rig/config/yaml_fields.h) and, as `rig run` does before anything starts, the
// reference controller's check of its own `controller:` section.
// Any input must give a spec or a rig::ConfigError that names the file and
// says something; any other exception escaping is a finding.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "controller/controller_config.h"
#include "harness/case_spec.h"
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
        spec = rig::harness::parse_case(text, "fuzz.yaml");
    } catch (const rig::ConfigError& error) {
        require_good_error(error);
        return 0;
    }
    require(!spec.name.empty() && spec.name_location.line > 0);
    require(rig::harness::duplicate_case_name_errors({spec, spec}).size() == 1);
    if (spec.controller.command.empty()) {
        try {
            rig::controller::parse_controller_config(rig::YamlSection(spec.controller.params));
        } catch (const rig::ConfigError& error) {
            require_good_error(error);
        }
    }
    return 0;
}
