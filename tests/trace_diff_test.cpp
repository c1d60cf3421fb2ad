// `rig diff`'s comparison (harness/trace/trace_diff.h) on hand-made sample
// lists: where each topic parts, in what order the topics part, who changed,
// the fields that differ, how a long sample is shown, and where two case
// files part. No trace file, no DDS.
#include <gtest/gtest.h>

#include "harness/trace/trace_diff.h"

namespace {

using namespace rig::harness;

// Rows numbered in the order given, as a trace stores them.
class Rows {
public:
    Rows& add(const std::string& topic, rig::TimeNs t_ns, const std::string& json, int round = 0) {
        rows_[topic].push_back(TraceRow{t_ns, round, ++rowid_, json, {}});
        return *this;
    }
    const TopicRows& rows() const { return rows_; }

private:
    TopicRows rows_;
    std::int64_t rowid_ = 0;
};

constexpr rig::TimeNs kSecond = 1'000'000'000;

// What both runs of a breakpoint case share before anything parts.
Rows common_start() {
    Rows rows;
    rows.add("device/main_flow_meter/count", 0, R"({"count_pulses":0})")
        .add("truth/hydraulics", 0, R"({"main_flow_l_min":0.0,"valve_opening_pct":90.0})")
        .add("actuator/ball_valve/relays", 0, R"({"forward":false,"reverse":true})");
    return rows;
}

TEST(TraceDiff, TheSameSamplesAreTheSameBehaviour) {
    Rows a = common_start();
    Rows b = common_start();
    a.add("truth/hydraulics", kSecond, R"({"main_flow_l_min":1.5})");
    b.add("truth/hydraulics", kSecond, R"({"main_flow_l_min":1.5})");
    const TraceDiff diff = diff_samples(a.rows(), b.rows());
    EXPECT_TRUE(diff.same());
    EXPECT_EQ(diff.first(), nullptr);
    EXPECT_EQ(diff.agreeing_samples, 4u);
    EXPECT_EQ(diff.same_topics.size(), 3u);
    EXPECT_EQ(parting_cause(diff), PartingCause::none);
}

TEST(TraceDiff, AChangedValveCommandPartsFirstOnItsActuatorTopic) {
    Rows a = common_start();
    Rows b = common_start();
    a.add("actuator/ball_valve/relays", 31'420'000'000, R"({"forward":true,"reverse":false})");
    b.add("actuator/ball_valve/relays", 31'420'000'000, R"({"forward":false,"reverse":false})");
    // The plant follows the command 10 ms later.
    a.add("truth/hydraulics", 31'430'000'000, R"({"main_flow_l_min":20.0,"valve_opening_pct":90.1})");
    b.add("truth/hydraulics", 31'430'000'000, R"({"main_flow_l_min":20.0,"valve_opening_pct":90.0})");
    const TraceDiff diff = diff_samples(a.rows(), b.rows());
    ASSERT_EQ(diff.partings.size(), 2u);
    const TopicParting& first = diff.partings[0];
    EXPECT_EQ(first.topic, "actuator/ball_valve/relays");
    EXPECT_EQ(first.role, TopicRole::actuator);
    EXPECT_EQ(first.t_ns, 31'420'000'000);
    EXPECT_EQ(first.index, 1u);
    ASSERT_TRUE(first.a && first.b);
    EXPECT_EQ(first.a->json_text, R"({"forward":true,"reverse":false})");
    EXPECT_EQ(first.b->json_text, R"({"forward":false,"reverse":false})");
    ASSERT_EQ(first.differing_fields.size(), 1u);
    EXPECT_EQ(first.differing_fields[0].path, "forward");
    EXPECT_EQ(first.differing_fields[0].a, "true");
    EXPECT_EQ(first.differing_fields[0].b, "false");
    EXPECT_EQ(diff.partings[1].topic, "truth/hydraulics");
    EXPECT_EQ(diff.partings[1].differing_fields.at(0).path, "valve_opening_pct");
    EXPECT_EQ(parting_cause(diff), PartingCause::controller);
    ASSERT_NE(diff.first_with_role(TopicRole::actuator), nullptr);
    EXPECT_EQ(diff.first_with_role(TopicRole::actuator)->topic, "actuator/ball_valve/relays");
    EXPECT_EQ(diff.same_topics, std::vector<std::string>{"device/main_flow_meter/count"});
}

TEST(TraceDiff, ADeviceThatPartsBeforeAnyActuatorMeansTheCaseOrTheRigChanged) {
    Rows a = common_start();
    Rows b = common_start();
    // Another seed: the meter's pulses part at 0.5 s, and the controller's
    // command follows at 2 s. Topic names sort the actuator first: the order
    // must be by time.
    a.add("device/main_flow_meter/count", kSecond / 2, R"({"count_pulses":4})");
    b.add("device/main_flow_meter/count", kSecond / 2, R"({"count_pulses":5})");
    a.add("actuator/ball_valve/relays", 2 * kSecond, R"({"forward":true,"reverse":false})");
    b.add("actuator/ball_valve/relays", 2 * kSecond, R"({"forward":false,"reverse":false})");
    const TraceDiff diff = diff_samples(a.rows(), b.rows());
    ASSERT_EQ(diff.partings.size(), 2u);
    EXPECT_EQ(diff.partings[0].topic, "device/main_flow_meter/count");
    EXPECT_EQ(diff.partings[0].t_ns, kSecond / 2);
    EXPECT_EQ(diff.partings[1].topic, "actuator/ball_valve/relays");
    EXPECT_EQ(parting_cause(diff), PartingCause::case_or_rig);
    EXPECT_EQ(diff.first_with_role(TopicRole::actuator)->t_ns, 2 * kSecond);
}

TEST(TraceDiff, ASampleOneRunHasAndTheOtherHasNotPartsAtItsTime) {
    Rows a = common_start();
    Rows b = common_start();
    a.add("actuator/section_valves/open", 3 * kSecond, R"({"open_mask":7})");
    b.add("actuator/section_valves/open", 3 * kSecond, R"({"open_mask":7})");
    b.add("actuator/section_valves/open", 4 * kSecond, R"({"open_mask":0})");
    const TraceDiff diff = diff_samples(a.rows(), b.rows());
    ASSERT_EQ(diff.partings.size(), 1u);
    const TopicParting& parting = diff.partings[0];
    EXPECT_EQ(parting.index, 1u);
    EXPECT_FALSE(parting.a.has_value());
    ASSERT_TRUE(parting.b.has_value());
    EXPECT_EQ(parting.t_ns, 4 * kSecond);
    EXPECT_EQ(parting.a_samples, 1u);
    EXPECT_EQ(parting.b_samples, 2u);
    EXPECT_TRUE(parting.differing_fields.empty());
}

TEST(TraceDiff, TheSameCommandAtAnotherTimePartsAtTheEarlierOne) {
    Rows a = common_start();
    Rows b = common_start();
    a.add("actuator/unloading_valve/open", 5 * kSecond, R"({"open":true})");
    b.add("actuator/unloading_valve/open", 4 * kSecond, R"({"open":true})");
    const TraceDiff diff = diff_samples(a.rows(), b.rows());
    ASSERT_EQ(diff.partings.size(), 1u);
    EXPECT_EQ(diff.partings[0].t_ns, 4 * kSecond);
    EXPECT_TRUE(diff.partings[0].differing_fields.empty());
}

TEST(TraceDiff, TopicsPartingAtOneInstantAreInTheOrderTheirRoundDeliveredThem) {
    Rows a;
    Rows b;
    // Round 1 delivers the status, round 2 the valve command and then the
    // plant's truth at that instant; all at t = 1 s.
    a.add("controller/status", kSecond, R"({"s":1})", 1).add("truth/vehicle", kSecond, R"({"along_m":1})", 2);
    a.add("actuator/ball_valve/relays", kSecond, R"({"forward":true})", 2);
    b.add("controller/status", kSecond, R"({"s":2})", 1).add("truth/vehicle", kSecond, R"({"along_m":2})", 2);
    b.add("actuator/ball_valve/relays", kSecond, R"({"forward":false})", 2);
    const TraceDiff diff = diff_samples(a.rows(), b.rows());
    ASSERT_EQ(diff.partings.size(), 3u);
    EXPECT_EQ(diff.partings[0].topic, "controller/status");
    EXPECT_EQ(diff.partings[1].topic, "truth/vehicle");  // stored before the command in its round
    EXPECT_EQ(diff.partings[2].topic, "actuator/ball_valve/relays");
    EXPECT_EQ(parting_cause(diff), PartingCause::controller);
}

TEST(TraceDiff, ATopicOnlyOneRunHasPartsAtItsFirstSample) {
    Rows a = common_start();
    Rows b = common_start();
    b.add("controller/vision/density", 2 * kSecond, R"({"density":[0.1]})");
    const TraceDiff diff = diff_samples(a.rows(), b.rows());
    ASSERT_EQ(diff.partings.size(), 1u);
    EXPECT_EQ(diff.partings[0].topic, "controller/vision/density");
    EXPECT_EQ(diff.partings[0].index, 0u);
    EXPECT_EQ(diff.partings[0].a_samples, 0u);
    EXPECT_EQ(parting_cause(diff), PartingCause::controller);
}

TEST(TraceDiff, ATopicOfNoKnownRolePartingFirstLeavesTheCauseUnknown) {
    Rows a;
    Rows b;
    a.add("team/debug", kSecond, R"({"x":1})");
    b.add("team/debug", kSecond, R"({"x":2})");
    EXPECT_EQ(parting_cause(diff_samples(a.rows(), b.rows())), PartingCause::unknown);
    // Declared as the controller's own, it is the controller's.
    const TraceDiff declared = diff_samples(a.rows(), b.rows(), [](const std::string&) { return TopicRole::controller; });
    EXPECT_EQ(parting_cause(declared), PartingCause::controller);
}

TEST(TraceDiff, DifferingFieldsNameTheirPathsThroughObjectsAndArrays) {
    const nlohmann::json a = nlohmann::json::parse(
        R"({"time_ns":5,"nozzles":[{"duty_pct":40,"flow_l_min":0.5},{"duty_pct":0}],"mode":"on"})");
    const nlohmann::json b = nlohmann::json::parse(
        R"({"time_ns":5,"nozzles":[{"duty_pct":40,"flow_l_min":0.6},{"duty_pct":10},{"duty_pct":0}],"extra":1})");
    std::size_t more = 99;
    const std::vector<FieldDifference> fields = differing_fields(a, b, 10, &more);
    std::vector<std::string> paths;
    for (const FieldDifference& field : fields) paths.push_back(field.path);
    EXPECT_EQ(paths, (std::vector<std::string>{"extra", "mode", "nozzles[0].flow_l_min", "nozzles[1].duty_pct", "nozzles[2]"}));
    EXPECT_EQ(more, 0u);
    EXPECT_EQ(fields[0].a, "");  // A has no "extra"
    EXPECT_EQ(fields[0].b, "1");
    EXPECT_EQ(fields[4].b, R"({"duty_pct":0})");
    // At most as many as asked for; the rest counted.
    const std::vector<FieldDifference> two = differing_fields(a, b, 2, &more);
    EXPECT_EQ(two.size(), 2u);
    EXPECT_EQ(more, 3u);
    // A scalar is its own whole value.
    const std::vector<FieldDifference> whole = differing_fields(nlohmann::json(1), nlohmann::json("1"), 10);
    ASSERT_EQ(whole.size(), 1u);
    EXPECT_EQ(whole[0].path, "");
}

TEST(TraceDiff, AShortSampleIsShownWholeALongOneByItsDifferingFieldsOrCut) {
    EXPECT_EQ(shown_sample(R"({"open":true})", {}, Run::a, 40).text, R"({"open":true})");
    EXPECT_TRUE(shown_sample(R"({"open":true})", {}, Run::a, 40).note.empty());

    const std::string long_sample = R"({"duty_pct":[10,20,30,40,50,60],"frequency_hz":9.0,"time_ns":123456789})";
    const std::vector<FieldDifference> fields{{"duty_pct[3]", "40", "45"}};
    const ShownSample a = shown_sample(long_sample, fields, Run::a, 30);
    EXPECT_EQ(a.text, "duty_pct[3]=40");
    EXPECT_NE(a.note.find("only the fields that differ"), std::string::npos) << a.note;
    EXPECT_NE(a.note.find(std::to_string(long_sample.size()) + " characters"), std::string::npos) << a.note;
    EXPECT_EQ(shown_sample(long_sample, fields, Run::b, 30).text, "duty_pct[3]=45");

    const ShownSample cut = shown_sample(long_sample, {}, Run::a, 30);
    EXPECT_EQ(cut.text, long_sample.substr(0, 30) + "\u2026");
    EXPECT_NE(cut.note.find("cut"), std::string::npos) << cut.note;

    // A cut never splits a character: "é" is two bytes, the cut falls inside it.
    const ShownSample accented = shown_sample("{\"text\":\"\u00e9\u00e9\u00e9\"}", {}, Run::a, 10);
    EXPECT_EQ(accented.text, "{\"text\":\"\u2026");
}

TEST(TraceDiff, CaseFilesPartAtTheirFirstDifferentLineInItsSection) {
    const std::string a = "name: x\nseed: 2\ncontroller:\n  target_flow_l_min: 20\n  pid: { kp: 0.1 }\nlimits: {}\n";
    const std::string b = "name: x\nseed: 2\ncontroller:\n  target_flow_l_min: 20\n  pid: { kp: 0.5 }\nlimits: {}\n";
    EXPECT_FALSE(first_case_file_difference(a, a).has_value());
    const auto difference = first_case_file_difference(a, b);
    ASSERT_TRUE(difference.has_value());
    EXPECT_EQ(difference->line, 5u);
    EXPECT_EQ(difference->section, "controller");
    EXPECT_EQ(difference->a_line, "  pid: { kp: 0.1 }");
    EXPECT_EQ(difference->b_line, "  pid: { kp: 0.5 }");
    // A top-level key that differs is its own section; a file that goes on is a difference too.
    EXPECT_EQ(first_case_file_difference(a, "name: x\nseed: 3\n")->section, "seed");
    const auto longer = first_case_file_difference("name: x\n", "name: x\nseed: 3\n");
    ASSERT_TRUE(longer.has_value());
    EXPECT_EQ(longer->line, 2u);
    EXPECT_EQ(longer->a_line, "");
}

TEST(TopicRoles, EveryTopicOfTheRigHasTheRoleItsNameGives) {
    EXPECT_EQ(topic_role("device/gnss/nmea"), TopicRole::device);
    EXPECT_EQ(topic_role("truth/nozzles"), TopicRole::truth);
    EXPECT_EQ(topic_role("actuator/nozzle_pwm/duty"), TopicRole::actuator);
    EXPECT_EQ(topic_role("controller/breakpoint_event"), TopicRole::controller);
    EXPECT_EQ(topic_role("rig/clock/tick"), TopicRole::clock);
    EXPECT_EQ(topic_role("devices/x"), TopicRole::other);
    EXPECT_EQ(to_string(TopicRole::actuator), "actuator");
}

}  // namespace
