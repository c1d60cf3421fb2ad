#include "harness/judge.h"

#include <sqlite3.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <map>
#include <set>
#include <stdexcept>

#include "emulators/field_frame.h"
#include "harness/boundary_judge.h"
#include "harness/sha256.h"
#include "harness/trace_file.h"
#include "harness/wire_fault_report.h"
#include "idl/topics.h"
#include "rig/runtime/failure_kind.h"

namespace rig::harness {

// ---------------------------------------------------------------- the plan

nlohmann::json to_json(const JudgingPlan& plan) {
    nlohmann::json json = {
        {"scenario", plan.scenario},
        {"breakpoint_along_m", plan.breakpoint_along_m},
        {"field",
         {{"origin_lat_deg", plan.field_origin_lat_deg},
          {"origin_lon_deg", plan.field_origin_lon_deg},
          {"origin_height_m", plan.field_origin_height_m},
          {"heading_deg", plan.field_heading_deg}}},
        {"judge_breakpoint", plan.judge_breakpoint},
        {"judge_flow", plan.judge_flow},
        {"judge_deposition", plan.judge_deposition},
        {"limits", plan.limits},
        {"expect", {{"fail", plan.expect_fail}, {"error", plan.expect_error}, {"set_aside", plan.expect_set_aside}}},
    };
    if (plan.judge_flow) {
        json["flow"] = {{"target_l_min", plan.flow.target_l_min},
                        {"band_pct", plan.flow.band_pct},
                        {"settle_by_s", plan.flow.settle_by_s},
                        {"window_from_ns", plan.flow_window.from_ns},
                        {"window_to_ns", plan.flow_window.to_ns},
                        {"kf11_pulses_per_l", plan.kf11_pulses_per_l},
                        {"kf11_window_s", plan.kf11_window_s}};
    }
    if (plan.judge_fig11) {
        json["fig11"] = {{"window_from_ns", plan.flow_window.from_ns}, {"window_to_ns", plan.flow_window.to_ns}};
    }
    if (plan.judge_deposition) {
        json["deposition"] = {{"nominal_dose_ul_cm2", plan.deposition.nominal_dose_ul_cm2},
                              {"sprayed_fraction", plan.deposition.sprayed_fraction},
                              {"cv_row_m", plan.deposition.cv_row_m},
                              {"cv_window_m", plan.deposition.cv_window_m},
                              {"strip_from_m", plan.deposition.strip_from_m},
                              {"strip_to_m", plan.deposition.strip_to_m}};
    }
    return json;
}

JudgingPlan judging_plan_from_json(const nlohmann::json& json) {
    // at("a/b"): the value, or an error naming the key path.
    std::function<const nlohmann::json&(const nlohmann::json&, const std::string&, const std::string&)> at =
        [](const nlohmann::json& node, const std::string& key, const std::string& path) -> const nlohmann::json& {
        if (!node.is_object() || !node.contains(key)) throw std::runtime_error("judging plan: no key " + path + key);
        return node.at(key);
    };
    try {
        JudgingPlan plan;
        plan.scenario = at(json, "scenario", "").get<std::string>();
        plan.breakpoint_along_m = at(json, "breakpoint_along_m", "").get<double>();
        const nlohmann::json& field = at(json, "field", "");
        plan.field_origin_lat_deg = at(field, "origin_lat_deg", "field.").get<double>();
        plan.field_origin_lon_deg = at(field, "origin_lon_deg", "field.").get<double>();
        plan.field_origin_height_m = at(field, "origin_height_m", "field.").get<double>();
        plan.field_heading_deg = at(field, "heading_deg", "field.").get<double>();
        plan.judge_breakpoint = at(json, "judge_breakpoint", "").get<bool>();
        plan.judge_flow = at(json, "judge_flow", "").get<bool>();
        plan.judge_deposition = at(json, "judge_deposition", "").get<bool>();
        plan.limits = at(json, "limits", "").get<std::map<std::string, double>>();
        const nlohmann::json& expect = at(json, "expect", "");
        plan.expect_fail = at(expect, "fail", "expect.").get<std::vector<std::string>>();
        plan.expect_error = at(expect, "error", "expect.").get<std::string>();
        // Traces from before expectations could be set aside have no reason.
        if (expect.contains("set_aside")) plan.expect_set_aside = at(expect, "set_aside", "expect.").get<std::string>();
        if (plan.judge_flow) {
            const nlohmann::json& flow = at(json, "flow", "");
            plan.flow.target_l_min = at(flow, "target_l_min", "flow.").get<double>();
            plan.flow.band_pct = at(flow, "band_pct", "flow.").get<double>();
            plan.flow.settle_by_s = at(flow, "settle_by_s", "flow.").get<double>();
            plan.flow_window.from_ns = at(flow, "window_from_ns", "flow.").get<TimeNs>();
            plan.flow_window.to_ns = at(flow, "window_to_ns", "flow.").get<TimeNs>();
            plan.kf11_pulses_per_l = at(flow, "kf11_pulses_per_l", "flow.").get<double>();
            plan.kf11_window_s = at(flow, "kf11_window_s", "flow.").get<double>();
        }
        // Traces from before the valve_calibration scenario have no fig11 section.
        if (json.contains("fig11")) {
            const nlohmann::json& fig11 = at(json, "fig11", "");
            plan.judge_fig11 = true;
            plan.flow_window.from_ns = at(fig11, "window_from_ns", "fig11.").get<TimeNs>();
            plan.flow_window.to_ns = at(fig11, "window_to_ns", "fig11.").get<TimeNs>();
        }
        if (plan.judge_deposition) {
            const nlohmann::json& deposition = at(json, "deposition", "");
            plan.deposition.nominal_dose_ul_cm2 = at(deposition, "nominal_dose_ul_cm2", "deposition.").get<double>();
            plan.deposition.sprayed_fraction = at(deposition, "sprayed_fraction", "deposition.").get<double>();
            plan.deposition.cv_row_m = at(deposition, "cv_row_m", "deposition.").get<double>();
            plan.deposition.cv_window_m = at(deposition, "cv_window_m", "deposition.").get<double>();
            plan.deposition.strip_from_m = at(deposition, "strip_from_m", "deposition.").get<double>();
            plan.deposition.strip_to_m = at(deposition, "strip_to_m", "deposition.").get<double>();
        }
        return plan;
    } catch (const nlohmann::json::exception& error) {
        throw std::runtime_error(std::string("judging plan: ") + error.what());
    }
}

// ---------------------------------------------------------------- reading a trace

namespace {

// The topics the judge reads (the rest of the trace is for people and tools).
const std::set<std::string>& judged_topics() {
    static const std::set<std::string> topics = {
        topics::kVehicleTruth,     topics::kHydraulicsTruth,  topics::kSectionValves,
        topics::kBreakpointEvent,  topics::kControllerStatus, topics::kMainFlowMeter,
        topics::kVehicle2dTruth,   topics::kNozzlesTruth,     topics::kGnssNmea,  // GNSS wire faults
        topics::kNozzlePwm,        topics::kVisionReport,     topics::kCameraViewTruth,  // seed 001's vision
    };
    return topics;
}

class TraceDb {
public:
    explicit TraceDb(const std::filesystem::path& file) : file_(file) {
        if (sqlite3_open_v2(file.c_str(), &db_, SQLITE_OPEN_READONLY, nullptr) != SQLITE_OK) {
            const std::string reason = db_ != nullptr ? sqlite3_errmsg(db_) : "out of memory";
            sqlite3_close(db_);
            db_ = nullptr;
            throw std::runtime_error("trace " + file.string() + ": cannot open: " + reason);
        }
    }
    ~TraceDb() { sqlite3_close(db_); }
    TraceDb(const TraceDb&) = delete;
    TraceDb& operator=(const TraceDb&) = delete;

    // Runs `sql`, calling `row` with each result row's statement.
    void each(const std::string& sql, const std::function<void(sqlite3_stmt*)>& row) {
        sqlite3_stmt* statement = nullptr;
        if (sqlite3_prepare_v2(db_, sql.c_str(), -1, &statement, nullptr) != SQLITE_OK) {
            const std::string reason = sqlite3_errmsg(db_);
            throw std::runtime_error("trace " + file_.string() + ": " + reason +
                                     " (not a trace of this rig, or from another version of it?)");
        }
        int rc = SQLITE_ROW;
        try {
            while ((rc = sqlite3_step(statement)) == SQLITE_ROW) row(statement);
        } catch (...) {
            sqlite3_finalize(statement);
            throw;
        }
        sqlite3_finalize(statement);
        if (rc != SQLITE_DONE) throw std::runtime_error("trace " + file_.string() + ": " + sqlite3_errmsg(db_));
    }

private:
    std::filesystem::path file_;
    sqlite3* db_ = nullptr;
};


std::string column_text(sqlite3_stmt* statement, int column) {
    const unsigned char* text = sqlite3_column_text(statement, column);
    return text == nullptr ? std::string() : std::string(reinterpret_cast<const char*>(text));
}

}  // namespace

RecordedTrace read_trace(const std::filesystem::path& file) {
    std::error_code error;
    const auto status = std::filesystem::status(file, error);
    if (error || !std::filesystem::exists(status)) throw std::runtime_error("trace " + file.string() + ": no such file");
    if (!std::filesystem::is_regular_file(status)) {
        throw std::runtime_error("trace " + file.string() + ": not a regular file");
    }
    RecordedTrace trace;
    trace.file = file;
    TraceDb db(file);
    db.each("SELECT key, value FROM meta", [&](sqlite3_stmt* row) {
        trace.meta[column_text(row, 0)] = column_text(row, 1);
    });
    const auto format = trace.meta.find("trace_format");
    if (format == trace.meta.end() || format->second != std::to_string(kTraceFormat)) {
        throw std::runtime_error("trace " + file.string() + ": trace format " +
                                 (format == trace.meta.end() ? std::string("unknown") : format->second) +
                                 ", this rig reads format " + std::to_string(kTraceFormat) + " (run the case again)");
    }
    // Every row goes through the digest (TraceFile's canonical form); the rows of
    // the judged topics are also parsed.
    Sha256 digest;
    db.each("SELECT t_ns, round, topic, json, rowid FROM samples ORDER BY rowid", [&](sqlite3_stmt* row) {
        const std::string topic = column_text(row, 2);
        const std::string text = column_text(row, 3);
        const TimeNs t_ns = sqlite3_column_int64(row, 0);
        const int round = sqlite3_column_int(row, 1);
        digest.add(std::to_string(t_ns) + " " + std::to_string(round) + " " + topic + " " + text + "\n");
        if (!judged_topics().count(topic)) return;
        RecordedSample sample;
        sample.t_ns = t_ns;
        sample.round = round;
        try {
            sample.json = nlohmann::json::parse(text);
        } catch (const nlohmann::json::exception& parse_error) {
            throw std::runtime_error("trace " + file.string() + ": samples row " +
                                     std::to_string(sqlite3_column_int64(row, 4)) + ": " + parse_error.what());
        }
        trace.samples[topic].push_back(std::move(sample));
    });

    // The deposition grid: mean dose across the boom per row and pass, summed in
    // nozzle order as emulators::DepositionGrid does (so the numbers match it exactly).
    if (const auto grid = trace.meta.find("deposition_grid"); grid != trace.meta.end()) {
        nlohmann::json params;
        try {
            params = nlohmann::json::parse(grid->second);
            trace.dose.first_row_centre_m = params.at("first_row_centre_m").get<double>();
            trace.dose.row_m = params.at("cell_along_m").get<double>();
        } catch (const nlohmann::json::exception& parse_error) {
            throw std::runtime_error("trace " + file.string() + ": meta deposition_grid: " + parse_error.what());
        }
        const auto rows = params.at("rows").get<std::size_t>();
        const int nozzles = params.at("nozzle_count").get<int>();
        const int passes = params.at("passes").get<int>();
        std::vector<std::vector<double>> sums(static_cast<std::size_t>(std::max(passes, 0)),
                                              std::vector<double>(rows, 0.0));
        db.each("SELECT pass, row, nozzle, dose_ul_cm2 FROM deposition ORDER BY rowid", [&](sqlite3_stmt* row) {
            const auto pass = static_cast<std::size_t>(sqlite3_column_int(row, 0));
            const auto index = static_cast<std::size_t>(sqlite3_column_int64(row, 1));
            const double dose = sqlite3_column_double(row, 3);
            digest.add("deposition " + std::to_string(pass) + " " + std::to_string(index) + " " +
                       std::to_string(sqlite3_column_int(row, 2)) + " " + nlohmann::json(dose).dump() + "\n");
            if (pass >= sums.size() || index >= rows) {
                throw std::runtime_error("trace " + file.string() + ": deposition cell (pass " + std::to_string(pass) +
                                         ", row " + std::to_string(index) + ") outside the recorded grid");
            }
            sums[pass][index] += dose;
        });
        for (auto& layer : sums) {
            for (double& sum : layer) sum /= nozzles;
        }
        if (!sums.empty()) trace.dose.first_pass = std::move(sums[0]);
        if (sums.size() > 1) trace.dose.continuation = std::move(sums[1]);
    }
    db.each("SELECT t_ns, landing FROM landing_edges ORDER BY rowid", [&](sqlite3_stmt* row) {
        const LandingEdgeSample edge{sqlite3_column_int64(row, 0), sqlite3_column_int(row, 1) != 0};
        digest.add("landing " + std::to_string(edge.t_ns) + " " + (edge.landing ? "1" : "0") + "\n");
        trace.landing_edges.push_back(edge);
    });
    trace.recomputed_sha256 = digest.hex();
    db.each("SELECT t_ns, participant, guid_prefix, endpoint, topic, event FROM discovery ORDER BY rowid",
            [&](sqlite3_stmt* row) {
                trace.discovery.push_back(RecordedDiscovery{sqlite3_column_int64(row, 0), column_text(row, 1),
                                                            column_text(row, 2), column_text(row, 3),
                                                            column_text(row, 4), column_text(row, 5)});
            });
    db.each("SELECT t_ns, topic, participant FROM foreign_samples ORDER BY rowid", [&](sqlite3_stmt* row) {
        trace.foreign_samples.push_back(
            RecordedForeignSample{sqlite3_column_int64(row, 0), column_text(row, 1), column_text(row, 2)});
    });
    return trace;
}

// ---------------------------------------------------------------- roles

std::optional<std::string> topic_role_violation(const std::string& endpoint, const std::string& topic) {
    const bool writer = endpoint == "writer";
    if (topic.rfind("truth/", 0) == 0) return std::string(writer ? "writes" : "reads") + " truth topic " + topic;
    if (writer && topic.rfind("device/", 0) == 0) return "writes device topic " + topic;
    if (writer && topic == topics::kClockTick) return "writes the clock's tick topic " + topic;
    return std::nullopt;
}

std::optional<std::string> declared_role_violation(const std::vector<std::string>& subscribed,
                                                   const std::vector<std::string>& published) {
    for (const std::string& topic : subscribed) {
        if (auto why = topic_role_violation("reader", topic)) return *why + " (declared in its hello)";
    }
    for (const std::string& topic : published) {
        if (auto why = topic_role_violation("writer", topic)) return *why + " (declared in its hello)";
    }
    return std::nullopt;
}

// ---------------------------------------------------------------- judging

namespace {

const std::vector<RecordedSample>& samples_of(const RecordedTrace& trace, const char* topic) {
    static const std::vector<RecordedSample> none;
    const auto it = trace.samples.find(topic);
    return it == trace.samples.end() ? none : it->second;
}

std::string meta_or(const RecordedTrace& trace, const std::string& key, const std::string& fallback = {}) {
    const auto it = trace.meta.find(key);
    return it == trace.meta.end() ? fallback : it->second;
}

// The first role broken in the trace: an endpoint discovery saw, or a forged sample.
std::optional<std::pair<std::string, std::string>> first_role_violation(const RecordedTrace& trace) {
    for (const RecordedDiscovery& endpoint : trace.discovery) {
        if (endpoint.event != "discovered") continue;
        if (const auto why = topic_role_violation(endpoint.endpoint, endpoint.topic)) {
            return std::make_pair(endpoint.participant, *why + " (participant '" + endpoint.participant + "', GUID prefix " +
                                                            endpoint.guid_prefix + ", seen by discovery)");
        }
    }
    if (!trace.foreign_samples.empty()) {
        const RecordedForeignSample& first = trace.foreign_samples.front();
        const auto count = std::count_if(trace.foreign_samples.begin(), trace.foreign_samples.end(),
                                         [&](const auto& sample) { return sample.topic == first.topic; });
        return std::make_pair(first.participant, "wrote " + std::to_string(count) + " sample(s) on " + first.topic +
                                                     " (participant '" + first.participant +
                                                     "'): forged data, never judged as truth");
    }
    return std::nullopt;
}

std::vector<VehicleSample> vehicle_samples(const RecordedTrace& trace) {
    std::vector<VehicleSample> samples;
    for (const RecordedSample& sample : samples_of(trace, topics::kVehicleTruth)) {
        samples.push_back(VehicleSample{sample.t_ns, sample.json.at("nozzle_line_along_m").get<double>(),
                                        sample.json.at("pass_index").get<int>()});
    }
    return samples;
}

// The flow judge reads the main flow and the sections; Fig. 11's also the pump
// and the valve (`with_pump_and_valve`).
std::vector<HydraulicsSample> hydraulics_samples(const RecordedTrace& trace, bool with_pump_and_valve = false) {
    std::vector<HydraulicsSample> samples;
    for (const RecordedSample& sample : samples_of(trace, topics::kHydraulicsTruth)) {
        HydraulicsSample hydraulics{sample.t_ns, sample.json.at("main_flow_l_min").get<double>(),
                                    sample.json.at("sections_spraying_mask").get<std::uint16_t>()};
        if (with_pump_and_valve) {
            hydraulics.pump_flow_l_min = sample.json.at("pump_flow_l_min").get<double>();
            hydraulics.valve_opening_pct = sample.json.at("valve_opening_pct").get<double>();
        }
        samples.push_back(hydraulics);
    }
    return samples;
}

std::vector<SectionCommand> section_commands(const RecordedTrace& trace) {
    std::vector<SectionCommand> commands;
    for (const RecordedSample& sample : samples_of(trace, topics::kSectionValves)) {
        commands.push_back(SectionCommand{sample.t_ns, sample.json.at("open_mask").get<std::uint16_t>()});
    }
    return commands;
}

std::vector<FlowMeterCountSample> flow_meter_samples(const RecordedTrace& trace) {
    std::vector<FlowMeterCountSample> samples;
    for (const RecordedSample& sample : samples_of(trace, topics::kMainFlowMeter)) {
        samples.push_back(FlowMeterCountSample{sample.t_ns, sample.json.at("count_pulses").get<std::uint32_t>(),
                                               sample.json.at("last_edge_capture_us").get<std::uint32_t>()});
    }
    return samples;
}

std::vector<BreakpointEventSample> breakpoint_events(const RecordedTrace& trace) {
    std::vector<BreakpointEventSample> events;
    for (const RecordedSample& sample : samples_of(trace, topics::kBreakpointEvent)) {
        BreakpointEventSample event;
        event.t_ns = sample.t_ns;
        event.kind = sample.json.at("kind").get<std::string>();
        if (sample.json.at("lat_deg").is_number()) event.lat_deg = sample.json.at("lat_deg").get<double>();
        if (sample.json.at("lon_deg").is_number()) event.lon_deg = sample.json.at("lon_deg").get<double>();
        events.push_back(event);
    }
    return events;
}

// Fig. 14: main flow (truth) and the controller's Eq. 3 reading, against the
// nozzle line's distance to the breakpoint, around the judged opening.
void add_flow_figure(const RecordedTrace& trace, const VehicleTrack& track, TimeNs open_ns, TimeNs window_end_ns,
                     double breakpoint_along_m, CaseFigures& figures) {
    const TimeNs from_ns = open_ns - seconds_to_ns(1.0);
    const TimeNs to_ns = std::min(window_end_ns, open_ns + seconds_to_ns(8.0));
    std::map<TimeNs, double> measured;
    for (const RecordedSample& status : samples_of(trace, topics::kControllerStatus)) {
        if (status.t_ns >= from_ns && status.t_ns <= to_ns && status.json.at("measured_flow_l_min").is_number()) {
            measured[status.t_ns] = status.json.at("measured_flow_l_min").get<double>();
        }
    }
    for (const RecordedSample& sample : samples_of(trace, topics::kHydraulicsTruth)) {
        if (sample.t_ns < from_ns || sample.t_ns > to_ns) continue;
        FlowSample point;
        point.t_s = ns_to_seconds(sample.t_ns);
        if (const auto along_m = track.nozzle_line_along_m(sample.t_ns)) {
            point.distance_to_breakpoint_m = *along_m - breakpoint_along_m;
        }
        point.main_flow_l_min = sample.json.at("main_flow_l_min").get<double>();
        if (const auto it = measured.find(sample.t_ns); it != measured.end()) point.measured_flow_l_min = it->second;
        figures.flow.push_back(point);
    }
}

// Fig. 15: dose per row across the breakpoint, by pass, with the judged areas.
void add_dose_figure(const DoseProfile& profile, const DepositionResult& deposition, double breakpoint_along_m,
                     double window_m, CaseFigures& figures) {
    double from_m = breakpoint_along_m - 2.0 * window_m;
    double to_m = breakpoint_along_m + 2.0 * window_m;
    for (const AreaSpan& area : deposition.areas) {
        from_m = std::min(from_m, area.from_along_m - 1.0);
        to_m = std::max(to_m, area.to_along_m + 1.0);
    }
    const std::size_t rows = std::max(profile.first_pass.size(), profile.continuation.size());
    for (std::size_t row = 0; row < rows; ++row) {
        const double along_m = profile.row_centre_m(row);
        if (along_m < from_m || along_m > to_m) continue;
        figures.dose.push_back(DoseSample{along_m, row < profile.first_pass.size() ? profile.first_pass[row] : 0.0,
                                          row < profile.continuation.size() ? profile.continuation[row] : 0.0});
    }
    figures.areas = deposition.areas;
}

void read_run_facts(const RecordedTrace& trace, CaseResult& result, CaseFigures& figures) {
    const std::string text = meta_or(trace, "run");
    if (text.empty()) return;
    nlohmann::json run;
    try {
        run = nlohmann::json::parse(text);
    } catch (const nlohmann::json::exception& error) {
        throw std::runtime_error("trace " + trace.file.string() + ": meta run: " + error.what());
    }
    result.wall_seconds = run.value("wall_seconds", 0.0);
    result.startup_wall_seconds = run.value("startup_wall_seconds", 0.0);
    result.instants = run.value("instants", std::uint64_t{0});
    result.rounds = run.value("rounds", std::uint64_t{0});
    result.stepping_wall_seconds = run.value("stepping_wall_seconds", 0.0);
    result.controller_mode = run.value("controller_mode", std::string());
    result.in_process_refused = run.value("in_process_refused", std::string());
    result.realtime_scheduling = run.value("realtime_scheduling", std::string());
    if (run.contains("board_io")) result.board_io = run.at("board_io");
    if (run.contains("lateness")) result.rig_lateness = run.at("lateness");
    if (run.contains("emission_jitter")) {
        for (const nlohmann::json& device : run.at("emission_jitter")) {
            EmissionJitter jitter{device.at("device").get<std::string>(), device.at("samples").get<std::size_t>(),
                                  device.at("p50_ms").get<double>(),      device.at("p99_ms").get<double>(),
                                  device.at("max_ms").get<double>(),      device.at("step_p99_ms").get<double>(),
                                  device.at("step_max_ms").get<double>()};
            result.emission_jitter.push_back(jitter);
            figures.jitter.push_back(JitterRow{jitter.device, jitter.p50_ms, jitter.p99_ms, jitter.max_ms, jitter.step_max_ms});
        }
    }
}

// A real-time run whose own emissions passed the case's lateness bound cannot
// judge the controller: its verdict is invalid (rig_overloaded), whatever the
// controller did, unless the run already ended in something the lateness does
// not explain (a stop signal, the rig's own error, a broken topic role).
void apply_rig_overload(CaseResult& result) {
    if (!result.rig_lateness.is_object()) return;
    const std::string overloaded = result.rig_lateness.value("overloaded", std::string());
    if (overloaded.empty()) return;
    for (const char* kept : {"interrupted", "harness_error", "topic_role_violation"}) {
        if (result.error_kind == kept) return;
    }
    std::string error = "the rig was overloaded: " + overloaded +
                        "; the run cannot judge the controller (its metrics are reported, not judged)";
    if (!result.error.empty()) error += "; the run also ended in " + result.error_kind + ": " + result.error;
    result.error_kind = std::string(to_string(FailureKind::rig_overloaded));
    result.error = std::move(error);
}

}  // namespace

namespace {

// Seed 001's vision: every ROI's true and measured cover, and the frames the
// run kept for the report (meta vision_report_frames, PNGs beside the trace).
void add_vision_figures(const RecordedTrace& trace, CaseFigures& figures) {
    const auto views = trace.samples.find(topics::kCameraViewTruth);
    if (views == trace.samples.end()) return;
    std::map<std::pair<int, long>, std::map<int, double>> measured;  // (camera, frame) -> nozzle -> D
    if (const auto reports = trace.samples.find(topics::kVisionReport); reports != trace.samples.end()) {
        for (const RecordedSample& s : reports->second) {
            std::map<int, double>& by_nozzle =
                measured[{s.json.at("camera").get<int>(), s.json.at("frame_number").get<long>()}];
            for (const nlohmann::json& n : s.json.at("nozzles")) {
                if (n.at("measured").get<bool>()) by_nozzle.emplace(n.at("nozzle").get<int>(), n.at("density").get<double>());
            }
        }
    }
    std::map<std::pair<int, long>, std::vector<VisionRoiSample>> by_frame;
    for (const RecordedSample& s : views->second) {
        const int camera = s.json.at("camera").get<int>();
        const long frame = s.json.at("frame_number").get<long>();
        const auto found = measured.find({camera, frame});
        for (const nlohmann::json& n : s.json.at("nozzles")) {
            VisionRoiSample roi;
            roi.camera = camera;
            roi.nozzle = n.at("nozzle").get<int>();
            roi.east_m = n.at("roi_centre_east_m").get<double>();
            roi.north_m = n.at("roi_centre_north_m").get<double>();
            roi.true_pct = 100.0 * n.at("density").get<double>();
            if (found != measured.end()) {
                if (const auto d = found->second.find(roi.nozzle); d != found->second.end()) roi.measured_pct = 100.0 * d->second;
            }
            figures.vision_rois.push_back(roi);
            by_frame[{camera, frame}].push_back(roi);
        }
    }
    const nlohmann::json kept = nlohmann::json::parse(meta_or(trace, "vision_report_frames", "[]"));
    for (const nlohmann::json& k : kept) {
        VisionFrameImage image;
        image.camera = k.at("camera").get<int>();
        image.frame_number = k.at("frame_number").get<long>();
        image.file = trace.file.parent_path() / k.at("file").get<std::string>();
        image.rois = by_frame[{image.camera, image.frame_number}];
        figures.vision_frames.push_back(std::move(image));
    }
}

}  // namespace

CaseRun judge_trace(const RecordedTrace& trace) {
    CaseRun run;
    CaseResult& result = run.result;
    CaseFigures& figures = run.figures;
    result.name = meta_or(trace, "case", trace.file.parent_path().filename().string());
    result.file = meta_or(trace, "case_file");
    result.mode = meta_or(trace, "mode", "lockstep");
    result.wiring = meta_or(trace, "wiring");
    result.trace_sha256 = meta_or(trace, "trace_sha256");
    result.trace_path = trace.file.string();
    try {
        result.seed = std::stoull(meta_or(trace, "seed", "0"));
        result.sim_seconds = ns_to_seconds(std::stoll(meta_or(trace, "end_ns", "0")));
    } catch (const std::exception&) {
        result.error_kind = "harness_error";
        result.error = "trace " + trace.file.string() + ": meta seed or end_ns is not a number";
    }
    // The rows must be those the run wrote: a trace edited afterwards is not judged as the run's.
    const std::string recorded_sha256 = meta_or(trace, "trace_sha256");
    if (!recorded_sha256.empty() && recorded_sha256 != trace.recomputed_sha256) {
        result.error_kind = "harness_error";
        result.error = "trace " + trace.file.string() + ": its rows give digest " + trace.recomputed_sha256 +
                       ", not the " + recorded_sha256 + " recorded when it was written (changed after the run?)";
    }
    const std::string outcome = meta_or(trace, "outcome", "running");
    if (outcome != "completed" && result.error.empty()) {
        result.error_kind = meta_or(trace, "error_kind", "interrupted");
        result.error = meta_or(trace, "error", "the run ended before its trace was finished (outcome: " + outcome + ")");
    }
    try {
        read_run_facts(trace, result, figures);
        const nlohmann::json judging = nlohmann::json::parse(meta_or(trace, "judging", "null"));
        const JudgingPlan plan = judging_plan_from_json(judging);
        result.limits = plan.limits;
        result.expected_error = plan.expect_error;
        result.expectation_set_aside = plan.expect_set_aside;
        figures.breakpoint_along_m = plan.breakpoint_along_m;
        // The trace says who touched what, whatever the run noticed live.
        if (result.error.empty()) {
            if (const auto violation = first_role_violation(trace)) {
                result.error_kind = "topic_role_violation";
                result.error = "node '" + violation->first + "': " + violation->second;
            }
        }

        apply_rig_overload(result);

        MetricSet metrics;
        const VehicleTrack track(vehicle_samples(trace));
        if (plan.judge_breakpoint) {
            const emulators::FieldFrame field(plan.field_origin_lat_deg, plan.field_origin_lon_deg,
                                              plan.field_origin_height_m, plan.field_heading_deg);
            metrics.merge(breakpoint_metrics(breakpoint_events(trace), track, field, plan.breakpoint_along_m));
        }
        if (plan.judge_flow) {
            const std::vector<HydraulicsSample> hydraulics = hydraulics_samples(trace);
            const std::vector<SectionCommand> commands = section_commands(trace);
            const std::vector<FlowReading> kf11 =
                kf11_readings(flow_meter_samples(trace), plan.kf11_pulses_per_l, plan.kf11_window_s);
            const FlowResult flow = flow_metrics(hydraulics, commands, kf11, plan.flow_window, plan.flow);
            metrics.merge(flow.metrics);
            figures.target_flow_l_min = plan.flow.target_l_min;
            if (flow.first_open_ns) {
                const std::optional<double> open_at_m = track.nozzle_line_along_m(*flow.first_open_ns);
                if (plan.judge_breakpoint && open_at_m) {
                    // Where the flow adjustment began, before the breakpoint (paper: 1.70 / 2.55 / 3.45 m).
                    metrics.values["flow_adjust_start_before_breakpoint_m"] = plan.breakpoint_along_m - *open_at_m;
                }
                add_flow_figure(trace, track, *flow.first_open_ns, plan.flow_window.to_ns, plan.breakpoint_along_m,
                                figures);
                if (open_at_m) figures.section_open_command_distance_m = *open_at_m - plan.breakpoint_along_m;
                figures.section_open_command_t_s = ns_to_seconds(*flow.first_open_ns);
            }
            metrics.merge(spray_timing_metrics(commands, hydraulics, trace.landing_edges));
        }
        if (plan.judge_fig11) {
            metrics.merge(fig11_metrics(hydraulics_samples(trace, /*with_pump_and_valve=*/true), plan.flow_window).metrics);
        }
        if (plan.judge_deposition) {
            const DepositionResult deposition = deposition_metrics(trace.dose, plan.deposition, plan.breakpoint_along_m);
            metrics.merge(deposition.metrics);
            add_dose_figure(trace.dose, deposition, plan.breakpoint_along_m, plan.deposition.cv_window_m, figures);
        }
        // Seed 001's boundary cases (harness/boundary_judge.h).
        if (plan.scenario == "boundary") {
            metrics.merge(boundary_trace_metrics(trace, boundary_judging_plan_from_json(judging.at("boundary"))));
            add_vision_figures(trace, figures);
        }
        metrics.merge(gnss_wire_fault_metrics(trace));  // cases with gnss.wire_faults only
        result.metrics = metrics.values;
        result.not_measured = metrics.not_measured;

        VerdictInputs inputs{metrics.values, metrics.not_measured, plan.limits, plan.expect_fail, plan.expect_error,
                             result.error_kind, result.error};
        const CaseVerdict verdict = judge_case(inputs);
        result.failures = verdict.failures;
        result.expected_failure = verdict.expected_failure;
        result.passed = verdict.passed;
    } catch (const std::exception& error) {
        // A trace read_trace accepted but whose content does not hold together.
        if (result.error.empty()) {
            result.error_kind = "harness_error";
            result.error = std::string("judging ") + trace.file.string() + ": " + error.what();
        }
        result.failures = {"error: " + result.error_kind + ": " + result.error};
        result.passed = false;
    }
    return run;
}

}  // namespace rig::harness
