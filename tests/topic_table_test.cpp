// The topic table is written twice: idl/topics.h for C++ and idl/topics.json
// for programs in other languages (the Cyclone DDS follower reads it). They
// must say the same: every constant, name and type, nothing more in either;
// and no two topics share a name.
#include <gtest/gtest.h>

#include "run_support.h"

#include <map>
#include <regex>
#include <set>
#include <string>

#include <nlohmann/json.hpp>

#include "idl/topics.h"

namespace {

struct Topic {
    std::string name;
    std::string type;
    friend bool operator==(const Topic&, const Topic&) = default;
};

// idl/topics.json's list of every topic.
nlohmann::json topic_table() {
    return nlohmann::json::parse(rig::testing::read_all(RIG_SOURCE_DIR "/idl/topics.json")).at("topics");
}

TEST(TopicTable, TheHeaderAndTheJsonFileSayTheSame) {
    // From the header's lines: inline constexpr const char* kName = "topic";  // msg::Type
    std::map<std::string, Topic> from_header;
    const std::regex line(R"re(inline constexpr const char\* (k\w+) = "([^"]+)";\s*// msg::(\w+))re");
    const std::string header = rig::testing::read_all(RIG_SOURCE_DIR "/idl/topics.h");
    for (auto it = std::sregex_iterator(header.begin(), header.end(), line); it != std::sregex_iterator(); ++it) {
        from_header[(*it)[1]] = Topic{(*it)[2], "rig::msg::" + (*it)[3].str()};
    }
    ASSERT_GT(from_header.size(), 20u) << "the header's lines were not found";

    std::map<std::string, Topic> from_json;
    for (const nlohmann::json& topic : topic_table()) {
        from_json[topic.at("constant").get<std::string>()] =
            Topic{topic.at("name").get<std::string>(), topic.at("type").get<std::string>()};
        const std::string role = topic.at("role");
        EXPECT_TRUE(role == "clock" || role == "device" || role == "actuator" || role == "controller" ||
                    role == "truth" || role == "self_test")
            << role;
    }
    for (const auto& [constant, topic] : from_header) {
        ASSERT_TRUE(from_json.count(constant)) << constant << " is not in topics.json";
        EXPECT_EQ(from_json.at(constant), topic) << constant;
    }
    EXPECT_EQ(from_json.size(), from_header.size());
    // And the header's values are the compiled ones.
    EXPECT_EQ(from_header.at("kClockTick").name, rig::topics::kClockTick);
    EXPECT_EQ(from_header.at("kBreakpointEvent").name, rig::topics::kBreakpointEvent);
}

// Two topics of one name would be one DDS topic with two types or two meanings.
// Checked over the table itself, so a topic added later is checked too (the
// test above keeps the header's constants the same as the table's).
TEST(TopicTable, EveryTopicHasANameAndAConstantOfItsOwn) {
    const nlohmann::json topics = topic_table();
    ASSERT_GT(topics.size(), 20u) << "the table's topics were not found";
    std::map<std::string, std::string> constant_of_name;
    std::set<std::string> constants;
    for (const nlohmann::json& topic : topics) {
        const std::string name = topic.at("name");
        const std::string constant = topic.at("constant");
        const auto [first, inserted] = constant_of_name.emplace(name, constant);
        EXPECT_TRUE(inserted) << name << " is the name of both " << first->second << " and " << constant;
        EXPECT_TRUE(constants.insert(constant).second) << constant << " is in the table twice";
    }
    // Seed 001's topics (the compiled names) are among them.
    namespace t = rig::topics;
    for (const char* name : {t::kLaserHeightSerial, t::kCameraLeftFrame, t::kCameraRightFrame, t::kNozzlePwm,
                             t::kVisionReport, t::kVehicle2dTruth, t::kNozzlesTruth, t::kCameraViewTruth}) {
        EXPECT_EQ(constant_of_name.count(name), 1u) << name << " is not in topics.json";
    }
}

}  // namespace
