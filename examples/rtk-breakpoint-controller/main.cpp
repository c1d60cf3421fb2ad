// An example of a team's own controller for the rig, written against the
// installed SDK only (rig::node, rig::nmea; docs/controller-contract.md): it
// identifies the breakpoint from the RTK fixes alone, as Table 4's RTK-only
// runs do. When the breakpoint button is pressed it stores where the nozzle
// line is (the antenna's fix moved back by the antenna-to-nozzle distance
// along the course); when it later drives over that point again it reports
// "reached". It reads the GNSS line and the button, and writes its breakpoint
// events; the rig judges it from the plant's truth like any controller.
//
// Arguments (the rig's contract): --domain N --node-name NAME --config FILE
// --state-dir DIR [--clock lockstep|realtime]. Its only setting, read from
// the config file: `antenna_to_nozzle_m: 1.63` (Eq. 6 at the paper's boom).
#include <cmath>
#include <cstdint>
#include <fstream>
#include <iostream>
#include <memory>
#include <optional>
#include <string>

#include "controllerPubSubTypes.h"
#include "devicePubSubTypes.h"
#include "idl/topics.h"
#include "rig/nmea/nmea_parser.h"
#include "rig/runtime/dds_context.h"
#include "rig/runtime/follower.h"
#include "rig/runtime/node.h"

namespace {

constexpr double kEarthRadiusM = 6371008.8;
constexpr double kPi = 3.14159265358979323846;

struct Fix {
    double lat_deg = 0.0;
    double lon_deg = 0.0;
};

// A point `distance_m` from `from` along `bearing_deg` (0 north, clockwise): a
// local flat-earth step, exact to well under a millimetre over a few metres.
Fix moved(const Fix& from, double bearing_deg, double distance_m) {
    const double bearing = bearing_deg * kPi / 180.0;
    const double north_m = distance_m * std::cos(bearing);
    const double east_m = distance_m * std::sin(bearing);
    return Fix{from.lat_deg + north_m / kEarthRadiusM * 180.0 / kPi,
               from.lon_deg + east_m / (kEarthRadiusM * std::cos(from.lat_deg * kPi / 180.0)) * 180.0 / kPi};
}

// How far `point` lies ahead of `from` along `bearing_deg`, in metres.
double ahead_m(const Fix& from, double bearing_deg, const Fix& point) {
    const double north_m = (point.lat_deg - from.lat_deg) * kPi / 180.0 * kEarthRadiusM;
    const double east_m = (point.lon_deg - from.lon_deg) * kPi / 180.0 * kEarthRadiusM * std::cos(from.lat_deg * kPi / 180.0);
    const double bearing = bearing_deg * kPi / 180.0;
    return north_m * std::cos(bearing) + east_m * std::sin(bearing);
}

class RtkBreakpointController final : public rig::Node {
public:
    RtkBreakpointController(std::string name, double antenna_to_nozzle_m)
        : name_(std::move(name)), antenna_to_nozzle_m_(antenna_to_nozzle_m) {}
    const std::string& name() const override { return name_; }

    void configure(rig::DdsContext& dds) override {
        nmea_ = std::make_unique<rig::Reader<rig::msg::NmeaSentence>>(dds, rig::topics::kGnssNmea);
        button_ = std::make_unique<rig::Reader<rig::msg::SwitchLevel>>(dds, rig::topics::kBreakpointButton);
        events_ = std::make_unique<rig::Writer<rig::msg::BreakpointEvent>>(dds, rig::topics::kBreakpointEvent);
    }
    bool has_unread_input() const override { return nmea_->has_unread() || button_->has_unread(); }

    rig::TimeNs step(rig::TimeNs now_ns) override {
        for (const auto& sentence : nmea_->take_all()) on_sentence(sentence.sentence().to_string(), now_ns);
        for (const auto& level : button_->take_all()) {
            if (level.closed() && !button_closed_) store(now_ns);
            button_closed_ = level.closed();
        }
        return rig::kNever;  // it only reacts to its inputs
    }

private:
    void on_sentence(const std::string& line, rig::TimeNs now_ns) {
        const rig::nmea::ParseResult parsed = rig::nmea::parse_sentence(line);
        if (!parsed.ok()) return;
        if (const auto* gga = std::get_if<rig::nmea::GgaData>(&parsed.sentence->data)) {
            if (gga->position && gga->fix_quality.value_or(0) > 0) {
                antenna_ = Fix{gga->position->lat_deg, gga->position->lon_deg};
            } else {
                antenna_.reset();
            }
        } else if (const auto* rmc = std::get_if<rig::nmea::RmcData>(&parsed.sentence->data)) {
            if (rmc->course_true_deg) course_deg_ = *rmc->course_true_deg;
            if (antenna_ && course_deg_) check_reached(now_ns);  // GGA then RMC: the epoch is complete
        }
    }

    void store(rig::TimeNs now_ns) {
        if (!antenna_ || !course_deg_) {
            std::cerr << name_ << ": button pressed without a fix and a course; ignored\n";
            return;
        }
        // The nozzle line is behind the antenna, along the course.
        breakpoint_ = moved(*antenna_, *course_deg_ + 180.0, antenna_to_nozzle_m_);
        armed_ = false;
        publish(rig::msg::BREAKPOINT_STORED, now_ns);
    }

    void check_reached(rig::TimeNs now_ns) {
        if (!breakpoint_) return;
        // Distance the nozzle line still has to go to the stored point.
        const double to_go_m = ahead_m(*antenna_, *course_deg_, *breakpoint_) + antenna_to_nozzle_m_;
        if (!armed_) {
            armed_ = to_go_m > 2.0;  // approaching it again, from well behind
            return;
        }
        if (to_go_m <= 0.0) {
            publish(rig::msg::BREAKPOINT_REACHED, now_ns);
            breakpoint_.reset();
        }
    }

    void publish(rig::msg::BreakpointEventKind kind, rig::TimeNs now_ns) {
        rig::msg::BreakpointEvent event;
        event.time_ns(now_ns);
        event.breakpoint_id(1);
        event.kind(kind);
        event.lat_deg(breakpoint_->lat_deg);
        event.lon_deg(breakpoint_->lon_deg);
        events_->publish(event);
    }

    std::string name_;
    double antenna_to_nozzle_m_;
    std::unique_ptr<rig::Reader<rig::msg::NmeaSentence>> nmea_;
    std::unique_ptr<rig::Reader<rig::msg::SwitchLevel>> button_;
    std::unique_ptr<rig::Writer<rig::msg::BreakpointEvent>> events_;
    std::optional<Fix> antenna_;
    std::optional<double> course_deg_;
    std::optional<Fix> breakpoint_;
    bool armed_ = false;
    bool button_closed_ = false;
};

// `key: value` from the config file (its one setting; anything else is ignored).
std::optional<double> setting(const std::string& file, const std::string& key) {
    std::ifstream in(file);
    for (std::string line; std::getline(in, line);) {
        if (line.rfind(key + ":", 0) == 0) return std::stod(line.substr(key.size() + 1));
    }
    return std::nullopt;
}

}  // namespace

int main(int argc, char** argv) {
    std::uint32_t domain = 0;
    std::string node_name = "controller";
    std::string config;
    std::string clock_mode = "lockstep";
    for (int i = 1; i + 1 < argc; i += 2) {
        const std::string key = argv[i];
        const std::string value = argv[i + 1];
        if (key == "--domain") domain = static_cast<std::uint32_t>(std::stoul(value));
        else if (key == "--node-name") node_name = value;
        else if (key == "--config") config = value;
        else if (key == "--clock") clock_mode = value;
        // --state-dir: this controller keeps no state between runs.
    }
    try {
        rig::FollowerStartup startup;
        startup.domain_id = domain;
        startup.clock = rig::clock_mode_from(clock_mode);
        startup.options.node_name = node_name;
        // On the wall clock this example stays at the scheduler's default.
        // Without this line run_follower asks for SCHED_FIFO 40 and locked
        // memory, as the rig's reference controllers do.
        startup.realtime_priority = std::nullopt;
        // The node is made once the DDS context exists, and destroyed before it.
        return rig::run_follower(startup, [&] {
            return std::make_unique<RtkBreakpointController>(node_name,
                                                             setting(config, "antenna_to_nozzle_m").value_or(1.63));
        });
    } catch (const std::exception& error) {
        std::cerr << node_name << ": " << error.what() << "\n";
        return 2;
    }
}
