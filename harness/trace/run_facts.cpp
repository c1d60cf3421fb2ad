#include "harness/trace/run_facts.h"

#include <set>
#include <stdexcept>

namespace rig::harness {

namespace {

// The keys this file names; any other key of meta `run` is the system's.
const std::set<std::string>& common_keys() {
    static const std::set<std::string> keys = {
        "wall_seconds",          "controller_mode",   "in_process_refused", "startup_wall_seconds", "instants",
        "rounds",                "stepping_wall_seconds", "realtime_scheduling", "cpu_placement", "emission_jitter",
        "lateness",              "board_io"};
    return keys;
}

}  // namespace

nlohmann::json to_json(const RunFacts& facts) {
    nlohmann::json jitter = nlohmann::json::array();
    for (const EmissionJitter& device : facts.emission_jitter) {
        jitter.push_back({{"device", device.device},
                          {"samples", device.samples},
                          {"p50_ms", device.p50_ms},
                          {"p99_ms", device.p99_ms},
                          {"max_ms", device.max_ms},
                          {"step_p99_ms", device.step_p99_ms},
                          {"step_max_ms", device.step_max_ms}});
    }
    nlohmann::json run = {{"wall_seconds", facts.wall_seconds},
                          {"controller_mode", facts.controller_mode},
                          {"in_process_refused", facts.in_process_refused},
                          {"startup_wall_seconds", facts.startup_wall_seconds},
                          {"instants", facts.instants},
                          {"rounds", facts.rounds},
                          {"stepping_wall_seconds", facts.stepping_wall_seconds},
                          {"realtime_scheduling", facts.realtime_scheduling},
                          {"cpu_placement", facts.cpu_placement},
                          {"emission_jitter", std::move(jitter)}};
    if (!facts.board_io.is_null()) run["board_io"] = facts.board_io;
    if (!facts.lateness.is_null()) run["lateness"] = facts.lateness;
    if (facts.system.is_object()) {
        for (const auto& [key, value] : facts.system.items()) {
            if (!common_keys().count(key)) run[key] = value;
        }
    }
    return run;
}

RunFacts run_facts_from_json(const nlohmann::json& run) {
    RunFacts facts;
    try {
        facts.wall_seconds = run.value("wall_seconds", 0.0);
        facts.startup_wall_seconds = run.value("startup_wall_seconds", 0.0);
        facts.instants = run.value("instants", std::uint64_t{0});
        facts.rounds = run.value("rounds", std::uint64_t{0});
        facts.stepping_wall_seconds = run.value("stepping_wall_seconds", 0.0);
        facts.controller_mode = run.value("controller_mode", std::string());
        facts.in_process_refused = run.value("in_process_refused", std::string());
        facts.realtime_scheduling = run.value("realtime_scheduling", std::string());
        facts.cpu_placement = run.value("cpu_placement", std::string());
        if (run.contains("board_io")) facts.board_io = run.at("board_io");
        if (run.contains("lateness")) facts.lateness = run.at("lateness");
        if (run.contains("emission_jitter")) {
            for (const nlohmann::json& device : run.at("emission_jitter")) {
                facts.emission_jitter.push_back(EmissionJitter{
                    device.at("device").get<std::string>(), device.at("samples").get<std::size_t>(),
                    device.at("p50_ms").get<double>(), device.at("p99_ms").get<double>(), device.at("max_ms").get<double>(),
                    device.at("step_p99_ms").get<double>(), device.at("step_max_ms").get<double>()});
            }
        }
        for (const auto& [key, value] : run.items()) {
            if (!common_keys().count(key)) facts.system[key] = value;
        }
    } catch (const nlohmann::json::exception& error) {
        throw std::runtime_error(std::string("meta run: ") + error.what());
    }
    return facts;
}

}  // namespace rig::harness
