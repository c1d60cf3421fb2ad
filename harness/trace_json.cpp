#include "harness/trace_json.h"

namespace rig::harness {

const char* to_string(msg::BreakpointEventKind kind) {
    switch (kind) {
        case msg::BREAKPOINT_STORED: return "stored";
        case msg::BREAKPOINT_REACHED: return "reached";
        case msg::BREAKPOINT_CLEARED: return "cleared";
    }
    return "unknown";
}

nlohmann::json to_json(const msg::NmeaSentence& sample) {
    std::string text = sample.sentence().to_string();
    while (!text.empty() && (text.back() == '\n' || text.back() == '\r')) text.pop_back();
    return {{"sentence", text}};
}

nlohmann::json to_json(const msg::EncoderCount& sample) { return {{"count_pulses", sample.count_pulses()}}; }

nlohmann::json to_json(const msg::ButtonLevel& sample) { return {{"pressed", sample.pressed()}}; }

nlohmann::json to_json(const msg::ControllerStatus& sample) {
    return {{"time_ns", sample.time_ns()},
            {"positioning_mode", sample.positioning_mode() == msg::RTK_ONLY ? "rtk_only" : "fusion"},
            {"breakpoint_pending", sample.breakpoint_pending()},
            {"odometer_active", sample.odometer_active()},
            {"nozzle_to_breakpoint_m", sample.nozzle_to_breakpoint_m()},
            {"speed_km_h", sample.speed_km_h()},
            {"l4_m", sample.l4_m()},
            {"gnss_fix_quality", sample.gnss_fix_quality()},
            {"nmea_rejected_count", sample.nmea_rejected_count()}};
}

nlohmann::json to_json(const msg::BreakpointEvent& sample) {
    return {{"time_ns", sample.time_ns()},
            {"breakpoint_id", sample.breakpoint_id()},
            {"kind", to_string(sample.kind())},
            {"lat_deg", sample.lat_deg()},
            {"lon_deg", sample.lon_deg()}};
}

nlohmann::json to_json(const msg::VehicleTruth& sample) {
    return {{"time_ns", sample.time_ns()},
            {"along_m", sample.along_m()},
            {"cross_m", sample.cross_m()},
            {"lat_deg", sample.lat_deg()},
            {"lon_deg", sample.lon_deg()},
            {"height_m", sample.height_m()},
            {"heading_deg", sample.heading_deg()},
            {"speed_m_s", sample.speed_m_s()},
            {"nozzle_line_along_m", sample.nozzle_line_along_m()},
            {"l4_m", sample.l4_m()},
            {"boom_height_m", sample.boom_height_m()},
            {"wheel_travel_m", sample.wheel_travel_m()}};
}

}  // namespace rig::harness
