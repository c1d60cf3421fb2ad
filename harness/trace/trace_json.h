#pragma once
// Readable JSON for every topic type: what the trace stores and what the report
// reads. Field names are the IDL's (units in the names).
//
// Written as text straight from the sample, with no JSON object in between:
// building, dumping and freeing an nlohmann::json per sample cost the paper
// suite in process about 1.2 s of its 12.4 s of CPU (docs/speed.md). The
// text is byte for byte what
// nlohmann::json::dump() gives for the same object (keys sorted, its number
// format, its escapes), because the trace digest is taken over it:
// tests/trace_json_test.cpp checks that for every type.
#include <string>

#include <nlohmann/json.hpp>

#include "msg_traits.h"

// Every type the trace records as bytes (harness/trace/trace_cdr.h), for lists over them.
#define RIG_TRACE_RECORDED_TYPES(X)                                                                             \
    X(NmeaSentence) X(EncoderCount) X(FlowMeterCount) X(AnalogInput) X(SwitchLevel) X(BallValveRelays)         \
        X(SectionValves) X(UnloadingValve) X(HydraulicsTruth) X(ControllerStatus) X(BreakpointEvent)            \
            X(VehicleTruth) X(SerialLine) X(NozzlePwm) X(Vehicle2dTruth) X(NozzlesTruth) X(VisionReport)        \
                X(CameraViewTruth)

namespace rig::harness {

std::string to_json_text(const msg::NmeaSentence& sample);
std::string to_json_text(const msg::EncoderCount& sample);
std::string to_json_text(const msg::FlowMeterCount& sample);
std::string to_json_text(const msg::AnalogInput& sample);
std::string to_json_text(const msg::SwitchLevel& sample);
std::string to_json_text(const msg::BallValveRelays& sample);
std::string to_json_text(const msg::SectionValves& sample);
std::string to_json_text(const msg::UnloadingValve& sample);
std::string to_json_text(const msg::HydraulicsTruth& sample);
std::string to_json_text(const msg::ControllerStatus& sample);
std::string to_json_text(const msg::BreakpointEvent& sample);
std::string to_json_text(const msg::VehicleTruth& sample);
// Seed 001's wires and truth.
std::string to_json_text(const msg::SerialLine& sample);
std::string to_json_text(const msg::NozzlePwm& sample);
std::string to_json_text(const msg::Vehicle2dTruth& sample);
std::string to_json_text(const msg::NozzlesTruth& sample);
// Seed 001's vision: the controller's report per frame and the crop truth under
// each frame (the frames themselves are not recorded: truth/camera_view names
// each by its SHA-256, and the run renders them again for the report).
std::string to_json_text(const msg::VisionReport& sample);
std::string to_json_text(const msg::CameraViewTruth& sample);
// The same sample as a JSON value, built from its fields with no text between:
// equal, number kinds included (unsigned for a non-negative integer, null for a
// non-finite number), to parsing its JSON text. The judge reads samples so.
#define RIG_DECLARE_TO_JSON_VALUE(Type) nlohmann::json to_json_value(const msg::Type& sample);
RIG_TRACE_RECORDED_TYPES(RIG_DECLARE_TO_JSON_VALUE)
#undef RIG_DECLARE_TO_JSON_VALUE
// A sample of a type the rig does not know, as its CDR bytes in hex.
std::string cdr_hex_json_text(const std::vector<unsigned char>& bytes);
const char* to_string(msg::BreakpointEventKind kind);
const char* to_string(msg::SprayPhase phase);

}  // namespace rig::harness
