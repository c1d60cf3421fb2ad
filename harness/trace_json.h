#pragma once
// Readable JSON for every topic type: what the trace stores and what the report
// reads. Field names are the IDL's (units in the names).
#include <nlohmann/json.hpp>

#include "msg_traits.h"

namespace rig::harness {

nlohmann::json to_json(const msg::NmeaSentence& sample);
nlohmann::json to_json(const msg::EncoderCount& sample);
nlohmann::json to_json(const msg::FlowMeterCount& sample);
nlohmann::json to_json(const msg::AnalogInput& sample);
nlohmann::json to_json(const msg::SwitchLevel& sample);
nlohmann::json to_json(const msg::BallValveRelays& sample);
nlohmann::json to_json(const msg::SectionValves& sample);
nlohmann::json to_json(const msg::UnloadingValve& sample);
nlohmann::json to_json(const msg::HydraulicsTruth& sample);
nlohmann::json to_json(const msg::ControllerStatus& sample);
nlohmann::json to_json(const msg::BreakpointEvent& sample);
nlohmann::json to_json(const msg::VehicleTruth& sample);
// Seed 001's wires and truth.
nlohmann::json to_json(const msg::SerialLine& sample);
nlohmann::json to_json(const msg::NozzlePwm& sample);
nlohmann::json to_json(const msg::Vehicle2dTruth& sample);
nlohmann::json to_json(const msg::NozzlesTruth& sample);
const char* to_string(msg::BreakpointEventKind kind);
const char* to_string(msg::SprayPhase phase);

}  // namespace rig::harness
