// Seed 001's reference controller logic, positioning and boundary half
// (controller/boundary/): UTM zone, Eq. 14 levels, Eq. 18 and 19, the two
// shut-off rules of Sec. 4.2 on drives across an area's edge, the look-ahead
// option, hostile input, and the node's duty commands (DutyCommandDelay, with
// the TEST-ONLY late fault). RMC sentences are written with the emulators'
// encoder from positions in the field's local frame (the plant's truth), so the
// controller's UTM and grid-convergence handling are exercised for real.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <iterator>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "controller/boundary/boundary_controller.h"
#include "controller/boundary/boundary_equations.h"
#include "controller/boundary/duty_command_delay.h"
#include "controller/boundary/utm_area.h"
#include "emulators/field2d/local_frame.h"
#include "emulators/field2d/vec2.h"
#include "rig/nmea/nmea_encoder.h"
#include "rig/text/number_text.h"

namespace {

using namespace rig::controller::boundary;
using rig::seconds_to_ns;
using rig::field2d::LocalFrame;
using rig::field2d::Vec2;

// Wuzhi county, Henan (Sec. 5.1).
const LocalFrame kFrame(35.1, 113.3, 90.0);

// A 20 m x 20 m area, corners recorded counter-clockwise from the south-west one.
TargetAreaConfig square_area(double density = 0.5, const std::string& name = "plot") {
    TargetAreaConfig area;
    area.name = name;
    area.density = density;
    for (const Vec2 c : {Vec2{0, 0}, Vec2{20, 0}, Vec2{20, 20}, Vec2{0, 20}}) {
        const auto g = kFrame.to_geodetic(c);
        area.corners.push_back({g.lat_deg, g.lon_deg});
    }
    return area;
}

BoundaryControllerConfig square_config(double density = 0.5) {
    BoundaryControllerConfig c;
    c.areas.push_back(square_area(density));
    return c;
}

// The RMC a perfect receiver would send with its antenna at `antenna` (local frame).
std::string rmc_at(Vec2 antenna, double course_deg, double speed_m_s, bool valid = true) {
    rig::nmea::GnssFix fix;
    fix.year = 2020;
    fix.month = 11;
    fix.day = 15;
    fix.utc_seconds_of_day = 7200.0;
    const auto g = kFrame.to_geodetic(antenna, 1.7);
    fix.lat_deg = g.lat_deg;
    fix.lon_deg = g.lon_deg;
    fix.fix_quality = valid ? 4 : 0;
    fix.speed_m_s = speed_m_s;
    fix.course_deg = course_deg;
    return rig::nmea::encode_rmc("GP", fix);
}

// The antenna that puts the boom centre (1.0 m ahead at H = 0.5 m, Eq. 18) at `centre`.
Vec2 antenna_for_centre(Vec2 centre, double course_deg) { return centre - 1.0 * rig::field2d::forward_of(course_deg); }

std::vector<double> duties_at(BoundaryController& c, Vec2 antenna, double course_deg, double speed_m_s, double t_s) {
    c.on_nmea_sentence(rmc_at(antenna, course_deg, speed_m_s), seconds_to_ns(t_s));
    return c.duty_pct();
}

TEST(BoundaryController, UtmZone49NorthForWuzhi) {
    // Zone = floor((113.3 + 180) / 6) + 1 = 49; central meridian 111 E.
    const UtmProjection utm(square_config().areas);
    EXPECT_EQ(utm.zone(), 49);
    EXPECT_TRUE(utm.north());
    // Grid convergence there: about (113.3 - 111) x sin 35.1 deg = 1.3225 deg.
    double gamma = 0.0;
    const GridPoint p = utm.forward(35.1, 113.3, gamma);
    EXPECT_NEAR(gamma, 1.3225, 0.002);
    // 2.3 deg east of the central meridian: about 210 km east of the false easting 500 km.
    EXPECT_NEAR(p.x_m, 500000.0 + 209500.0, 1500.0);
}

TEST(BoundaryEquations, Eq14LevelsAndTheirBoundaries) {
    const BoundaryControllerConfig c = square_config();  // k 0.78, A 0.00375, b 0.296
    // D 0.5 at 1.5 m/s: q = 0.40968 x 0.5 x 1.5 / 0.78 = 0.30726 / 0.78 = 0.393923 L/min,
    // s = (0.393923 - 0.296) / 0.00375 = 26.113 % -> level 2, 100 %.
    EXPECT_NEAR(eq14_theoretical_duty_pct(c, 0.5, 1.5), 26.113, 0.001);
    EXPECT_EQ(spray_level(c, 26.113), 2);
    // D 0.3 (sparse, < 40 %) at 1.5 m/s: q = 0.184356 / 0.78 = 0.236354, s = -15.906 % -> level 1, 40 %.
    EXPECT_NEAR(eq14_theoretical_duty_pct(c, 0.3, 1.5), -15.906, 0.001);
    EXPECT_EQ(level_duty_pct(c, spray_level(c, -15.906)), 40.0);
    // D / k = 1 at 0.75 m/s: q = 0.30726, s = 3.0 % -> level 1 (level 2 unreachable at 0.75 m/s).
    EXPECT_NEAR(eq14_theoretical_duty_pct(c, 0.78, 0.75), 3.003, 0.001);
    EXPECT_EQ(spray_level(c, eq14_theoretical_duty_pct(c, 0.78, 0.75)), 1);
    // Standing: s = -0.296 / 0.00375 = -78.93 % -> level 0, valve closed.
    EXPECT_NEAR(eq14_theoretical_duty_pct(c, 0.5, 0.0), -78.933, 0.001);
    EXPECT_EQ(spray_level(c, -78.933), 0);
    // The thresholds themselves: -55 % is still level 0, 5 % still level 1.
    EXPECT_EQ(spray_level(c, -55.0), 0);
    EXPECT_EQ(spray_level(c, -54.99), 1);
    EXPECT_EQ(spray_level(c, 5.0), 1);
    EXPECT_EQ(spray_level(c, 5.01), 2);
    EXPECT_EQ(spray_level(c, NAN), 0);
    EXPECT_EQ(level_duty_pct(c, 0), 0.0);
    EXPECT_EQ(level_duty_pct(c, 2), 100.0);
    EXPECT_THROW(level_duty_pct(c, 3), std::invalid_argument);
}

TEST(BoundaryEquations, Eq18AndEq19) {
    const BoundaryControllerConfig c = square_config();
    // Eq. 18 at H = 0.5 m: sqrt(0.5^2 - 0.3^2) - (0.3 - 0.9) = 1.0 m; 0.9 m at H = 0.4 m.
    EXPECT_NEAR(eq18_boom_offset_m(c, 0.5), 1.0, 1e-12);
    EXPECT_NEAR(eq18_boom_offset_m(c, 0.4), 0.9, 1e-12);
    EXPECT_THROW(eq18_boom_offset_m(c, 1.4), std::invalid_argument);
    // Eq. 19: course 0, a nozzle 1.25 m right and 1.0 m ahead of the antenna at
    // (100, 200): (101.25, 201.0). Course 90 (east): right is south: (101.0, 198.75).
    const GridPoint north = eq19_body_to_grid({100.0, 200.0}, 0.0, 1.25, 1.0);
    EXPECT_DOUBLE_EQ(north.x_m, 101.25);
    EXPECT_DOUBLE_EQ(north.y_m, 201.0);
    const GridPoint east = eq19_body_to_grid({100.0, 200.0}, 90.0, 1.25, 1.0);
    EXPECT_DOUBLE_EQ(east.x_m, 101.0);
    EXPECT_DOUBLE_EQ(east.y_m, 198.75);
}

// The rows of the markdown table in `doc` whose header row starts with `header`:
// each row's cells, trimmed. Fails the test when the table is not there.
std::vector<std::vector<std::string>> doc_table(const std::string& doc, const std::string& header) {
    std::vector<std::vector<std::string>> rows;
    const std::size_t start = doc.find(header);
    EXPECT_NE(start, std::string::npos) << "no table headed '" << header << "'";
    if (start == std::string::npos) return rows;
    std::istringstream lines(doc.substr(start));
    std::string line;
    std::getline(lines, line);  // the header
    std::getline(lines, line);  // | --- | ... |
    while (std::getline(lines, line) && line.rfind("| ", 0) == 0) {
        std::vector<std::string> cells;
        std::istringstream cell_stream(line.substr(1));
        for (std::string cell; std::getline(cell_stream, cell, '|');) {
            const std::size_t first = cell.find_first_not_of(' ');
            const std::size_t last = cell.find_last_not_of(' ');
            cells.push_back(first == std::string::npos ? "" : cell.substr(first, last - first + 1));
        }
        rows.push_back(cells);
    }
    return rows;
}

std::string point_text(const GridPoint& p) {
    return "(" + rig::fixed_text(p.x_m, 4) + ", " + rig::fixed_text(p.y_m, 4) + ")";
}

// docs/seed001-boundary.md "Writing a seed-001 controller" works Eq. 18-19 and
// Eq. 12-14 through for a team writing its own controller: every number there
// is what the reference controller's equations give, at the printed precision.
TEST(BoundaryEquations, TheWorkedExamplesInTheDocsAreTheCodes) {
    std::ifstream file(RIG_SOURCE_DIR "/docs/seed001-boundary.md");
    ASSERT_TRUE(file) << "docs/seed001-boundary.md";
    const std::string doc((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
    const BoundaryControllerConfig c = square_config();

    const auto positions = doc_table(doc, "| H (m) | Y1 (m) | nozzle 0, b = 0 |");
    ASSERT_GE(positions.size(), 3u);  // more than one boom height
    for (const std::vector<std::string>& row : positions) {
        ASSERT_EQ(row.size(), 6u) << row.front();
        const double height_m = std::stod(row[0]);
        const double y1_m = eq18_boom_offset_m(c, height_m);
        EXPECT_EQ(row[1], rig::fixed_text(y1_m, 4)) << "Y1 at H = " << row[0];
        std::size_t column = 2;
        for (const double course_deg : {0.0, 30.0}) {
            for (const double right_m : {-1.25, 1.25}) {  // nozzles 0 and 5 of six 0.5 m apart
                EXPECT_EQ(row[column++], point_text(eq19_body_to_grid({0.0, 0.0}, course_deg, right_m, y1_m)))
                    << "H = " << row[0] << ", course " << course_deg << ", x = " << right_m;
            }
        }
    }

    const auto rates = doc_table(doc, "| D | v (m/s) | q (L/min) |");
    ASSERT_GE(rates.size(), 4u);
    std::set<int> levels;
    for (const std::vector<std::string>& row : rates) {
        ASSERT_EQ(row.size(), 6u) << row.front();
        const double density = std::stod(row[0]);
        const double speed_m_s = std::stod(row[1]);
        const double flow_l_min = c.eq12_coefficient_l_min_per_m_s * density * speed_m_s / c.k_max_cover;
        const double duty_pct = eq14_theoretical_duty_pct(c, density, speed_m_s);
        const int level = spray_level(c, duty_pct);
        levels.insert(level);
        const std::string where = "D = " + row[0] + ", v = " + row[1];
        EXPECT_EQ(row[2], rig::fixed_text(flow_l_min, 4)) << where;
        EXPECT_EQ(row[3], rig::fixed_text(duty_pct, 2)) << where;
        EXPECT_EQ(row[4], std::to_string(level)) << where;
        EXPECT_EQ(row[5], rig::shortest_text(level_duty_pct(c, level)) + " %") << where;
    }
    EXPECT_EQ(levels, (std::set<int>{0, 1, 2})) << "the table shows every level";
}

TEST(BoundaryController, Rule1ANozzleOutsideTheAreaIsOff) {
    // Heading north along the east edge (east = 20), antenna at east 19.0: the
    // nozzles at 17.75, 18.25, ..., 20.25 m east; nozzle 5 is 25 cm outside.
    BoundaryController c(square_config());
    const std::vector<double> d = duties_at(c, {19.0, 10.0}, 0.0, 1.5, 0.0);
    EXPECT_EQ(d, (std::vector<double>{100, 100, 100, 100, 100, 0}));
    EXPECT_TRUE(c.status().centre_inside);
    EXPECT_FALSE(c.status().nozzles[5].inside);
    EXPECT_EQ(c.status().nozzles[4].area, 0);
}

TEST(BoundaryController, Rule2TheBoomCentreOutsideTurnsAllOff) {
    // Antenna at east 20.3: the boom centre is 30 cm outside though nozzles 0
    // and 1 (19.05, 19.55 m) are inside.
    BoundaryController c(square_config());
    const std::vector<double> d = duties_at(c, {20.3, 10.0}, 0.0, 1.5, 0.0);
    EXPECT_EQ(d, std::vector<double>(6, 0.0));
    EXPECT_FALSE(c.status().centre_inside);
    EXPECT_TRUE(c.status().nozzles[0].inside);
}

TEST(BoundaryController, TheCentreRuleFaultSpraysTheInsideNozzlesWithTheCentreOutside) {
    // The same place as Rule2TheBoomCentreOutsideTurnsAllOff with the TEST-ONLY
    // fault: nozzles 0 and 1 (19.05, 19.55 m) spray though the centre is out.
    BoundaryControllerConfig config = square_config();
    config.faults.ignore_centre_rule = true;
    BoundaryController c(config);
    const std::vector<double> d = duties_at(c, {20.3, 10.0}, 0.0, 1.5, 0.0);
    EXPECT_EQ(d, (std::vector<double>{100, 100, 0, 0, 0, 0}));
    EXPECT_FALSE(c.status().centre_inside);
}

TEST(BoundaryController, DrivingOutAcrossTheEdgeShutsAllAtTheFixPastIt) {
    // North at 1.5 m/s at east 10, fixes every 0.1 s (0.15 m): the boom centre,
    // 1.0 m ahead of the antenna, passes north = 20 between the antenna at 18.95
    // (centre 19.95, inside) and 19.10 (centre 20.10, outside).
    BoundaryController c(square_config());
    for (int k = 0; k <= 20; ++k) {
        const double antenna_n = 17.0 + 0.15 * k;
        const std::vector<double> d = duties_at(c, {10.0, antenna_n}, 0.0, 1.5, 0.1 * k);
        const double expected = antenna_n + 1.0 < 20.0 ? 100.0 : 0.0;
        EXPECT_EQ(d, std::vector<double>(6, expected)) << "antenna at north " << antenna_n;
    }
}

TEST(BoundaryController, CrossingObliquelyShutsNozzlesOneByOne) {
    // Heading 45 deg (north-east) toward the north edge; the boom across the
    // heading puts nozzle 0 (left) 0.884 m further north than the centre and
    // nozzle 5 0.884 m further south. Centre at north 19.6: nozzles 0 (20.48)
    // and 1 (20.13) are outside, 2 (19.78) and the rest inside, the centre too.
    BoundaryController c(square_config(0.3));  // sparse: level 1, 40 %
    const std::vector<double> d = duties_at(c, antenna_for_centre({10.0, 19.6}, 45.0), 45.0, 1.5, 0.0);
    EXPECT_EQ(d, (std::vector<double>{0, 0, 40, 40, 40, 40}));
    // Centre at north 20.2: outside; everything off although nozzles 4 (19.67) and 5 (19.32) are inside.
    const std::vector<double> out = duties_at(c, antenna_for_centre({10.0, 20.2}, 45.0), 45.0, 1.5, 0.1);
    EXPECT_EQ(out, std::vector<double>(6, 0.0));
    EXPECT_TRUE(c.status().nozzles[5].inside);
}

TEST(BoundaryController, DensityPerAreaSetsTheLevel) {
    BoundaryControllerConfig config;
    // Two areas side by side: west half sparse (D 0.3), east half normal (D 0.5).
    TargetAreaConfig west = square_area(0.3, "west");
    TargetAreaConfig east = square_area(0.5, "east");
    for (auto& corner : east.corners) {
        const Vec2 en = kFrame.to_local(corner.lat_deg, corner.lon_deg);
        const auto g = kFrame.to_geodetic({en.east_m + 20.0, en.north_m});
        corner = {g.lat_deg, g.lon_deg};
    }
    config.areas = {west, east};
    BoundaryController c(config);
    // Straddling the line east = 20 heading north: nozzles 0-2 west (40 %), 3-5 east (100 %).
    EXPECT_EQ(duties_at(c, {20.0, 10.0}, 0.0, 1.5, 0.0), (std::vector<double>{40, 40, 40, 100, 100, 100}));
}

TEST(BoundaryController, LookAheadSwitchesEarlyWithoutChatter) {
    BoundaryControllerConfig config = square_config();
    config.lookahead_enabled = true;  // on 1.0 s (1.5 m ahead), off 0.5 s (0.75 m ahead)
    BoundaryController c(config);
    BoundaryController plain(square_config());
    std::vector<double> on_centres;
    std::vector<double> plain_on_centres;
    bool was_on = false;
    int switches = 0;
    for (int k = 0; k <= 175; ++k) {
        const double centre_n = -4.0 + 0.15 * k;
        const Vec2 antenna{10.0, centre_n - 1.0};
        const bool on = duties_at(c, antenna, 0.0, 1.5, 0.1 * k)[0] > 0.0;
        if (on != was_on) ++switches;
        was_on = on;
        if (on) on_centres.push_back(centre_n);
        if (duties_at(plain, antenna, 0.0, 1.5, 0.1 * k)[0] > 0.0) plain_on_centres.push_back(centre_n);
    }
    EXPECT_EQ(switches, 2);  // on once, off once
    ASSERT_FALSE(on_centres.empty());
    // On from the first fix with the centre 1.5 m short of the south edge (north -1.5)...
    EXPECT_GE(on_centres.front(), -1.5 - 0.05);
    EXPECT_LT(on_centres.front(), -1.5 + 0.15 + 0.05);
    // ... off once both points ahead are past the north edge: centre past 20 - 0.75 = 19.25.
    EXPECT_LE(on_centres.back(), 19.25 + 0.05);
    EXPECT_GT(on_centres.back(), 19.25 - 0.15 - 0.05);
    // Without look-ahead: on while the centre itself is inside, [0, 20].
    EXPECT_GE(plain_on_centres.front(), 0.0 - 0.05);
    EXPECT_LT(plain_on_centres.front(), 0.15 + 0.05);
    EXPECT_LE(plain_on_centres.back(), 20.0 + 0.05);
    EXPECT_GT(plain_on_centres.back(), 20.0 - 0.15 - 0.05);
}

TEST(BoundaryController, GridConvergenceIsTheUtmErrorUnlessCorrected) {
    // Heading true north; in UTM zone 49 true north is 1.32 deg clockwise of
    // grid north. The paper uses the course as the grid bearing: nozzle 5
    // (1.25 m right, 1.0 m ahead, 1.60 m from the antenna) then lands
    // 1.60 m x 0.02308 rad = 3.7 cm from where it is. Corrected, it is within
    // a millimetre of its truth (UTM's scale, 1.00014 here, is all that is left).
    BoundaryControllerConfig corrected_config = square_config();
    corrected_config.correct_grid_convergence = true;
    BoundaryController paper(square_config());
    BoundaryController corrected(corrected_config);
    const Vec2 antenna{10.0, 10.0};
    duties_at(paper, antenna, 0.0, 1.5, 0.0);
    duties_at(corrected, antenna, 0.0, 1.5, 0.0);
    const auto truth_ll = kFrame.to_geodetic(antenna + Vec2{1.25, 1.0});
    const GridPoint truth = paper.projection().forward(truth_ll.lat_deg, truth_ll.lon_deg);
    const GridPoint p = paper.status().nozzles[5].position;
    const GridPoint q = corrected.status().nozzles[5].position;
    EXPECT_NEAR(std::hypot(p.x_m - truth.x_m, p.y_m - truth.y_m), 0.0369, 0.001);
    EXPECT_LT(std::hypot(q.x_m - truth.x_m, q.y_m - truth.y_m), 0.001);
}

TEST(BoundaryController, StandingStillOrNoCourseMeansNoSpray) {
    BoundaryController c(square_config());
    // Inside, but standing: Eq. 14 gives level 0.
    EXPECT_EQ(duties_at(c, {10.0, 10.0}, 0.0, 0.0, 0.0), std::vector<double>(6, 0.0));
    // A first fix without a course: no way to place the boom.
    BoundaryController fresh(square_config());
    EXPECT_EQ(duties_at(fresh, {10.0, 10.0}, NAN, 1.5, 0.0), std::vector<double>(6, 0.0));
    EXPECT_FALSE(fresh.status().course_deg.has_value());
}

TEST(BoundaryController, CourseIsHeldWhenSlowOrEmpty) {
    BoundaryController c(square_config());
    duties_at(c, {10.0, 10.0}, 0.0, 1.5, 0.0);
    // 0.1 m/s is below course_hold_speed_m_s (0.2): its course 90 is not taken.
    duties_at(c, {10.0, 10.0}, 90.0, 0.1, 0.1);
    EXPECT_EQ(*c.status().course_deg, 0.0);
    duties_at(c, {10.0, 10.0}, NAN, 1.5, 0.2);  // empty course field
    EXPECT_EQ(*c.status().course_deg, 0.0);
    duties_at(c, {10.0, 10.0}, 90.0, 1.5, 0.3);
    EXPECT_EQ(*c.status().course_deg, 90.0);
}

TEST(BoundaryController, FixTimeoutAndInvalidFixTurnAllOff) {
    BoundaryController c(square_config());
    EXPECT_EQ(duties_at(c, {10.0, 10.0}, 0.0, 1.5, 0.0), std::vector<double>(6, 100.0));
    EXPECT_EQ(c.update(seconds_to_ns(0.4)), seconds_to_ns(0.5));  // still fresh: wake at the deadline
    EXPECT_EQ(c.duty_pct()[0], 100.0);
    EXPECT_EQ(c.update(seconds_to_ns(0.5)), rig::kNever);          // 0.5 s without a fix
    EXPECT_EQ(c.duty_pct(), std::vector<double>(6, 0.0));
    EXPECT_FALSE(c.take_notices().empty());
    // Back on with the next fix; then an RMC with status V turns everything off.
    EXPECT_EQ(duties_at(c, {10.0, 10.15}, 0.0, 1.5, 0.6), std::vector<double>(6, 100.0));
    c.on_nmea_sentence(rmc_at({10.0, 10.3}, 0.0, 1.5, false), seconds_to_ns(0.7));
    EXPECT_EQ(c.duty_pct(), std::vector<double>(6, 0.0));
}

TEST(BoundaryController, LaserHeightMovesTheBoom) {
    BoundaryController c(square_config());
    // "D=0.400m": H = 0.4 m -> Y1 = 0.9 m (Eq. 18). Antenna at north 19.05: the
    // centre at 19.95 (inside) rather than 20.05 at the default 0.5 m (outside).
    c.on_laser_line("D=0.400m\r\n", 0);
    EXPECT_DOUBLE_EQ(c.status().boom_height_m, 0.4);
    EXPECT_NEAR(c.status().boom_offset_m, 0.9, 1e-12);
    EXPECT_EQ(duties_at(c, {10.0, 19.05}, 0.0, 1.5, 0.0), std::vector<double>(6, 100.0));
    BoundaryController at_default(square_config());
    EXPECT_EQ(duties_at(at_default, {10.0, 19.05}, 0.0, 1.5, 0.0), std::vector<double>(6, 0.0));
    // A device error, garbage and a height the lift cannot reach are counted and ignored.
    c.on_laser_line("E=1\r\n", 0);
    c.on_laser_line("D=0.4", 0);
    c.on_laser_line("D=0.100m\r\n", 0);
    EXPECT_EQ(c.status().rejected_laser_lines, 3u);
    EXPECT_DOUBLE_EQ(c.status().boom_height_m, 0.4);
}

TEST(BoundaryController, HostileNmeaIsCountedNeverThrown) {
    BoundaryController c(square_config());
    EXPECT_EQ(duties_at(c, {10.0, 10.0}, 0.0, 1.5, 0.0), std::vector<double>(6, 100.0));
    std::string bad_checksum = rmc_at({30.0, 10.0}, 0.0, 1.5);
    bad_checksum[bad_checksum.size() - 3] = bad_checksum[bad_checksum.size() - 3] == '0' ? '1' : '0';
    EXPECT_NO_THROW(c.on_nmea_sentence(bad_checksum, seconds_to_ns(0.1)));
    EXPECT_NO_THROW(c.on_nmea_sentence("$GPRMC,garbage*00\r\n", seconds_to_ns(0.1)));
    EXPECT_NO_THROW(c.on_nmea_sentence(std::string("\x00\xff$\x01", 4), seconds_to_ns(0.1)));
    EXPECT_EQ(c.status().rejected_sentences, 3u);
    // Outputs unchanged by rejected input.
    EXPECT_EQ(c.duty_pct(), std::vector<double>(6, 100.0));
    // A GGA is not what the paper's controller reads: ignored, not rejected.
    c.on_nmea_sentence("$GPGGA,020000.00,3506.00000000,N,11318.00000000,E,4,20,0.7,91.700,M,0.000,M,1.0,0001*7A\r\n",
                       seconds_to_ns(0.1));
    const auto notices = c.take_notices();
    ASSERT_GE(notices.size(), 3u);
    EXPECT_NE(notices[0].find("checksum"), std::string::npos) << notices[0];
}

TEST(BoundaryController, BadConfigurationIsRejectedByName) {
    const auto expect_bad = [](BoundaryControllerConfig config, const std::string& fragment) {
        try {
            BoundaryController c(config);
            ADD_FAILURE() << "no exception for " << fragment;
        } catch (const std::invalid_argument& e) {
            EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
        }
    };
    expect_bad(BoundaryControllerConfig{}, "boundary.areas");
    BoundaryControllerConfig c = square_config();
    c.areas[0].density = 1.5;
    expect_bad(c, "areas[0] 'plot'.density");
    c = square_config();
    std::swap(c.areas[0].corners[1], c.areas[0].corners[2]);  // bow-tie
    expect_bad(c, "area 'plot': edges");
    c = square_config();
    c.areas[0].corners[1] = c.areas[0].corners[0];  // repeated corner
    expect_bad(c, "same point");
    c = square_config();
    const auto mid = kFrame.to_geodetic({10.0, 0.0});
    const auto far = kFrame.to_geodetic({30.0, 0.0});
    c.areas[0].corners = {c.areas[0].corners[0], {mid.lat_deg, mid.lon_deg}, {far.lat_deg, far.lon_deg}};  // collinear
    expect_bad(c, "degenerate");
    c = square_config();
    c.lookahead_on_s = 0.2;  // shorter than lookahead_off_s 0.5
    expect_bad(c, "lookahead_on_s");
    c = square_config();
    c.level1_max_pct = -60.0;
    expect_bad(c, "level1_max_pct");
    c = square_config();
    c.default_boom_height_m = 2.0;
    expect_bad(c, "default_boom_height_m");
    c = square_config();
    c.faults.command_delay_s = -0.1;
    expect_bad(c, "faults.command_delay_s");
}

TEST(DutyCommandDelay, WithoutDelayEachChangeGoesOutInTheStepThatDecidedIt) {
    DutyCommandDelay commands(0);
    const std::vector<double> open(6, 100.0);
    const std::vector<double> shut(6, 0.0);
    commands.decide(shut, 0);  // the first command goes out, whatever it says
    EXPECT_EQ(commands.take_due(0), std::vector<std::vector<double>>{shut});
    commands.decide(shut, seconds_to_ns(0.1));  // unchanged: nothing to send
    EXPECT_TRUE(commands.take_due(seconds_to_ns(0.1)).empty());
    EXPECT_EQ(commands.next_due_ns(), rig::kNever);
    commands.decide(open, seconds_to_ns(0.2));
    EXPECT_EQ(commands.take_due(seconds_to_ns(0.2)), std::vector<std::vector<double>>{open});
}

TEST(DutyCommandDelay, TheLateFaultSendsEveryChangeInOrderTheDelayAfterItsDecision) {
    // 0.3 s late: the changes decided at 1.0 and 1.1 s go out at 1.3 and 1.4 s,
    // both, in order, though the second was decided before the first went out.
    DutyCommandDelay commands(seconds_to_ns(0.3));
    const std::vector<double> open(6, 100.0);
    const std::vector<double> half{100, 100, 100, 0, 0, 0};
    const std::vector<double> shut(6, 0.0);
    commands.decide(open, seconds_to_ns(0.5));
    commands.decide(half, seconds_to_ns(1.0));
    commands.decide(shut, seconds_to_ns(1.1));
    EXPECT_EQ(commands.next_due_ns(), seconds_to_ns(0.8));
    EXPECT_TRUE(commands.take_due(seconds_to_ns(0.8) - 1).empty());
    EXPECT_EQ(commands.take_due(seconds_to_ns(1.2)), std::vector<std::vector<double>>{open});
    EXPECT_EQ(commands.next_due_ns(), seconds_to_ns(1.3));
    EXPECT_EQ(commands.take_due(seconds_to_ns(1.4)), (std::vector<std::vector<double>>{half, shut}));
    EXPECT_EQ(commands.next_due_ns(), rig::kNever);
    EXPECT_THROW(DutyCommandDelay(-1), std::invalid_argument);
}

}  // namespace
