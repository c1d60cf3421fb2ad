#include "harness/trace_json.h"

namespace rig::harness {

const char* to_string(msg::BreakpointEventKind kind) {
    switch (kind) {
        case msg::BREAKPOINT_STORED: return "stored";
        case msg::BREAKPOINT_REACHED: return "reached";
        case msg::BREAKPOINT_CLEARED: return "cleared";
        case msg::SPRAY_RESUMED: return "spray_resumed";
    }
    return "unknown";
}

const char* to_string(msg::SprayPhase phase) {
    switch (phase) {
        case msg::SPRAY_VALVE_RESET: return "valve_reset";
        case msg::SPRAY_IDLE: return "idle";
        case msg::SPRAY_PRE_ADJUST: return "pre_adjust";
        case msg::SPRAY_REGULATING: return "regulating";
        case msg::SPRAY_HALTED: return "halted";
        case msg::SPRAY_APPROACH: return "approach";
    }
    return "unknown";
}

nlohmann::json to_json(const msg::NmeaSentence& sample) {
    std::string text = sample.sentence().to_string();
    while (!text.empty() && (text.back() == '\n' || text.back() == '\r')) text.pop_back();
    return {{"sentence", text}};
}

nlohmann::json to_json(const msg::EncoderCount& sample) { return {{"count_pulses", sample.count_pulses()}}; }

nlohmann::json to_json(const msg::FlowMeterCount& sample) {
    return {{"count_pulses", sample.count_pulses()}, {"last_edge_capture_us", sample.last_edge_capture_us()}};
}

nlohmann::json to_json(const msg::AnalogInput& sample) { return {{"voltage_v", sample.voltage_v()}}; }

nlohmann::json to_json(const msg::SwitchLevel& sample) { return {{"closed", sample.closed()}}; }

nlohmann::json to_json(const msg::BallValveRelays& sample) {
    return {{"forward", sample.forward()}, {"reverse", sample.reverse()}};
}

nlohmann::json to_json(const msg::SectionValves& sample) { return {{"open_mask", sample.open_mask()}}; }

nlohmann::json to_json(const msg::UnloadingValve& sample) { return {{"open", sample.open()}}; }

nlohmann::json to_json(const msg::HydraulicsTruth& sample) {
    return {{"time_ns", sample.time_ns()},
            {"pump_flow_l_min", sample.pump_flow_l_min()},
            {"valve_opening_pct", sample.valve_opening_pct()},
            {"main_flow_l_min", sample.main_flow_l_min()},
            {"main_volume_l", sample.main_volume_l()},
            {"sections_commanded_mask", sample.sections_commanded_mask()},
            {"sections_spraying_mask", sample.sections_spraying_mask()},
            {"unloading_open", sample.unloading_open()},
            {"nozzles_spraying", sample.nozzles_spraying()}};
}

nlohmann::json to_json(const msg::ControllerStatus& sample) {
    return {{"time_ns", sample.time_ns()},
            {"positioning_mode", sample.positioning_mode() == msg::RTK_ONLY ? "rtk_only" : "fusion"},
            {"breakpoint_pending", sample.breakpoint_pending()},
            {"odometer_active", sample.odometer_active()},
            {"nozzle_to_breakpoint_m", sample.nozzle_to_breakpoint_m()},
            {"speed_km_h", sample.speed_km_h()},
            {"l4_m", sample.l4_m()},
            {"gnss_fix_quality", sample.gnss_fix_quality()},
            {"nmea_rejected_count", sample.nmea_rejected_count()},
            {"spray_phase", to_string(sample.spray_phase())},
            {"target_flow_l_min", sample.target_flow_l_min()},
            {"measured_flow_l_min", sample.measured_flow_l_min()},
            {"pump_flow_l_min", sample.pump_flow_l_min()},
            {"valve_opening_estimate_pct", sample.valve_opening_estimate_pct()},
            {"valve_opening_command_pct", sample.valve_opening_command_pct()},
            {"boom_height_m", sample.boom_height_m()}};
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
            {"wheel_travel_m", sample.wheel_travel_m()},
            {"pass_index", sample.pass_index()}};
}

nlohmann::json to_json(const msg::SerialLine& sample) {
    std::string text = sample.text().to_string();
    while (!text.empty() && (text.back() == '\n' || text.back() == '\r')) text.pop_back();
    return {{"text", text}};
}

nlohmann::json to_json(const msg::NozzlePwm& sample) {
    return {{"frequency_hz", sample.frequency_hz()}, {"duty_pct", sample.duty_pct()}};
}

nlohmann::json to_json(const msg::Vehicle2dTruth& sample) {
    return {{"time_ns", sample.time_ns()},
            {"east_m", sample.east_m()},
            {"north_m", sample.north_m()},
            {"heading_deg", sample.heading_deg()},
            {"speed_m_s", sample.speed_m_s()},
            {"yaw_rate_deg_s", sample.yaw_rate_deg_s()},
            {"antenna_east_m", sample.antenna_east_m()},
            {"antenna_north_m", sample.antenna_north_m()},
            {"antenna_lat_deg", sample.antenna_lat_deg()},
            {"antenna_lon_deg", sample.antenna_lon_deg()},
            {"antenna_height_m", sample.antenna_height_m()},
            {"antenna_velocity_east_m_s", sample.antenna_velocity_east_m_s()},
            {"antenna_velocity_north_m_s", sample.antenna_velocity_north_m_s()},
            {"boom_height_m", sample.boom_height_m()},
            {"boom_offset_m", sample.boom_offset_m()},
            {"boom_centre_east_m", sample.boom_centre_east_m()},
            {"boom_centre_north_m", sample.boom_centre_north_m()}};
}

nlohmann::json to_json(const msg::NozzlesTruth& sample) {
    nlohmann::json nozzles = nlohmann::json::array();
    for (const msg::NozzleTruth& n : sample.nozzles()) {
        nozzles.push_back({{"east_m", n.east_m()},
                           {"north_m", n.north_m()},
                           {"duty_pct", n.duty_pct()},
                           {"opening", n.opening()},
                           {"flow_l_min", n.flow_l_min()},
                           {"delivered_l", n.delivered_l()}});
    }
    return {{"time_ns", sample.time_ns()}, {"nozzles", std::move(nozzles)}};
}

}  // namespace rig::harness
