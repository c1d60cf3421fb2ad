#include "harness/trace/trace_json.h"

#include <algorithm>
#include <array>
#include <charconv>
#include <cstdint>
#include <cmath>
#include <stdexcept>
#include <string_view>
#include <type_traits>
#include <vector>

#include <nlohmann/json.hpp>

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

namespace {

std::string without_line_end(std::string text) {
    while (!text.empty() && (text.back() == '\n' || text.back() == '\r')) text.pop_back();
    return text;
}

// Each type's fields, once, in the IDL's order.
template <class Out>
void fields(const msg::NmeaSentence& sample, Out& out) {
    out("sentence", without_line_end(sample.sentence().to_string()));
}
// The wheel encoder and the KF11 meter count pulses alike (idl/device.idl).
template <class Out, class Count,
          std::enable_if_t<std::is_same_v<Count, msg::EncoderCount> || std::is_same_v<Count, msg::FlowMeterCount>, int> = 0>
void fields(const Count& sample, Out& out) {
    out("count_pulses", sample.count_pulses());
    out("last_edge_capture_us", sample.last_edge_capture_us());
}
template <class Out>
void fields(const msg::AnalogInput& sample, Out& out) {
    out("voltage_v", sample.voltage_v());
}
template <class Out>
void fields(const msg::SwitchLevel& sample, Out& out) {
    out("closed", sample.closed());
}
template <class Out>
void fields(const msg::BallValveRelays& sample, Out& out) {
    out("forward", sample.forward());
    out("reverse", sample.reverse());
}
template <class Out>
void fields(const msg::SectionValves& sample, Out& out) {
    out("open_mask", sample.open_mask());
}
template <class Out>
void fields(const msg::UnloadingValve& sample, Out& out) {
    out("open", sample.open());
}
template <class Out>
void fields(const msg::HydraulicsTruth& sample, Out& out) {
    out("time_ns", sample.time_ns());
    out("pump_flow_l_min", sample.pump_flow_l_min());
    out("valve_opening_pct", sample.valve_opening_pct());
    out("main_flow_l_min", sample.main_flow_l_min());
    out("main_volume_l", sample.main_volume_l());
    out("sections_commanded_mask", sample.sections_commanded_mask());
    out("sections_spraying_mask", sample.sections_spraying_mask());
    out("unloading_open", sample.unloading_open());
    out("nozzles_spraying", sample.nozzles_spraying());
}
template <class Out>
void fields(const msg::ControllerStatus& sample, Out& out) {
    out("time_ns", sample.time_ns());
    out("positioning_mode", sample.positioning_mode() == msg::RTK_ONLY ? "rtk_only" : "fusion");
    out("breakpoint_pending", sample.breakpoint_pending());
    out("odometer_active", sample.odometer_active());
    out("nozzle_to_breakpoint_m", sample.nozzle_to_breakpoint_m());
    out("speed_km_h", sample.speed_km_h());
    out("l4_m", sample.l4_m());
    out("gnss_fix_quality", sample.gnss_fix_quality());
    out("nmea_rejected_count", sample.nmea_rejected_count());
    out("spray_phase", to_string(sample.spray_phase()));
    out("target_flow_l_min", sample.target_flow_l_min());
    out("measured_flow_l_min", sample.measured_flow_l_min());
    out("pump_flow_l_min", sample.pump_flow_l_min());
    out("valve_opening_estimate_pct", sample.valve_opening_estimate_pct());
    out("valve_opening_command_pct", sample.valve_opening_command_pct());
    out("boom_height_m", sample.boom_height_m());
}
template <class Out>
void fields(const msg::BreakpointEvent& sample, Out& out) {
    out("time_ns", sample.time_ns());
    out("breakpoint_id", sample.breakpoint_id());
    out("kind", to_string(sample.kind()));
    out("lat_deg", sample.lat_deg());
    out("lon_deg", sample.lon_deg());
}
template <class Out>
void fields(const msg::VehicleTruth& sample, Out& out) {
    out("time_ns", sample.time_ns());
    out("along_m", sample.along_m());
    out("cross_m", sample.cross_m());
    out("lat_deg", sample.lat_deg());
    out("lon_deg", sample.lon_deg());
    out("height_m", sample.height_m());
    out("heading_deg", sample.heading_deg());
    out("speed_m_s", sample.speed_m_s());
    out("nozzle_line_along_m", sample.nozzle_line_along_m());
    out("l4_m", sample.l4_m());
    out("boom_height_m", sample.boom_height_m());
    out("wheel_travel_m", sample.wheel_travel_m());
    out("pass_index", sample.pass_index());
}
template <class Out>
void fields(const msg::SerialLine& sample, Out& out) {
    out("text", without_line_end(sample.text().to_string()));
}
template <class Out>
void fields(const msg::NozzlePwm& sample, Out& out) {
    out("frequency_hz", sample.frequency_hz());
    out("duty_pct", sample.duty_pct());
}
template <class Out>
void fields(const msg::Vehicle2dTruth& sample, Out& out) {
    out("time_ns", sample.time_ns());
    out("east_m", sample.east_m());
    out("north_m", sample.north_m());
    out("heading_deg", sample.heading_deg());
    out("speed_m_s", sample.speed_m_s());
    out("yaw_rate_deg_s", sample.yaw_rate_deg_s());
    out("antenna_east_m", sample.antenna_east_m());
    out("antenna_north_m", sample.antenna_north_m());
    out("antenna_lat_deg", sample.antenna_lat_deg());
    out("antenna_lon_deg", sample.antenna_lon_deg());
    out("antenna_height_m", sample.antenna_height_m());
    out("antenna_velocity_east_m_s", sample.antenna_velocity_east_m_s());
    out("antenna_velocity_north_m_s", sample.antenna_velocity_north_m_s());
    out("boom_height_m", sample.boom_height_m());
    out("boom_offset_m", sample.boom_offset_m());
    out("boom_centre_east_m", sample.boom_centre_east_m());
    out("boom_centre_north_m", sample.boom_centre_north_m());
}
template <class Out>
void fields(const msg::NozzleTruth& nozzle, Out& out) {
    out("east_m", nozzle.east_m());
    out("north_m", nozzle.north_m());
    out("duty_pct", nozzle.duty_pct());
    out("opening", nozzle.opening());
    out("flow_l_min", nozzle.flow_l_min());
    out("delivered_l", nozzle.delivered_l());
}
template <class Out>
void fields(const msg::NozzlesTruth& sample, Out& out) {
    out("time_ns", sample.time_ns());
    out("nozzles", sample.nozzles());
}
template <class Out>
void fields(const msg::NozzleDensityReport& nozzle, Out& out) {
    out("nozzle", nozzle.nozzle());
    out("measured", nozzle.measured());
    out("density", nozzle.density());
    out("level", nozzle.level());
}
template <class Out>
void fields(const msg::VisionReport& sample, Out& out) {
    out("time_ns", sample.time_ns());
    out("camera", sample.camera());
    out("frame_number", sample.frame_number());
    out("status", sample.status().to_string());
    out("threshold", sample.threshold());
    out("speed_m_s", sample.speed_m_s());
    out("boom_height_m", sample.boom_height_m());
    out("nozzles", sample.nozzles());
}
template <class Out>
void fields(const msg::NozzleRoiTruth& nozzle, Out& out) {
    out("nozzle", nozzle.nozzle());
    out("density", nozzle.density());
    out("roi_centre_east_m", nozzle.roi_centre_east_m());
    out("roi_centre_north_m", nozzle.roi_centre_north_m());
}
template <class Out>
void fields(const msg::CameraViewTruth& sample, Out& out) {
    out("time_ns", sample.time_ns());
    out("camera", sample.camera());
    out("frame_number", sample.frame_number());
    out("delivered", sample.delivered());
    out("rgb_sha256", sample.rgb_sha256().to_string());
    out("speed_m_s", sample.speed_m_s());
    out("boom_height_m", sample.boom_height_m());
    out("nozzles", sample.nozzles());
}


// One JSON object being written: each field's value is rendered as it comes,
// and finish() puts the fields in key order, as nlohmann's std::map object
// does, so a type lists its fields in the IDL's order.
class ObjectText {
public:
    void operator()(std::string_view key, bool value) { add(key, value ? "true" : "false"); }
    void operator()(std::string_view key, const char* value) { add_string(key, value); }
    void operator()(std::string_view key, const std::string& value) { add_string(key, value); }
    template <class Number, std::enable_if_t<std::is_arithmetic_v<Number> && !std::is_same_v<Number, bool>, int> = 0>
    void operator()(std::string_view key, Number value) {
        begin(key);
        append_number(value);
        close();
    }
    // An array: of numbers (NozzlePwm's duties) or of objects (NozzlesTruth's nozzles).
    template <class Element>
    void operator()(std::string_view key, const std::vector<Element>& elements) {
        begin(key);
        values_ += '[';
        for (std::size_t i = 0; i < elements.size(); ++i) {
            if (i > 0) values_ += ',';
            if constexpr (std::is_arithmetic_v<Element>) {
                append_number(elements[i]);
            } else {
                ObjectText element;
                fields(elements[i], element);
                values_ += element.finish();
            }
        }
        values_ += ']';
        close();
    }

    std::string finish() {
        std::sort(fields_.begin(), fields_.begin() + static_cast<std::ptrdiff_t>(count_),
                  [](const Field& a, const Field& b) { return a.key < b.key; });
        std::string text;
        text.reserve(values_.size() + count_ * 24 + 2);
        text += '{';
        for (std::size_t i = 0; i < count_; ++i) {
            if (i > 0) text += ',';
            text += '"';
            text += fields_[i].key;  // the IDL's names: nothing to escape
            text += "\":";
            text.append(values_, fields_[i].begin, fields_[i].end - fields_[i].begin);
        }
        text += '}';
        return text;
    }

private:
    struct Field {
        std::string_view key;
        std::size_t begin = 0;
        std::size_t end = 0;
    };

    void begin(std::string_view key) {
        if (count_ == fields_.size()) throw std::logic_error("trace JSON: more than 32 fields in one object");
        fields_[count_].key = key;
        fields_[count_].begin = values_.size();
    }
    void close() { fields_[count_++].end = values_.size(); }
    template <class Number>
    void append_number(Number value) {
        std::array<char, 64> buffer{};
        if constexpr (std::is_floating_point_v<Number>) {
            // nlohmann stores every floating-point value as a double and writes a
            // non-finite one as null; otherwise its shortest round-trip digits.
            const double as_double = static_cast<double>(value);
            if (!std::isfinite(as_double)) {
                values_ += "null";
                return;
            }
            char* end = nlohmann::detail::to_chars(buffer.data(), buffer.data() + buffer.size(), as_double);
            values_.append(buffer.data(), end);
        } else {
            // Integers as nlohmann stores them: 64-bit signed or unsigned.
            using Wide = std::conditional_t<std::is_signed_v<Number>, std::int64_t, std::uint64_t>;
            char* end = std::to_chars(buffer.data(), buffer.data() + buffer.size(), static_cast<Wide>(value)).ptr;
            values_.append(buffer.data(), end);
        }
    }
    void add(std::string_view key, std::string_view literal) {
        begin(key);
        values_ += literal;
        close();
    }
    // nlohmann's escapes (dump with ensure_ascii off): the two-character ones,
    // \u00xx for other control characters, everything else as it is. Text that
    // is not plain ASCII goes through nlohmann itself, which also checks the
    // UTF-8 (and throws on bytes that are not, as the trace always did).
    void add_string(std::string_view key, std::string_view text) {
        begin(key);
        const bool ascii = std::all_of(text.begin(), text.end(), [](char c) { return static_cast<unsigned char>(c) < 0x80; });
        if (!ascii) {
            values_ += nlohmann::json(std::string(text)).dump();
            close();
            return;
        }
        static const char* hex = "0123456789abcdef";
        values_ += '"';
        for (const char c : text) {
            switch (c) {
                case '"': values_ += "\\\""; break;
                case '\\': values_ += "\\\\"; break;
                case '\b': values_ += "\\b"; break;
                case '\f': values_ += "\\f"; break;
                case '\n': values_ += "\\n"; break;
                case '\r': values_ += "\\r"; break;
                case '\t': values_ += "\\t"; break;
                default:
                    if (static_cast<unsigned char>(c) < 0x20) {
                        values_ += "\\u00";
                        values_ += hex[(c >> 4) & 0xf];
                        values_ += hex[c & 0xf];
                    } else {
                        values_ += c;
                    }
            }
        }
        values_ += '"';
        close();
    }

    std::array<Field, 32> fields_{};
    std::size_t count_ = 0;
    std::string values_;
};

// One JSON object built as a value, field by field: what nlohmann::json::parse
// gives for ObjectText's text, without the text. Numbers take the kind parsing
// gives them: a finite floating-point value a double (its text always has a
// '.' or an exponent), an integer unsigned unless negative, a non-finite value null.
class ObjectValue {
public:
    void operator()(std::string_view key, bool value) { object_[std::string(key)] = value; }
    void operator()(std::string_view key, const char* value) { object_[std::string(key)] = value; }
    void operator()(std::string_view key, const std::string& value) { object_[std::string(key)] = value; }
    template <class Number, std::enable_if_t<std::is_arithmetic_v<Number> && !std::is_same_v<Number, bool>, int> = 0>
    void operator()(std::string_view key, Number value) {
        object_[std::string(key)] = number(value);
    }
    template <class Element>
    void operator()(std::string_view key, const std::vector<Element>& elements) {
        nlohmann::json array = nlohmann::json::array();
        for (const Element& element : elements) {
            if constexpr (std::is_arithmetic_v<Element>) {
                array.push_back(number(element));
            } else {
                ObjectValue object;
                fields(element, object);
                array.push_back(object.take());
            }
        }
        object_[std::string(key)] = std::move(array);
    }
    nlohmann::json take() { return std::move(object_); }

private:
    template <class Number>
    static nlohmann::json number(Number value) {
        if constexpr (std::is_floating_point_v<Number>) {
            const double as_double = static_cast<double>(value);
            if (!std::isfinite(as_double)) return nullptr;
            return as_double;
        } else if constexpr (std::is_signed_v<Number>) {
            if (value < 0) return static_cast<std::int64_t>(value);
            return static_cast<std::uint64_t>(value);
        } else {
            return static_cast<std::uint64_t>(value);
        }
    }

    nlohmann::json object_ = nlohmann::json::object();
};

template <class Sample>
nlohmann::json object_value(const Sample& sample) {
    ObjectValue out;
    fields(sample, out);
    return out.take();
}

template <class Sample>
std::string object_text(const Sample& sample) {
    ObjectText out;
    fields(sample, out);
    return out.finish();
}

}  // namespace

std::string to_json_text(const msg::NmeaSentence& sample) { return object_text(sample); }
std::string to_json_text(const msg::EncoderCount& sample) { return object_text(sample); }
std::string to_json_text(const msg::FlowMeterCount& sample) { return object_text(sample); }
std::string to_json_text(const msg::AnalogInput& sample) { return object_text(sample); }
std::string to_json_text(const msg::SwitchLevel& sample) { return object_text(sample); }
std::string to_json_text(const msg::BallValveRelays& sample) { return object_text(sample); }
std::string to_json_text(const msg::SectionValves& sample) { return object_text(sample); }
std::string to_json_text(const msg::UnloadingValve& sample) { return object_text(sample); }
std::string to_json_text(const msg::HydraulicsTruth& sample) { return object_text(sample); }
std::string to_json_text(const msg::ControllerStatus& sample) { return object_text(sample); }
std::string to_json_text(const msg::BreakpointEvent& sample) { return object_text(sample); }
std::string to_json_text(const msg::VehicleTruth& sample) { return object_text(sample); }
std::string to_json_text(const msg::SerialLine& sample) { return object_text(sample); }
std::string to_json_text(const msg::NozzlePwm& sample) { return object_text(sample); }
std::string to_json_text(const msg::Vehicle2dTruth& sample) { return object_text(sample); }
std::string to_json_text(const msg::NozzlesTruth& sample) { return object_text(sample); }
std::string to_json_text(const msg::VisionReport& sample) { return object_text(sample); }
std::string to_json_text(const msg::CameraViewTruth& sample) { return object_text(sample); }

#define RIG_DEFINE_TO_JSON_VALUE(Type) \
    nlohmann::json to_json_value(const msg::Type& sample) { return object_value(sample); }
RIG_TRACE_RECORDED_TYPES(RIG_DEFINE_TO_JSON_VALUE)
#undef RIG_DEFINE_TO_JSON_VALUE

std::string cdr_hex_json_text(const std::vector<unsigned char>& bytes) {
    static const char* digits = "0123456789abcdef";
    std::string hex;
    hex.reserve(bytes.size() * 2);
    for (const unsigned char byte : bytes) {
        hex += digits[byte >> 4];
        hex += digits[byte & 0xf];
    }
    ObjectText out;
    out("cdr_hex", hex);
    return out.finish();
}

}  // namespace rig::harness
