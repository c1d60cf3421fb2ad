// report.html: one self-contained, well-formed page with gnuplot figures, odd
// case names escaped, errors shown, byte-identical across runs, and still
// written (with the reason in place of the figures) when gnuplot is missing.
// RIG_SAMPLE_REPORT=FILE keeps a copy of the sample page to look at.
#include "harness/report/html_report.h"
#include "harness/systems/breakpoint/breakpoint_figures.h"
#include "tool_support.h"

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

namespace rig::harness {
namespace {

namespace fs = std::filesystem;

constexpr double kTargetFlow = 20.0;
constexpr double kSpeedMps = 6.0 / 3.6;
constexpr double kOpenCommandDistance = -3.45;
constexpr double kOpenCommandTime = 40.0;
constexpr double kAdjustTime = 1.4;

// A flow step response: 0 until the open command, then a first-order rise
// that enters and stays within ±3 % of target at exactly kAdjustTime.
std::vector<FlowSample> step_response(double overshoot_scale) {
    const double time_constant = kAdjustTime / std::log(1.0 / 0.03);
    std::vector<FlowSample> samples;
    for (int i = 0; i <= 600; ++i) {
        const double t = kOpenCommandTime - 2.0 + 0.01 * i;
        const double since = t - kOpenCommandTime;
        const double flow = since < 0 ? 0.0 : kTargetFlow * (1.0 - std::exp(-since / time_constant));
        FlowSample sample;
        sample.t_s = t;
        sample.distance_to_breakpoint_m = kOpenCommandDistance + since * kSpeedMps;
        sample.main_flow_l_min = flow * overshoot_scale;
        // The controller's Eq. 3 estimate: pulse counting every 0.1 s, slightly off.
        sample.measured_flow_l_min = i % 10 == 0 ? flow * 1.01 : kNotMeasured;
        samples.push_back(sample);
    }
    return samples;
}

// 19 rows 0.3 m apart around a breakpoint at 0 m; the continuation starts
// spraying 1.5 m before it, so rows in [-1.5, 0) get both passes.
std::vector<DoseSample> dose_with_overlap() {
    std::vector<DoseSample> rows;
    for (int row = 0; row < 19; ++row) {
        const double along = -3.3 + 0.3 * row;
        DoseSample sample;
        sample.along_m = along;
        sample.first_pass_dose = along < 0.0 ? 7500.0 + 40.0 * (row % 3) : 0.0;
        sample.continuation_dose = along >= -1.5 - 1e-9 ? 8200.0 - 30.0 * (row % 2) : 0.0;
        rows.push_back(sample);
    }
    return rows;
}

BreakpointFigures breakpoint_figures_with_data() {
    BreakpointFigures figures;
    figures.target_flow_l_min = kTargetFlow;
    figures.breakpoint_along_m = 0.0;
    figures.section_open_command_distance_m = kOpenCommandDistance;
    figures.flow = step_response(1.0);
    figures.dose = dose_with_overlap();
    figures.areas = {{"operational", -3.45, -1.5}, {"repeated", -1.5, 0.0}, {"continuation", 0.0, 2.25}};
    return figures;
}

CaseFigures figures_of(BreakpointFigures system) {
    CaseFigures figures;
    figures.system = std::make_shared<BreakpointFigures>(std::move(system));
    return figures;
}

CaseFigures figures_with_data() { return figures_of(breakpoint_figures_with_data()); }

CaseResult odd_name_case() {
    CaseResult result;
    result.name = "overlap <6km/h> & \"fusion\" 'o_k'";
    result.file = "cases/a&b <c>.yaml";
    result.passed = true;
    result.seed = 3;
    result.metrics = {
        {"flow_adjust_time_s", kAdjustTime}, {"overlap_m", 1.5}, {"missed_m", 0.0}, {"flow_error_pct", 2.1}};
    result.limits = {{"flow_adjust_time_s", 1.7}, {"overlap_m", 3.3}, {"missed_m", 0.0}};
    result.trace_path = "out/odd.trace";
    result.trace_sha256 = std::string(64, 'c');
    result.sim_seconds = 60.0;
    result.wall_seconds = 1.5;
    return result;
}

CaseResult failing_case() {
    CaseResult result;
    result.name = "breakpoint-4.5kmh-rtk";
    result.file = "cases/bp45.yaml";
    result.passed = false;
    result.seed = 2;
    result.metrics = {{"flow_adjust_time_s", 2.2}, {"overlap_m", 3.61}, {"missed_m", 0.0}};
    result.limits = {{"flow_adjust_time_s", 1.7}, {"overlap_m", 3.3}, {"missed_m", 0.0}};
    result.failures = {"flow_adjust_time_s 2.2 > 1.7", "overlap_m 3.61 > 3.3"};
    result.sim_seconds = 58.0;
    result.wall_seconds = 1.2;
    return result;
}

CaseResult error_case() {
    CaseResult result;
    result.name = "plant-dies";
    result.file = "cases/dies.yaml";
    result.passed = false;
    result.seed = 1;
    result.limits = {{"overlap_m", 3.3}};
    result.error = "node 'plant' stopped answering at t=12.5 s <exit 9>";
    result.error_kind = "node_unresponsive";
    result.failures = {"error: node_unresponsive: " + result.error};  // as judge_case() gives it
    result.sim_seconds = 12.5;
    result.wall_seconds = 10.0;
    return result;
}

struct Suite {
    std::vector<CaseResult> results;
    std::vector<CaseFigures> figures;
};

Suite synthetic_suite() {
    Suite suite;
    suite.results = {odd_name_case(), failing_case(), error_case()};
    BreakpointFigures slow_flow = breakpoint_figures_with_data();
    slow_flow.flow = step_response(1.02);
    CaseFigures slow = figures_of(slow_flow);
    slow.jitter = {{"gnss <rs232>", 0.05, 0.4, 1.2}, {"flow meter", 0.02, 0.1, 0.3}};
    suite.figures = {figures_with_data(), slow, CaseFigures{}};
    return suite;
}

std::string read_all(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    std::ostringstream content;
    content << in.rdbuf();
    return content.str();
}

std::size_t count(const std::string& text, const std::string& needle) {
    std::size_t found = 0;
    for (std::size_t pos = text.find(needle); pos != std::string::npos; pos = text.find(needle, pos + 1)) ++found;
    return found;
}

class HtmlReportTest : public ::testing::Test {
protected:
    void SetUp() override {
        std::random_device entropy;
        dir_ = fs::temp_directory_path() /
               ("html_report_test_" + std::to_string(::getpid()) + "_" + std::to_string(entropy()));
        fs::create_directories(dir_);
    }
    void TearDown() override {
        std::error_code ignored;
        fs::remove_all(dir_, ignored);
    }
    // Exit status of a command run through the shell on paths we made (no user strings).
    static int shell(const std::string& command) {
        const int status = std::system(command.c_str());
        return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    }

    fs::path dir_;
};

TEST_F(HtmlReportTest, DrawsFiguresEscapesNamesShowsErrorsAndIsWellFormed) {
    ASSERT_TRUE(rig::testing::tool_installed("gnuplot", "gnuplot-nox"));
    const Suite suite = synthetic_suite();
    const fs::path file = dir_ / "report.html";
    const std::vector<std::string> problems =
        write_html_report(file, suite.results, suite.figures, summarize(suite.results));
    for (const std::string& problem : problems) ADD_FAILURE() << problem;
    const std::string page = read_all(file);
    ASSERT_FALSE(page.empty());
    // To look at it in a browser: RIG_SAMPLE_REPORT=/tmp/sample-report.html
    if (const char* keep = std::getenv("RIG_SAMPLE_REPORT"); keep != nullptr && *keep != '\0') {
        fs::copy_file(file, keep, fs::copy_options::overwrite_existing);
    }

    // One flow and one dose figure per case with data; none for the case that did not run.
    EXPECT_EQ(count(page, "<figure class=\"figure flow\""), 2u);
    EXPECT_EQ(count(page, "<figure class=\"figure dose\""), 2u);
    EXPECT_NE(page.find("id=\"case-1-flow\""), std::string::npos);
    EXPECT_NE(page.find("id=\"case-2-dose\""), std::string::npos);
    EXPECT_EQ(page.find("id=\"case-3-flow\""), std::string::npos);
    // Panels: flow by distance + by time, dose + Eq. 9 per case, and one chart per
    // limited metric measured in at least two cases (flow_adjust_time_s, missed_m, overlap_m).
    EXPECT_EQ(count(page, "<svg"), 2u * 4u + 3u);
    EXPECT_EQ(page.find("not drawn"), std::string::npos);
    // Self-contained: no script, nothing fetched.
    EXPECT_EQ(page.find("<script"), std::string::npos);
    EXPECT_EQ(page.find("src="), std::string::npos);
    EXPECT_EQ(page.find("<?xml"), std::string::npos);

    // Odd names escaped in the HTML and in gnuplot's SVG text alike.
    EXPECT_EQ(page.find("overlap <6km/h>"), std::string::npos);
    EXPECT_NE(page.find("overlap &lt;6km/h&gt; &amp; \"fusion\" 'o_k'"), std::string::npos);
    EXPECT_NE(page.find("cases/a&amp;b &lt;c&gt;.yaml"), std::string::npos);
    EXPECT_NE(page.find("gnss &lt;rs232&gt;"), std::string::npos);

    // The error is prominent in the case's own section and in the table.
    EXPECT_NE(page.find("<div class=\"error-box\"><strong>The case did not run to the end (node_unresponsive):"
                        "</strong>\n<pre>node 'plant' stopped answering at t=12.5 s &lt;exit 9&gt;</pre>"),
              std::string::npos);
    EXPECT_NE(page.find("<li>error: node_unresponsive: node 'plant' stopped answering"), std::string::npos);
    // Failing limited metrics are highlighted, with enough digits.
    EXPECT_NE(page.find("<div class=\"metric-line over\"><span class=\"name\">overlap_m</span> <span "
                        "class=\"num\">3.61 / 3.3</span></div>"),
              std::string::npos);
    EXPECT_NE(page.find("<span class=\"badge fail\">FAIL</span>"), std::string::npos);
    // Summary: speed-up = simulated / wall.
    EXPECT_NE(page.find("130.5 s</td><td class=\"num\">12.7 s</td><td class=\"num\">10.3\u00d7"), std::string::npos);

    // Well-formed as XML as a whole (the SVGs included), so as polyglot XHTML.
    ASSERT_TRUE(rig::testing::tool_installed("xmllint", "libxml2-utils"));
    EXPECT_EQ(shell("xmllint --noout '" + file.string() + "'"), 0);
    // And each inlined SVG alone.
    // (A plain search: std::regex recurses per character and overflows the stack
    // on a figure's worth of SVG in a sanitizer build.)
    int svg_index = 0;
    const std::string svg_end = "</svg>";
    for (std::size_t from = page.find("<svg"); from != std::string::npos; from = page.find("<svg", from)) {
        const std::size_t end = page.find(svg_end, from);
        ASSERT_NE(end, std::string::npos) << "an <svg> without its </svg>";
        const fs::path svg_file = dir_ / ("figure-" + std::to_string(svg_index++) + ".svg");
        std::ofstream(svg_file, std::ios::binary) << page.substr(from, end + svg_end.size() - from);
        EXPECT_EQ(shell("xmllint --noout '" + svg_file.string() + "'"), 0) << svg_file;
        from = end + svg_end.size();
    }
    EXPECT_EQ(svg_index, 11);
}

TEST_F(HtmlReportTest, SameInputsGiveTheSameBytes) {
    ASSERT_TRUE(rig::testing::tool_installed("gnuplot", "gnuplot-nox"));
    const Suite suite = synthetic_suite();
    write_html_report(dir_ / "first.html", suite.results, suite.figures, summarize(suite.results));
    write_html_report(dir_ / "second.html", suite.results, suite.figures, summarize(suite.results));
    const std::string first = read_all(dir_ / "first.html");
    EXPECT_FALSE(first.empty());
    EXPECT_TRUE(first == read_all(dir_ / "second.html"));
}

TEST_F(HtmlReportTest, MissingGnuplotStillWritesTheReportWithTheReason) {
    const Suite suite = synthetic_suite();
    HtmlReportOptions options;
    options.gnuplot = (dir_ / "no-such-gnuplot").string();
    const std::vector<std::string> problems =
        write_html_report(dir_ / "report.html", suite.results, suite.figures, summarize(suite.results), options);
    ASSERT_EQ(problems.size(), 1u);  // one reason, not one line per panel
    EXPECT_NE(problems[0].find("11 figure panels not drawn"), std::string::npos) << problems[0];
    EXPECT_NE(problems[0].find("no-such-gnuplot"), std::string::npos) << problems[0];

    const std::string page = read_all(dir_ / "report.html");
    EXPECT_NE(page.find("&lt;scratch&gt;/all.gp': No such file or directory"), std::string::npos);
    // Deterministic even so: the scratch directory's random name is not in the page.
    write_html_report(dir_ / "again.html", suite.results, suite.figures, summarize(suite.results), options);
    EXPECT_TRUE(page == read_all(dir_ / "again.html"));
    EXPECT_EQ(count(page, "<svg"), 0u);
    EXPECT_EQ(count(page, "class=\"panel figure-error\""), 11u);
    EXPECT_NE(page.find("Problems with this report"), std::string::npos);
    EXPECT_NE(page.find("no-such-gnuplot"), std::string::npos);
    // The tables are all there.
    EXPECT_EQ(count(page, "<figure class=\"figure flow\""), 2u);
    EXPECT_NE(page.find("<td class=\"mono\">flow_error_pct</td>"), std::string::npos);
    // Well-formed without its figures too.
    ASSERT_TRUE(rig::testing::tool_installed("xmllint", "libxml2-utils"));
    EXPECT_EQ(shell("xmllint --noout '" + (dir_ / "report.html").string() + "'"), 0);
}

// A stand-in for gnuplot: refuses the all-panels batch (so each panel is drawn
// alone) and, when `bad_text` is set, any panel whose script contains it.
fs::path gnuplot_wrapper(const fs::path& dir, const std::string& bad_text) {
    const fs::path wrapper = dir / "gnuplot-wrapper";
    std::ofstream out(wrapper, std::ios::binary);
    out << "#!/bin/sh\ncase \"$1\" in */all.gp) echo 'batch refused' >&2; exit 1;; esac\n";
    if (!bad_text.empty()) out << "if grep -q '" << bad_text << "' \"$1\"; then echo 'bad panel' >&2; exit 3; fi\n";
    out << "exec gnuplot \"$@\"\n";
    out.close();
    fs::permissions(wrapper, fs::perms::owner_all);
    return wrapper;
}

TEST_F(HtmlReportTest, PanelsDrawnOneByOneAreTheSameAsInOneBatch) {
    ASSERT_TRUE(rig::testing::tool_installed("gnuplot", "gnuplot-nox"));
    const Suite suite = synthetic_suite();
    const std::vector<std::string> batch_problems =
        write_html_report(dir_ / "batch.html", suite.results, suite.figures, summarize(suite.results));
    EXPECT_TRUE(batch_problems.empty());
    HtmlReportOptions options;
    options.gnuplot = gnuplot_wrapper(dir_, "").string();
    const std::vector<std::string> alone_problems =
        write_html_report(dir_ / "alone.html", suite.results, suite.figures, summarize(suite.results), options);
    EXPECT_TRUE(alone_problems.empty());
    EXPECT_TRUE(read_all(dir_ / "batch.html") == read_all(dir_ / "alone.html"));
}

TEST_F(HtmlReportTest, AFailingPanelSpoilsOnlyItself) {
    ASSERT_TRUE(rig::testing::tool_installed("gnuplot", "gnuplot-nox"));
    const Suite suite = synthetic_suite();
    HtmlReportOptions options;
    options.gnuplot = gnuplot_wrapper(dir_, "Normalised total dose").string();
    const std::vector<std::string> problems =
        write_html_report(dir_ / "report.html", suite.results, suite.figures, summarize(suite.results), options);
    ASSERT_EQ(problems.size(), 1u);
    EXPECT_NE(problems[0].find("2 figure panels not drawn (case 1 ("), std::string::npos) << problems[0];
    EXPECT_NE(problems[0].find("): normalised dose, ...): gnuplot ("), std::string::npos) << problems[0];
    EXPECT_NE(problems[0].find("process exited with status 3:\nbad panel"), std::string::npos) << problems[0];
    const std::string page = read_all(dir_ / "report.html");
    EXPECT_EQ(count(page, "<svg"), 9u);
    EXPECT_EQ(count(page, "Normalised total dose per row (Eq. 9): not drawn."), 2u);
}

TEST_F(HtmlReportTest, AStuckGnuplotIsStoppedAtTheTimeLimit) {
    const fs::path stuck = dir_ / "stuck-gnuplot";
    std::ofstream(stuck, std::ios::binary) << "#!/bin/sh\nexec sleep 60\n";
    fs::permissions(stuck, fs::perms::owner_all);
    const Suite suite = synthetic_suite();
    HtmlReportOptions options;
    options.gnuplot = stuck.string();
    options.gnuplot_time_limit = std::chrono::milliseconds(200);
    const std::vector<std::string> problems =
        write_html_report(dir_ / "report.html", suite.results, suite.figures, summarize(suite.results), options);
    ASSERT_EQ(problems.size(), 1u);
    EXPECT_NE(problems[0].find("11 figure panels not drawn"), std::string::npos) << problems[0];
    EXPECT_NE(problems[0].find("(time limit 200 ms)"), std::string::npos) << problems[0];
    EXPECT_EQ(count(read_all(dir_ / "report.html"), "class=\"panel figure-error\""), 11u);
}

TEST_F(HtmlReportTest, CaseNamesAreNeverCode) {
    ASSERT_TRUE(rig::testing::tool_installed("gnuplot", "gnuplot-nox"));
    Suite suite = synthetic_suite();
    suite.results.resize(1);
    suite.figures.resize(1);
    // A name made to close gnuplot's string and run a command stays text.
    suite.results[0].name = "x' ; system('touch " + (dir_ / "pwned").string() + "') ; '";
    std::vector<CaseResult> twice = {suite.results[0], suite.results[0]};
    twice[1].name += "\n\\";
    const std::vector<std::string> problems =
        write_html_report(dir_ / "report.html", twice, {suite.figures[0], suite.figures[0]}, summarize(twice));
    for (const std::string& problem : problems) ADD_FAILURE() << problem;
    EXPECT_FALSE(fs::exists(dir_ / "pwned"));
    EXPECT_EQ(count(read_all(dir_ / "report.html"), "<svg"), 2u * 4u + 3u);
}

TEST_F(HtmlReportTest, LongTracesAreThinnedForThePage) {
    ASSERT_TRUE(rig::testing::tool_installed("gnuplot", "gnuplot-nox"));
    Suite suite = synthetic_suite();
    suite.results.resize(1);
    suite.figures.resize(1);
    // A minute at 1 kHz, with one spike that must survive the thinning.
    BreakpointFigures long_trace = breakpoint_figures_with_data();
    std::vector<FlowSample>& flow = long_trace.flow;
    flow.clear();
    for (int i = 0; i <= 60'000; ++i) {
        FlowSample sample;
        sample.t_s = 0.001 * i;
        sample.distance_to_breakpoint_m = -50.0 + sample.t_s * kSpeedMps;
        sample.main_flow_l_min = i == 31'234 ? 37.5 : 20.0 + 0.2 * std::sin(0.01 * i);
        sample.measured_flow_l_min = sample.main_flow_l_min;
        flow.push_back(sample);
    }
    long_trace.section_open_command_t_s = 30.0;
    suite.figures[0] = figures_of(long_trace);
    const HtmlReport report = render_html_report(suite.results, suite.figures, summarize(suite.results));
    EXPECT_TRUE(report.problems.empty());
    EXPECT_EQ(count(report.html, "<svg"), 4u);
    EXPECT_LT(report.html.size(), 2'000'000u);
    // The y axis reaches past the spike.
    EXPECT_NE(report.html.find("> 40</text>"), std::string::npos);
}

TEST(HtmlReport, ExpectedFailureIsShownAsSuchWithoutFigures) {
    CaseResult negative = failing_case();
    negative.name = "rtk-only-dropout";
    negative.passed = true;  // judge_case: broke exactly the limits it expects to
    negative.expected_failure = true;
    const HtmlReport report = render_html_report({negative}, {}, summarize({negative}));
    EXPECT_TRUE(report.problems.empty());
    EXPECT_NE(report.html.find(">expected failure OK</span>"), std::string::npos);
    EXPECT_NE(report.html.find("<div class=\"metric-line expected\"><span class=\"name\">overlap_m</span>"),
              std::string::npos);
    EXPECT_NE(report.html.find("<li>overlap_m 3.61 &gt; 3.3 <span class=\"expected\">(expected)</span></li>"),
              std::string::npos);
    EXPECT_NE(report.html.find("No flow, dose, vision or jitter data was recorded for this case."), std::string::npos);
    EXPECT_NE(report.html.find("<p class=\"verdict pass\">All 1 case passed</p>"), std::string::npos);
    EXPECT_EQ(report.html.find("<svg"), std::string::npos);
}

TEST_F(HtmlReportTest, WriteResultsWithFiguresAddsReportHtmlAndNeverThrowsForIt) {
    const Suite suite = synthetic_suite();
    HtmlReportOptions options;
    options.gnuplot = (dir_ / "no-such-gnuplot").string();
    const fs::path out = dir_ / "out";
    const std::vector<std::string> problems =
        write_results(out, suite.results, summarize(suite.results), suite.figures, options);
    EXPECT_EQ(problems.size(), 1u);
    for (const char* name : {"results.json", "junit.xml", "report.txt", "report.html"}) {
        EXPECT_TRUE(fs::exists(out / name)) << name;
    }
    // report.html cannot be written (a directory is in its place): told, not thrown.
    fs::remove(out / "report.html");
    fs::create_directories(out / "report.html" / "blocker");
    std::vector<std::string> blocked;
    EXPECT_NO_THROW(blocked = write_results(out, suite.results, summarize(suite.results), suite.figures, options));
    ASSERT_FALSE(blocked.empty());
    EXPECT_NE(blocked.back().find("report.html not written"), std::string::npos) << blocked.back();
}

}  // namespace
}  // namespace rig::harness
