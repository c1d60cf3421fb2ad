// docs/modbus-register-map.md is what a team wires a board from: every number
// of its "Scalings" tables and of its "External boards" key table must be the
// one the code uses (the emulators' case defaults, the reference controller's
// calibration, the board timeouts). A constant changed in code without the
// page fails here, naming both.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "controller/controller_config.h"
#include "controller/valve_calibration.h"
#include "harness/spec/board_spec.h"
#include "harness/spec/case_spec.h"
#include "harness/systems/breakpoint/breakpoint_case.h"
#include "harness/systems/systems.h"
#include "rig/runtime/io_image.h"

namespace {

// Table rows of the page: cells between '|', trimmed, backticks removed.
std::vector<std::vector<std::string>> table_rows(const std::string& text) {
    std::vector<std::vector<std::string>> rows;
    std::istringstream lines(text);
    for (std::string line; std::getline(lines, line);) {
        if (line.rfind("| ", 0) != 0) continue;
        std::vector<std::string> cells;
        std::istringstream cells_in(line.substr(1));
        for (std::string cell; std::getline(cells_in, cell, '|');) {
            std::string clean;
            for (char c : cell) {
                if (c != '`') clean += c;
            }
            const auto first = clean.find_first_not_of(' ');
            const auto last = clean.find_last_not_of(' ');
            cells.push_back(first == std::string::npos ? "" : clean.substr(first, last - first + 1));
        }
        rows.push_back(cells);
    }
    return rows;
}

std::string read_page() {
    std::ifstream in(RIG_SOURCE_DIR "/docs/modbus-register-map.md");
    std::stringstream text;
    text << in.rdbuf();
    return text.str();
}

// The second cell of the page's row named `name`; a failure, and "", when the page has no such row.
std::string documented_text(const std::vector<std::vector<std::string>>& rows, const std::string& name) {
    for (const auto& row : rows) {
        if (row.size() >= 2 && row[0] == name) return row[1];
    }
    ADD_FAILURE() << "docs/modbus-register-map.md has no row '" << name << "'";
    return "";
}

// The page's number for a named row (first word of its second cell); NaN when absent.
double documented(const std::vector<std::vector<std::string>>& rows, const std::string& name) {
    const std::string text = documented_text(rows, name);
    return text.empty() ? std::nan("") : std::stod(text);
}

// Equal to the shown precision: relative 1e-4 (the page rounds derived values to 4 significant digits).
void expect_documented(const std::vector<std::vector<std::string>>& rows, const std::string& name, double code_value) {
    const double page = documented(rows, name);
    EXPECT_NEAR(page, code_value, std::abs(code_value) * 1e-4) << name << ": page says " << page << ", code " << code_value;
}

}  // namespace

TEST(RegisterMapDoc, EveryScalingIsTheCodesConstant) {
    const auto rows = table_rows(read_page());
    const rig::harness::BreakpointSections defaults;
    const rig::controller::ControllerConfig controller;
    expect_documented(rows, "adc_full_scale_counts", rig::io::kAdcFullScale);
    expect_documented(rows, "adc_reference_v", rig::io::kAdcReferenceV);
    expect_documented(rows, "pump_flow_full_scale_m3_h", defaults.pump_sensor.full_scale_m3_h);
    // The emulator and the reference controller agree on it, so the page can give one number.
    EXPECT_EQ(controller.pump_sensor_full_scale_m3_h, defaults.pump_sensor.full_scale_m3_h);
    EXPECT_EQ(controller.pump_sensor_span_v, rig::io::kAdcReferenceV);
    expect_documented(rows, "pump_flow_l_min_per_count",
                      defaults.pump_sensor.full_scale_m3_h * 1000.0 / 60.0 / rig::io::kAdcFullScale);
    expect_documented(rows, "boom_height_range_m", defaults.boom_height_sensor.range_m);
    EXPECT_EQ(controller.boom_height_range_m, defaults.boom_height_sensor.range_m);
    expect_documented(rows, "boom_height_m_per_count", defaults.boom_height_sensor.range_m / rig::io::kAdcFullScale);
    expect_documented(rows, "main_flow_pulses_per_l", defaults.flow_meter.pulses_per_l);
    EXPECT_EQ(controller.flow_meter_pulses_per_l, defaults.flow_meter.pulses_per_l);
    expect_documented(rows, "wheel_encoder_pulses_per_rev", defaults.encoder.pulses_per_rev);
    expect_documented(rows, "wheel_diameter_m", defaults.encoder.wheel_diameter_m);
    expect_documented(rows, "capture_timer_hz", rig::io::kCaptureTimerHz);
    expect_documented(rows, "capture_timer_wrap_s", 4294967296.0 / rig::io::kCaptureTimerHz);
    expect_documented(rows, "valve_travel_s", defaults.hydraulics.valve_travel_s);
    expect_documented(rows, "valve_motor_start_delay_s", defaults.hydraulics.valve_motor_start_delay_s);
    expect_documented(rows, "valve_backlash_pct", defaults.hydraulics.valve_backlash_pct);
}

TEST(RegisterMapDoc, TheValveCalibrationIsTheReferenceControllers) {
    const auto rows = table_rows(read_page());
    std::map<double, std::pair<double, double>> page;  // opening -> (slope, intercept)
    bool in_table = false;
    for (const auto& row : rows) {
        if (row.size() >= 3 && row[0] == "opening %") {
            in_table = true;
            continue;
        }
        if (!in_table || row.size() < 3 || row[0].empty() || row[0][0] == '-') continue;
        try {
            page[std::stod(row[0])] = {std::stod(row[1]), std::stod(row[2])};
        } catch (const std::exception&) {
            in_table = false;  // the next table
        }
    }
    const auto code = rig::controller::default_calibration();
    ASSERT_EQ(page.size(), code.size()) << "calibration rows on the page vs in controller/valve_calibration.cpp";
    for (const auto& line : code) {
        ASSERT_TRUE(page.contains(line.opening_pct)) << line.opening_pct;
        EXPECT_EQ(page[line.opening_pct].first, line.slope) << line.opening_pct;
        EXPECT_EQ(page[line.opening_pct].second, line.intercept_l_min) << line.opening_pct;
    }
}

TEST(RegisterMapDoc, TheBoardKeysDefaultsAreTheCodes) {
    const auto rows = table_rows(read_page());
    const rig::harness::BoardSpec board;
    expect_documented(rows, "board.attach_timeout_s", board.attach_timeout_s);
    expect_documented(rows, "board.silence_timeout_s", board.silence_timeout_s);
    expect_documented(rows, "board.failsafe_timeout_s", board.failsafe_timeout_s);
    EXPECT_EQ(documented_text(rows, "board.failsafe"), std::string(rig::modbus::to_string(board.failsafe)));
}
