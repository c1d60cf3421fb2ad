#include "harness/trace/trace_mcap.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <functional>
#include <iostream>
#include <map>
#include <memory>
#include <set>
#include <stdexcept>

#include "harness/trace/mcap_writer.h"
#include "harness/trace/trace_reader.h"
#include "rig/runtime/version.h"

namespace rig::harness {

namespace fs = std::filesystem;

namespace {

// What a topic's JSON samples look like, merged over all of them.
struct JsonShape {
    std::set<std::string> types;
    std::map<std::string, JsonShape> properties;
    std::unique_ptr<JsonShape> items;

    void merge(const nlohmann::json& value) {
        switch (value.type()) {
            case nlohmann::json::value_t::null: types.insert("null"); break;
            case nlohmann::json::value_t::boolean: types.insert("boolean"); break;
            case nlohmann::json::value_t::number_integer:
            case nlohmann::json::value_t::number_unsigned: types.insert("integer"); break;
            case nlohmann::json::value_t::number_float: types.insert("number"); break;
            case nlohmann::json::value_t::string: types.insert("string"); break;
            case nlohmann::json::value_t::array:
                types.insert("array");
                if (!items) items = std::make_unique<JsonShape>();
                for (const nlohmann::json& item : value) items->merge(item);
                break;
            case nlohmann::json::value_t::object:
                types.insert("object");
                for (const auto& [key, field] : value.items()) properties[key].merge(field);
                break;
            default: types.insert("string"); break;  // binary and discarded: not produced by the trace
        }
    }

    nlohmann::json schema() const {
        std::set<std::string> names = types;
        if (names.count("number") != 0) names.erase("integer");  // 1 and 1.5 on one field: a number
        nlohmann::json out = nlohmann::json::object();
        if (names.size() == 1) out["type"] = *names.begin();
        else if (!names.empty()) out["type"] = std::vector<std::string>(names.begin(), names.end());
        if (!properties.empty()) {
            nlohmann::json fields = nlohmann::json::object();
            for (const auto& [key, field] : properties) fields[key] = field.schema();
            out["properties"] = std::move(fields);
        }
        if (items && !items->types.empty()) out["items"] = items->schema();
        return out;
    }
};

nlohmann::json titled_schema(const JsonShape& shape, const std::string& title) {
    nlohmann::json schema = shape.schema();
    schema["$schema"] = "https://json-schema.org/draft/2020-12/schema";
    schema["title"] = title;
    return schema;
}

std::string text_column(sqlite3_stmt* row, int column) { return TraceReader::text(row, column); }

std::uint64_t time_column(sqlite3_stmt* row, int column) {
    return static_cast<std::uint64_t>(std::max<std::int64_t>(0, TraceReader::integer(row, column)));
}

}  // namespace

std::string json_schema_of(const std::vector<std::string>& samples, const std::string& title) {
    JsonShape shape;
    for (const std::string& sample : samples) shape.merge(nlohmann::json::parse(sample));
    return titled_schema(shape, title).dump();
}

TraceMcapSummary write_trace_mcap(const fs::path& trace, const fs::path& mcap) {
    TraceReader reader(trace);
    if (!reader.has_table("samples") || !reader.has_table("meta")) {
        throw std::runtime_error(trace.string() + ": no samples or meta table: not a trace of this rig");
    }
    // Pass 1: each channel's shape, and the DDS type its writer announced when discovery saw it.
    std::map<std::string, JsonShape> shapes;
    reader.rows("select topic, json from samples", [&](sqlite3_stmt* row) {
        shapes[text_column(row, 0)].merge(nlohmann::json::parse(text_column(row, 1)));
    });
    const bool has_foreign = reader.has_table("foreign_samples");
    if (has_foreign) {
        reader.rows("select participant, topic, json from foreign_samples", [&](sqlite3_stmt* row) {
            shapes["foreign/" + text_column(row, 0) + "/" + text_column(row, 1)].merge(
                nlohmann::json::parse(text_column(row, 2)));
        });
    }
    std::map<std::string, std::string> dds_types;
    if (reader.has_table("discovery")) {
        reader.rows("select topic, type from discovery where type != ''",
                    [&](sqlite3_stmt* row) { dds_types.emplace(text_column(row, 0), text_column(row, 1)); });
    }

    McapWriter writer(mcap, "", std::string("rig ") + RIG_VERSION_STRING + " (sprayer HIL rig trace)");
    std::map<std::string, std::uint16_t> channel_of;
    std::map<std::uint16_t, std::uint32_t> sequence_of;
    for (const auto& [channel, shape] : shapes) {
        const std::string topic = channel.rfind("foreign/", 0) == 0 ? channel.substr(channel.rfind('/') + 1) : channel;
        const auto type = dds_types.find(topic);
        const std::string title = type != dds_types.end() ? type->second : "rig trace JSON of " + topic;
        const std::uint16_t schema = writer.add_schema(title, "jsonschema", titled_schema(shape, title).dump());
        std::map<std::string, std::string> metadata = {{"trace_topic", topic}};
        if (type != dds_types.end()) metadata["dds_type"] = type->second;
        channel_of[channel] = writer.add_channel(schema, channel, "json", metadata);
    }
    // Pass 2: the messages, in the order the rounds delivered them.
    const auto add = [&](const std::string& channel, std::uint64_t t_ns, const std::string& json) {
        const std::uint16_t id = channel_of.at(channel);
        writer.add_message(id, sequence_of[id]++, t_ns, t_ns, json);
    };
    reader.rows("select t_ns, topic, json from samples order by rowid", [&](sqlite3_stmt* row) {
        add(text_column(row, 1), time_column(row, 0), text_column(row, 2));
    });
    if (has_foreign) {
        reader.rows("select t_ns, participant, topic, json from foreign_samples order by rowid", [&](sqlite3_stmt* row) {
            add("foreign/" + text_column(row, 1) + "/" + text_column(row, 2), time_column(row, 0), text_column(row, 3));
        });
    }
    std::map<std::string, std::string> meta;
    reader.rows("select key, value from meta", [&](sqlite3_stmt* row) { meta[text_column(row, 0)] = text_column(row, 1); });
    writer.add_metadata("rig.trace.meta", meta);
    writer.close();
    return {writer.message_count(), channel_of.size()};
}

}  // namespace rig::harness
