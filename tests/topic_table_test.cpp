// The topic table is written twice: idl/topics.h for C++ and idl/topics.json
// for programs in other languages (the Cyclone DDS follower reads it). They
// must say the same: every constant, name and type, nothing more in either.
#include <gtest/gtest.h>

#include "run_support.h"

#include <map>
#include <regex>
#include <string>

#include <nlohmann/json.hpp>

#include "idl/topics.h"

namespace {

struct Topic {
    std::string name;
    std::string type;
    friend bool operator==(const Topic&, const Topic&) = default;
};

TEST(TopicTable, TheHeaderAndTheJsonFileSayTheSame) {
    // From the header's lines: inline constexpr const char* kName = "topic";  // msg::Type
    std::map<std::string, Topic> from_header;
    const std::regex line(R"re(inline constexpr const char\* (k\w+) = "([^"]+)";\s*// msg::(\w+))re");
    const std::string header = rig::testing::read_all(RIG_SOURCE_DIR "/idl/topics.h");
    for (auto it = std::sregex_iterator(header.begin(), header.end(), line); it != std::sregex_iterator(); ++it) {
        from_header[(*it)[1]] = Topic{(*it)[2], "rig::msg::" + (*it)[3].str()};
    }
    ASSERT_GT(from_header.size(), 20u) << "the header's lines were not found";

    const nlohmann::json table = nlohmann::json::parse(rig::testing::read_all(RIG_SOURCE_DIR "/idl/topics.json"));
    std::map<std::string, Topic> from_json;
    for (const nlohmann::json& topic : table.at("topics")) {
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

}  // namespace
