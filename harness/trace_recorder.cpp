#include "harness/trace_recorder.h"

#include <openssl/evp.h>
#include <sqlite3.h>

#include <stdexcept>

#include "harness/trace_json.h"
#include "idl/topics.h"

namespace rig::harness {

namespace {

void exec_sql(sqlite3* db, const char* sql, const std::filesystem::path& file) {
    char* error = nullptr;
    if (sqlite3_exec(db, sql, nullptr, nullptr, &error) != SQLITE_OK) {
        const std::string message = error != nullptr ? error : "unknown error";
        sqlite3_free(error);
        throw std::runtime_error("trace " + file.string() + ": " + message);
    }
}

constexpr const char* kSchema = R"sql(
PRAGMA journal_mode = OFF;
PRAGMA synchronous = OFF;
CREATE TABLE meta (key TEXT PRIMARY KEY, value TEXT);
CREATE TABLE samples (t_ns INTEGER NOT NULL, round INTEGER NOT NULL, topic TEXT NOT NULL, json TEXT NOT NULL);
CREATE INDEX samples_by_topic ON samples (topic, t_ns);
CREATE VIEW vehicle_truth AS SELECT t_ns / 1e9 AS t_s,
  json_extract(json, '$.along_m') AS antenna_along_m,
  json_extract(json, '$.nozzle_line_along_m') AS nozzle_line_along_m,
  json_extract(json, '$.speed_m_s') AS speed_m_s,
  json_extract(json, '$.wheel_travel_m') AS wheel_travel_m
  FROM samples WHERE topic = 'truth/vehicle';
CREATE VIEW nmea AS SELECT t_ns / 1e9 AS t_s, json_extract(json, '$.sentence') AS sentence
  FROM samples WHERE topic = 'device/gnss/nmea';
CREATE VIEW breakpoint_events AS SELECT t_ns / 1e9 AS t_s, json_extract(json, '$.kind') AS kind,
  json_extract(json, '$.lat_deg') AS lat_deg, json_extract(json, '$.lon_deg') AS lon_deg
  FROM samples WHERE topic = 'controller/breakpoint_event';
CREATE VIEW controller_status AS SELECT t_ns / 1e9 AS t_s,
  json_extract(json, '$.nozzle_to_breakpoint_m') AS nozzle_to_breakpoint_m,
  json_extract(json, '$.odometer_active') AS odometer_active,
  json_extract(json, '$.speed_km_h') AS speed_km_h,
  json_extract(json, '$.spray_phase') AS spray_phase,
  json_extract(json, '$.measured_flow_l_min') AS measured_flow_l_min,
  json_extract(json, '$.valve_opening_estimate_pct') AS valve_opening_estimate_pct,
  json_extract(json, '$.valve_opening_command_pct') AS valve_opening_command_pct
  FROM samples WHERE topic = 'controller/status';
CREATE VIEW hydraulics AS SELECT t_ns / 1e9 AS t_s,
  json_extract(json, '$.main_flow_l_min') AS main_flow_l_min,
  json_extract(json, '$.pump_flow_l_min') AS pump_flow_l_min,
  json_extract(json, '$.valve_opening_pct') AS valve_opening_pct,
  json_extract(json, '$.sections_spraying_mask') AS sections_spraying_mask,
  json_extract(json, '$.nozzles_spraying') AS nozzles_spraying
  FROM samples WHERE topic = 'truth/hydraulics';
CREATE VIEW actuators AS SELECT t_ns / 1e9 AS t_s, topic, json
  FROM samples WHERE topic LIKE 'actuator/%';
-- Spray on the ground (plant truth), written at the end of the run: dose per
-- grid cell (pass 0 = first pass, 1 = continuation), nozzle columns left to right.
CREATE TABLE deposition (pass INTEGER NOT NULL, along_m REAL NOT NULL, nozzle INTEGER NOT NULL,
  dose_ul_cm2 REAL NOT NULL);
CREATE VIEW deposition_rows AS SELECT pass, along_m, avg(dose_ul_cm2) AS mean_dose_ul_cm2
  FROM deposition GROUP BY pass, along_m;
BEGIN;
)sql";

}  // namespace

template <class Msg>
void TraceRecorder::add_channel(DdsContext& dds, const char* topic) {
    auto reader = std::make_shared<Reader<Msg>>(dds, topic);
    readers_.push_back(reader);
    channels_.push_back(Channel{topic, [reader] {
                                    std::vector<nlohmann::json> out;
                                    for (const Msg& sample : reader->take_all()) out.push_back(to_json(sample));
                                    return out;
                                }});
}

TraceRecorder::TraceRecorder(DdsContext& dds, const std::filesystem::path& file) {
    // Fixed channel order: part of what makes the trace reproducible.
    add_channel<msg::VehicleTruth>(dds, topics::kVehicleTruth);
    add_channel<msg::NmeaSentence>(dds, topics::kGnssNmea);
    add_channel<msg::EncoderCount>(dds, topics::kWheelEncoder);
    add_channel<msg::HydraulicsTruth>(dds, topics::kHydraulicsTruth);
    add_channel<msg::FlowMeterCount>(dds, topics::kMainFlowMeter);
    add_channel<msg::AnalogInput>(dds, topics::kPumpFlowSensor);
    add_channel<msg::AnalogInput>(dds, topics::kBoomHeightSensor);
    add_channel<msg::SwitchLevel>(dds, topics::kBreakpointButton);
    add_channel<msg::SwitchLevel>(dds, topics::kSpraySwitch);
    add_channel<msg::BallValveRelays>(dds, topics::kBallValveRelays);
    add_channel<msg::SectionValves>(dds, topics::kSectionValves);
    add_channel<msg::UnloadingValve>(dds, topics::kUnloadingValve);
    add_channel<msg::ControllerStatus>(dds, topics::kControllerStatus);
    add_channel<msg::BreakpointEvent>(dds, topics::kBreakpointEvent);

    std::filesystem::remove(file);
    if (sqlite3_open(file.c_str(), &db_) != SQLITE_OK) {
        throw std::runtime_error("cannot create trace " + file.string() + ": " + sqlite3_errmsg(db_));
    }
    exec_sql(db_, kSchema, file);
    if (sqlite3_prepare_v2(db_, "INSERT INTO samples VALUES (?, ?, ?, ?)", -1, &insert_, nullptr) != SQLITE_OK) {
        throw std::runtime_error("trace " + file.string() + ": " + sqlite3_errmsg(db_));
    }
    digest_ = EVP_MD_CTX_new();
    EVP_DigestInit_ex(digest_, EVP_sha256(), nullptr);
}

TraceRecorder::~TraceRecorder() {
    if (insert_ != nullptr) sqlite3_finalize(insert_);
    if (db_ != nullptr) sqlite3_close(db_);
    if (digest_ != nullptr) EVP_MD_CTX_free(digest_);
}

void TraceRecorder::set_meta(const std::string& key, const std::string& value) {
    sqlite3_stmt* statement = nullptr;
    sqlite3_prepare_v2(db_, "INSERT OR REPLACE INTO meta VALUES (?, ?)", -1, &statement, nullptr);
    sqlite3_bind_text(statement, 1, key.c_str(), -1, SQLITE_TRANSIENT);
    sqlite3_bind_text(statement, 2, value.c_str(), -1, SQLITE_TRANSIENT);
    sqlite3_step(statement);
    sqlite3_finalize(statement);
}

void TraceRecorder::append(TimeNs t, int round, const std::string& topic, const nlohmann::json& json) {
    const std::string text = json.dump();
    const std::string canonical =
        std::to_string(t) + " " + std::to_string(round) + " " + topic + " " + text + "\n";
    EVP_DigestUpdate(digest_, canonical.data(), canonical.size());
    sqlite3_bind_int64(insert_, 1, t);
    sqlite3_bind_int(insert_, 2, round);
    sqlite3_bind_text(insert_, 3, topic.c_str(), -1, SQLITE_TRANSIENT);
    sqlite3_bind_text(insert_, 4, text.c_str(), -1, SQLITE_TRANSIENT);
    if (sqlite3_step(insert_) != SQLITE_DONE) throw std::runtime_error(std::string("trace: ") + sqlite3_errmsg(db_));
    sqlite3_reset(insert_);
    by_topic_[topic].emplace_back(t, json);
}

void TraceRecorder::drain(TimeNs t, int round) {
    for (const Channel& channel : channels_) {
        for (const nlohmann::json& json : channel.take()) append(t, round, channel.topic, json);
    }
}

void TraceRecorder::record_deposition(const emulators::DepositionGrid& grid) {
    sqlite3_stmt* statement = nullptr;
    if (sqlite3_prepare_v2(db_, "INSERT INTO deposition VALUES (?, ?, ?, ?)", -1, &statement, nullptr) != SQLITE_OK) {
        throw std::runtime_error(std::string("trace: ") + sqlite3_errmsg(db_));
    }
    // Non-empty cells only; each one also goes into the digest, so a changed
    // deposition changes trace_sha256 like a changed sample does.
    for (int pass = 0; pass < grid.pass_count(); ++pass) {
        for (std::size_t row = 0; row < grid.row_count(); ++row) {
            for (int nozzle = 0; nozzle < grid.params().nozzle_count; ++nozzle) {
                const double dose = grid.dose_ul_cm2(pass, row, nozzle);
                if (dose <= 0.0) continue;
                const std::string canonical = "deposition " + std::to_string(pass) + " " + std::to_string(row) + " " +
                                              std::to_string(nozzle) + " " + nlohmann::json(dose).dump() + "\n";
                EVP_DigestUpdate(digest_, canonical.data(), canonical.size());
                sqlite3_bind_int(statement, 1, pass);
                sqlite3_bind_double(statement, 2, grid.row_centre_m(row));
                sqlite3_bind_int(statement, 3, nozzle);
                sqlite3_bind_double(statement, 4, dose);
                if (sqlite3_step(statement) != SQLITE_DONE) {
                    const std::string error = sqlite3_errmsg(db_);
                    sqlite3_finalize(statement);
                    throw std::runtime_error("trace: " + error);
                }
                sqlite3_reset(statement);
            }
        }
    }
    sqlite3_finalize(statement);
}

std::string TraceRecorder::finish() {
    if (!sha256_.empty()) return sha256_;
    exec_sql(db_, "COMMIT;", "trace");
    unsigned char hash[EVP_MAX_MD_SIZE];
    unsigned int length = 0;
    EVP_DigestFinal_ex(digest_, hash, &length);
    static const char* hex = "0123456789abcdef";
    for (unsigned int i = 0; i < length; ++i) {
        sha256_ += hex[hash[i] >> 4];
        sha256_ += hex[hash[i] & 0xf];
    }
    sqlite3_finalize(insert_);
    insert_ = nullptr;
    sqlite3_close(db_);
    db_ = nullptr;
    return sha256_;
}

const std::vector<std::pair<TimeNs, nlohmann::json>>& TraceRecorder::samples(const std::string& topic) const {
    static const std::vector<std::pair<TimeNs, nlohmann::json>> empty;
    const auto it = by_topic_.find(topic);
    return it == by_topic_.end() ? empty : it->second;
}

}  // namespace rig::harness
