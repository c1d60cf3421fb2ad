#pragma once
// The seed-001 reference controller's configuration as a case gives it: the
// case's `controller:` section (docs/controller-contract.md, --config FILE),
// read strictly (unknown keys, wrong types and out-of-range values are a
// rig::ConfigError naming file, line and key). Keys are the field names of
// BoundaryControllerConfig (boundary_config.h), where each is declared once
// with its unit, default and source; `areas`, `faults` and `calibration` are
// sections.
#include <filesystem>
#include <vector>

#include "controller/boundary/boundary_config.h"
#include "rig/config/yaml_fields.h"

namespace rig::controller::boundary {

// Table 3's measurement (Sec. 5.2): the paper held each duty on every nozzle of
// the standing sprayer for a minute and read a measuring cylinder. With
// `calibration:` the node does the same instead of the boundary logic: from
// start_s each duty of duties_pct for hold_s, then every valve shut.
struct DutySweepConfig {
    std::vector<double> duties_pct;  // each [0, 100]; empty: no sweep (the boundary logic runs)
    double start_s = 1.0;            // [0, 3600]
    double hold_s = 10.0;            // (0, 3600]; the paper: 60 s per point
};

struct BoundaryNodeConfig {
    BoundaryControllerConfig controller;
    DutySweepConfig calibration;
};

// Throws rig::ConfigError at the offending key (a bound BoundaryControllerConfig's
// validate() finds is reported at the section).
BoundaryNodeConfig parse_boundary_node_config(const YamlSection& section);
BoundaryNodeConfig load_boundary_node_config(const std::filesystem::path& file);

}  // namespace rig::controller::boundary
