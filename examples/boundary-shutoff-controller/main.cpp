// An example of a team's own seed-001 controller (Yang et al. 2022: per-nozzle
// shut-off at a target area's boundary), written against the installed SDK
// only (rig::node, rig::nmea, rig/papers/seed001.h) and the contract
// (docs/controller-contract.md, docs/seed001-boundary.md "Writing a seed-001
// controller"). On every RMC fix it puts each nozzle on the ground by Eq. 18
// (the boom centre Y1(H) ahead of the antenna, H from the L4 laser) and Eq. 19
// (turned by the RMC course), shuts off every nozzle outside the target area
// and the whole boom when its centre is outside (Sec. 4.2), and gives each
// nozzle that may spray the duty of Eq. 14's level for its area's density at
// the RMC speed (Eq. 12-14). It does not use the cameras (Sec. 2's vision
// half): a job that has them is run with the areas' densities.
//
// Arguments (the rig's contract): --domain N --node-name NAME --config FILE
// --state-dir DIR --job FILE [--clock lockstep|realtime]. It has no settings
// of its own: --config must be an empty mapping; everything about the field
// and the sprayer comes from the job.
#include <yaml-cpp/yaml.h>

#include <charconv>
#include <cmath>
#include <cstdint>
#include <iostream>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "actuatorPubSubTypes.h"
#include "devicePubSubTypes.h"
#include "idl/topics.h"
#include "rig/nmea/nmea_parser.h"
#include "rig/papers/seed001.h"
#include "rig/runtime/dds_context.h"
#include "rig/runtime/follower.h"
#include "rig/runtime/node.h"

namespace {

namespace paper = rig::papers::seed001;
constexpr double kPi = 3.14159265358979323846;

// ------------------------------------------------------------------ the job

// A key of the job file, read with the file and line in every error.
class JobFile {
public:
    explicit JobFile(std::string path) : path_(std::move(path)) {
        try {
            root_ = YAML::LoadFile(path_);
        } catch (const YAML::Exception& error) {
            throw std::runtime_error(path_ + ": not a YAML job file: " + error.what());
        }
    }
    const YAML::Node& root() const { return root_; }

    YAML::Node child(const YAML::Node& parent, const std::string& key, const std::string& where) const {
        if (!parent.IsMap()) throw std::runtime_error(at(parent) + (where.empty() ? "the job" : where) + ": not a mapping");
        const YAML::Node node = parent[key];
        if (!node) throw std::runtime_error(at(parent) + where + key + ": missing");
        return node;
    }
    double number(const YAML::Node& parent, const std::string& key, const std::string& where) const {
        const YAML::Node node = child(parent, key, where);
        double value = 0.0;
        if (!node.IsScalar() || !YAML::convert<double>::decode(node, value) || !std::isfinite(value)) {
            throw std::runtime_error(at(node) + where + key + ": not a number");
        }
        return value;
    }
    std::string text(const YAML::Node& parent, const std::string& key, const std::string& where) const {
        const YAML::Node node = child(parent, key, where);
        if (!node.IsScalar()) throw std::runtime_error(at(node) + where + key + ": not a text");
        return node.Scalar();
    }
    std::string at(const YAML::Node& node) const {
        return path_ + ":" + std::to_string(node.Mark().line + 1) + ": ";
    }

private:
    std::string path_;
    YAML::Node root_;
};

struct LatLon {
    double lat_deg = 0.0;
    double lon_deg = 0.0;
};

struct Area {
    std::string name;
    double density = 0.0;        // plant cover D, 0..1 (Eq. 17)
    std::vector<LatLon> corners;
};

struct Job {
    LatLon origin;
    double origin_height_m = 0.0;
    std::vector<Area> areas;
    int nozzle_count = 0;
    double nozzle_spacing_m = 0.0;
    double rod_length_m = 0.0;            // Eq. 18's I
    double hinge_height_m = 0.0;          // Hp
    double antenna_to_o_m = 0.0;          // M
    double hinge_to_boom_centre_m = 0.0;  // L
    double laser_mount_offset_m = 0.0;    // the laser reads D = H + this
    double pwm_frequency_hz = 0.0;
    bool cameras = false;
};

Job load_job(const std::string& path) {
    const JobFile file(path);
    const YAML::Node& root = file.root();
    Job job;
    const YAML::Node origin = file.child(file.child(root, "field", ""), "origin", "field.");
    job.origin = LatLon{file.number(origin, "lat_deg", "field.origin."), file.number(origin, "lon_deg", "field.origin.")};
    job.origin_height_m = file.number(origin, "height_m", "field.origin.");
    const YAML::Node areas = file.child(root, "areas", "");
    if (!areas.IsSequence() || areas.size() == 0) throw std::runtime_error(file.at(areas) + "areas: at least one target area");
    for (std::size_t i = 0; i < areas.size(); ++i) {
        const std::string where = "areas[" + std::to_string(i) + "].";
        Area area;
        area.name = file.text(areas[i], "name", where);
        area.density = file.number(areas[i], "density", where);
        if (area.density < 0.0 || area.density > 1.0) {
            throw std::runtime_error(file.at(areas[i]) + where + "density: must be in [0, 1]");
        }
        const YAML::Node corners = file.child(areas[i], "corners", where);
        if (!corners.IsSequence() || corners.size() < 3) {
            throw std::runtime_error(file.at(corners) + where + "corners: at least 3");
        }
        for (std::size_t c = 0; c < corners.size(); ++c) {
            const std::string corner = where + "corners[" + std::to_string(c) + "].";
            area.corners.push_back(LatLon{file.number(corners[c], "lat_deg", corner), file.number(corners[c], "lon_deg", corner)});
        }
        job.areas.push_back(std::move(area));
    }
    const YAML::Node sprayer = file.child(root, "sprayer", "");
    const double nozzles = file.number(sprayer, "nozzle_count", "sprayer.");
    // actuator/nozzle_pwm/duty carries at most 32 duties.
    if (nozzles != std::floor(nozzles) || nozzles < 1 || nozzles > 32) {
        throw std::runtime_error(file.at(sprayer) + "sprayer.nozzle_count: a whole number in [1, 32]");
    }
    job.nozzle_count = static_cast<int>(nozzles);
    job.nozzle_spacing_m = file.number(sprayer, "nozzle_spacing_m", "sprayer.");
    if (job.nozzle_spacing_m <= 0.0) throw std::runtime_error(file.at(sprayer) + "sprayer.nozzle_spacing_m: must be > 0");
    const YAML::Node lift = file.child(sprayer, "lift", "sprayer.");
    job.rod_length_m = file.number(lift, "rod_length_m", "sprayer.lift.");
    job.hinge_height_m = file.number(lift, "hinge_height_m", "sprayer.lift.");
    job.antenna_to_o_m = file.number(lift, "antenna_to_o_m", "sprayer.lift.");
    job.hinge_to_boom_centre_m = file.number(lift, "hinge_to_boom_centre_m", "sprayer.lift.");
    if (job.rod_length_m <= 0.0) throw std::runtime_error(file.at(lift) + "sprayer.lift.rod_length_m: must be > 0");
    job.laser_mount_offset_m = file.number(file.child(root, "laser", ""), "mount_offset_m", "laser.");
    job.pwm_frequency_hz = file.number(file.child(root, "valves", ""), "frequency_hz", "valves.");
    if (job.pwm_frequency_hz <= 0.0) throw std::runtime_error(file.at(root) + "valves.frequency_hz: must be > 0");
    job.cameras = static_cast<bool>(root["cameras"]);
    return job;
}

// ------------------------------------------------------------------ geometry

struct EastNorth {
    double east_m = 0.0;
    double north_m = 0.0;
};

// The field's tangent plane at the job's origin, to first order: metres per
// degree from the WGS84 radii of curvature there. Over the few tens of metres
// of a case the second-order terms stay below a millimetre, and true north is
// grid north to within microradians, so the RMC course turns the boom here as
// it is (no UTM grid convergence to ignore).
class FieldPlane {
public:
    FieldPlane(LatLon origin, double height_m) : origin_(origin) {
        constexpr double a = 6378137.0;                  // WGS84 semi-major axis, m
        constexpr double f = 1.0 / 298.257223563;        // WGS84 flattening
        const double e2 = f * (2.0 - f);
        const double s = std::sin(origin.lat_deg * kPi / 180.0);
        const double w = std::sqrt(1.0 - e2 * s * s);
        const double prime_vertical_m = a / w;           // N
        const double meridian_m = a * (1.0 - e2) / (w * w * w);  // M
        m_per_deg_north_ = (meridian_m + height_m) * kPi / 180.0;
        m_per_deg_east_ = (prime_vertical_m + height_m) * std::cos(origin.lat_deg * kPi / 180.0) * kPi / 180.0;
    }
    EastNorth to_plane(LatLon p) const {
        double dlon = p.lon_deg - origin_.lon_deg;
        if (dlon > 180.0) dlon -= 360.0;
        if (dlon < -180.0) dlon += 360.0;
        return {dlon * m_per_deg_east_, (p.lat_deg - origin_.lat_deg) * m_per_deg_north_};
    }

private:
    LatLon origin_;
    double m_per_deg_north_ = 0.0;
    double m_per_deg_east_ = 0.0;
};

// Crossing-number test: is `p` inside the polygon `corners` (in order around it)?
bool inside(const std::vector<EastNorth>& corners, EastNorth p) {
    bool in = false;
    for (std::size_t i = 0, j = corners.size() - 1; i < corners.size(); j = i++) {
        const EastNorth& a = corners[i];
        const EastNorth& b = corners[j];
        if ((a.north_m > p.north_m) != (b.north_m > p.north_m) &&
            p.east_m < (b.east_m - a.east_m) * (p.north_m - a.north_m) / (b.north_m - a.north_m) + a.east_m) {
            in = !in;
        }
    }
    return in;
}

// ------------------------------------------------------------------ the paper's equations

// Eq. 18: the boom centre's distance ahead of the antenna at boom height H,
// Y1 = sqrt(I^2 - (Hp - H)^2) - (M - L). nullopt where the rods cannot be.
std::optional<double> eq18_boom_ahead_m(const Job& job, double boom_height_m) {
    const double drop_m = job.hinge_height_m - boom_height_m;
    if (!(std::abs(drop_m) <= job.rod_length_m)) return std::nullopt;
    return std::sqrt(job.rod_length_m * job.rod_length_m - drop_m * drop_m) - (job.antenna_to_o_m - job.hinge_to_boom_centre_m);
}

// Eq. 19: a body point x right and y ahead of the antenna, turned by the
// course b (clockwise from north): east = x cos b + y sin b, north = -x sin b + y cos b.
EastNorth eq19_on_ground(EastNorth antenna, double course_deg, double right_m, double ahead_m) {
    const double b = course_deg * kPi / 180.0;
    return {antenna.east_m + right_m * std::cos(b) + ahead_m * std::sin(b),
            antenna.north_m - right_m * std::sin(b) + ahead_m * std::cos(b)};
}

// Eq. 12-14 and Sec. 3.2.2's levels: the duty, %, of a nozzle over cover D at speed v.
double eq14_level_duty_pct(double density, double speed_m_s) {
    const double flow_l_min = paper::kEq12CoefficientLMinPerMS * density * speed_m_s / paper::kEq14MaxCover;  // Eq. 12
    const double duty_pct = (flow_l_min - paper::kEq13InterceptLMin) / paper::kEq13SlopeLMinPerPct;         // Eq. 13 for s
    if (duty_pct <= paper::kLevel0MaxPct) return 0.0;
    if (duty_pct <= paper::kLevel1MaxPct) return paper::kLevel1DutyPct;
    return paper::kLevel2DutyPct;
}

// "D=0.503m" (CR LF on the wire): the distance, m; nullopt for anything else
// ("E=<code>", a broken line).
std::optional<double> laser_distance_m(std::string_view line) {
    while (!line.empty() && (line.back() == '\n' || line.back() == '\r')) line.remove_suffix(1);
    if (line.size() < 4 || line.substr(0, 2) != "D=" || line.back() != 'm') return std::nullopt;
    const std::string_view digits = line.substr(2, line.size() - 3);
    double value = 0.0;
    const auto [end, error] = std::from_chars(digits.data(), digits.data() + digits.size(), value);
    if (error != std::errc{} || end != digits.data() + digits.size() || !std::isfinite(value)) return std::nullopt;
    return value;
}

// ------------------------------------------------------------------ the node

// Below this speed the RMC course is noise (the receiver blanks it near
// standstill): the last one is held.
constexpr double kCourseHoldSpeedMS = 0.2;
// No valid fix for this long: every nozzle off (five missed 10 Hz epochs).
constexpr rig::TimeNs kFixTimeoutNs = 500'000'000;

class BoundaryShutoffController final : public rig::Node {
public:
    BoundaryShutoffController(std::string name, Job job)
        : name_(std::move(name)), job_(std::move(job)), plane_(job_.origin, job_.origin_height_m),
          duty_pct_(static_cast<std::size_t>(job_.nozzle_count), 0.0) {
        for (const Area& area : job_.areas) {
            std::vector<EastNorth> corners;
            for (const LatLon& corner : area.corners) corners.push_back(plane_.to_plane(corner));
            areas_.push_back(std::move(corners));
        }
    }
    const std::string& name() const override { return name_; }

    void configure(rig::DdsContext& dds) override {
        nmea_ = std::make_unique<rig::Reader<rig::msg::NmeaSentence>>(dds, rig::topics::kGnssNmea);
        laser_ = std::make_unique<rig::Reader<rig::msg::SerialLine>>(dds, rig::topics::kLaserHeightSerial);
        pwm_ = std::make_unique<rig::Writer<rig::msg::NozzlePwm>>(dds, rig::topics::kNozzlePwm);
    }
    bool has_unread_input() const override { return nmea_->has_unread() || laser_->has_unread(); }

    rig::TimeNs step(rig::TimeNs now_ns) override {
        // The laser first: a fix at this instant is placed with the height measured with it.
        for (const auto& line : laser_->take_all()) on_laser_line(line.text().to_string());
        for (const auto& sentence : nmea_->take_all()) on_sentence(sentence.sentence().to_string(), now_ns);
        if (fix_ && now_ns >= fix_->read_ns + kFixTimeoutNs) fix_.reset();
        decide();
        if (!published_ || duty_pct_ != published_pct_) {
            rig::msg::NozzlePwm pwm;
            pwm.frequency_hz(job_.pwm_frequency_hz);
            pwm.duty_pct(duty_pct_);
            pwm_->publish(pwm);
            published_pct_ = duty_pct_;
            published_ = true;
        }
        return fix_ ? fix_->read_ns + kFixTimeoutNs : rig::kNever;
    }

private:
    struct Fix {
        EastNorth antenna;
        double speed_m_s = 0.0;
        rig::TimeNs read_ns = 0;
    };

    void on_laser_line(const std::string& line) {
        const std::optional<double> distance_m = laser_distance_m(line);
        if (!distance_m) return;  // an error line or noise: the last height holds
        const double height_m = *distance_m - job_.laser_mount_offset_m;
        // Where the lift cannot be (the beam hit the crop): the last height holds.
        if (eq18_boom_ahead_m(job_, height_m)) boom_height_m_ = height_m;
    }

    void on_sentence(const std::string& line, rig::TimeNs now_ns) {
        const rig::nmea::ParseResult parsed = rig::nmea::parse_sentence(line);
        if (!parsed.ok()) return;
        const auto* rmc = std::get_if<rig::nmea::RmcData>(&parsed.sentence->data);
        if (rmc == nullptr) return;
        if (rmc->status != rig::nmea::DataStatus::valid || !rmc->position) {
            fix_.reset();  // the receiver has no solution: nowhere to spray
            return;
        }
        Fix fix;
        fix.antenna = plane_.to_plane(LatLon{rmc->position->lat_deg, rmc->position->lon_deg});
        fix.speed_m_s = rmc->speed_m_s.value_or(0.0);
        fix.read_ns = now_ns;
        if (rmc->course_true_deg && fix.speed_m_s >= kCourseHoldSpeedMS) course_deg_ = *rmc->course_true_deg;
        fix_ = fix;
    }

    // The area a ground point is in, or -1.
    int area_of(EastNorth p) const {
        for (std::size_t i = 0; i < areas_.size(); ++i) {
            if (inside(areas_[i], p)) return static_cast<int>(i);
        }
        return -1;
    }

    void decide() {
        duty_pct_.assign(duty_pct_.size(), 0.0);
        // Without a fix, a course and a boom height nothing can be placed: all off.
        if (!fix_ || !course_deg_ || !boom_height_m_) return;
        const double ahead_m = *eq18_boom_ahead_m(job_, *boom_height_m_);
        // Sec. 4.2, environment 2: the boom centre outside every area shuts the whole boom.
        if (area_of(eq19_on_ground(fix_->antenna, *course_deg_, 0.0, ahead_m)) < 0) return;
        for (int i = 0; i < job_.nozzle_count; ++i) {
            // Nozzle 0 leftmost facing the travel, the boom centred on the antenna's line.
            const double right_m = (i - 0.5 * (job_.nozzle_count - 1)) * job_.nozzle_spacing_m;
            const int area = area_of(eq19_on_ground(fix_->antenna, *course_deg_, right_m, ahead_m));
            // Environment 1: a nozzle outside every area is off.
            if (area >= 0) {
                duty_pct_[static_cast<std::size_t>(i)] =
                    eq14_level_duty_pct(job_.areas[static_cast<std::size_t>(area)].density, fix_->speed_m_s);
            }
        }
    }

    std::string name_;
    Job job_;
    FieldPlane plane_;
    std::vector<std::vector<EastNorth>> areas_;
    std::unique_ptr<rig::Reader<rig::msg::NmeaSentence>> nmea_;
    std::unique_ptr<rig::Reader<rig::msg::SerialLine>> laser_;
    std::unique_ptr<rig::Writer<rig::msg::NozzlePwm>> pwm_;
    std::optional<Fix> fix_;
    std::optional<double> course_deg_;
    std::optional<double> boom_height_m_;
    std::vector<double> duty_pct_;
    std::vector<double> published_pct_;
    bool published_ = false;
};

// This controller has no settings: its --config (the case's `controller:`
// section without `command`) must be an empty mapping.
void check_no_settings(const std::string& path) {
    YAML::Node config;
    try {
        config = YAML::LoadFile(path);
    } catch (const YAML::Exception& error) {
        throw std::runtime_error(path + ": not a YAML file: " + error.what());
    }
    if (!config.IsMap() && !config.IsNull()) throw std::runtime_error(path + ": the controller section must be a mapping");
    for (const auto& entry : config) {
        throw std::runtime_error(path + ":" + std::to_string(entry.first.Mark().line + 1) + ": " +
                                 entry.first.Scalar() +
                                 ": this controller has no settings (the field and the sprayer come from --job)");
    }
}

}  // namespace

int main(int argc, char** argv) {
    std::optional<std::uint32_t> domain;
    std::string node_name = "controller";
    std::string config;
    std::string job_file;
    std::string clock_mode = "lockstep";
    try {
        for (int i = 1; i + 1 < argc; i += 2) {
            const std::string key = argv[i];
            const std::string value = argv[i + 1];
            if (key == "--domain") {
                std::uint32_t id = 0;
                const auto [end, error] = std::from_chars(value.data(), value.data() + value.size(), id);
                if (error != std::errc{} || end != value.data() + value.size()) {
                    throw std::runtime_error("--domain: not a domain id: '" + value + "'");
                }
                domain = id;
            } else if (key == "--node-name") {
                node_name = value;
            } else if (key == "--config") {
                config = value;
            } else if (key == "--job") {
                job_file = value;
            } else if (key == "--clock") {
                clock_mode = value;
            }
            // --state-dir: this controller keeps no state between runs.
        }
        if (!domain || config.empty()) throw std::runtime_error("--domain N and --config FILE are required");
        if (job_file.empty()) throw std::runtime_error("no --job FILE: this controller runs seed-001 (system: boundary) cases");
        check_no_settings(config);
        Job job = load_job(job_file);
        if (job.cameras) std::cerr << node_name << ": the job has cameras; this controller sprays by the areas' densities\n";
        rig::FollowerStartup startup;
        startup.domain_id = *domain;
        startup.clock = rig::clock_mode_from(clock_mode);
        startup.options.node_name = node_name;
        // On the wall clock this example stays at the scheduler's default
        // (without this line run_follower asks for SCHED_FIFO 40 and locked memory).
        startup.realtime_priority = std::nullopt;
        // The node is made once the DDS context exists, and destroyed before it.
        return rig::run_follower(startup, [&] { return std::make_unique<BoundaryShutoffController>(node_name, std::move(job)); });
    } catch (const std::exception& error) {
        std::cerr << node_name << ": " << error.what() << "\n";
        return 2;
    }
}
