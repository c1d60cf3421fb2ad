#pragma once
// An MCAP file writer (https://mcap.dev/spec, magic "MCAP0"), written from the
// specification for the rig's traces: schemas, channels and messages in
// uncompressed chunks, each followed by its message indexes; then Data End, a
// summary section (schemas, channels, chunk indexes, statistics, metadata
// indexes) with summary offsets, so indexed readers (Foxglove, the official
// @mcap/core reader) seek instead of scanning. Every CRC the format has is
// filled in: the chunks', the data section's and the summary's.
//
// Records are written as they come; only a chunk's records are held in memory
// until the chunk is full (chunk_bytes). Messages should come in log-time order
// (the trace's are): readers sort within a chunk but expect chunks in order.
#include <cstdint>
#include <fstream>
#include <filesystem>
#include <map>
#include <string>
#include <utility>
#include <vector>

namespace rig::harness {

// CRC-32 (IEEE 802.3, reflected, as zlib and MCAP use it), continued from `crc`.
std::uint32_t crc32_update(std::uint32_t crc, const void* data, std::size_t size);

class McapWriter {
public:
    // Opens (truncates) `file`; throws std::runtime_error naming it when it cannot.
    McapWriter(const std::filesystem::path& file, const std::string& profile, const std::string& library,
               std::size_t chunk_bytes = 1 << 20);
    ~McapWriter();
    McapWriter(const McapWriter&) = delete;
    McapWriter& operator=(const McapWriter&) = delete;

    // Returns the new schema's id (1, 2, ...).
    std::uint16_t add_schema(const std::string& name, const std::string& encoding, const std::string& data);
    // Returns the new channel's id (0, 1, ...); schema_id 0 = no schema.
    std::uint16_t add_channel(std::uint16_t schema_id, const std::string& topic, const std::string& message_encoding,
                              const std::map<std::string, std::string>& metadata = {});
    void add_message(std::uint16_t channel_id, std::uint32_t sequence, std::uint64_t log_time_ns,
                     std::uint64_t publish_time_ns, const std::string& data);
    // A Metadata record (name and string pairs), outside chunks, indexed in the summary.
    void add_metadata(const std::string& name, const std::map<std::string, std::string>& metadata);
    // Writes the last chunk, the summary and the footer; throws on a write error.
    // The destructor closes without throwing (a file left without its footer).
    void close();

    std::uint64_t message_count() const { return message_count_; }

private:
    struct Schema {
        std::uint16_t id;
        std::string name, encoding, data;
    };
    struct Channel {
        std::uint16_t id, schema_id;
        std::string topic, message_encoding;
        std::map<std::string, std::string> metadata;
    };
    struct ChunkIndex {
        std::uint64_t start_time, end_time, offset, length;
        std::map<std::uint16_t, std::uint64_t> message_index_offsets;
        std::uint64_t message_index_length, records_size;
    };
    struct MetadataIndex {
        std::uint64_t offset, length;
        std::string name;
    };

    static std::string schema_record(const Schema& schema);
    static std::string channel_record(const Channel& channel);
    // Appends a record to the file (outside chunks), keeping the data CRC.
    void write_record(std::uint8_t opcode, const std::string& content);
    void write_raw(const std::string& bytes);
    // Appends a record to the open chunk.
    void chunk_record(std::uint8_t opcode, const std::string& content);
    void flush_chunk();

    std::filesystem::path file_;
    std::ofstream out_;
    std::size_t chunk_bytes_;
    bool closed_ = false;
    std::uint64_t position_ = 0;
    std::uint32_t data_crc_ = 0;
    std::vector<Schema> schemas_;
    std::vector<Channel> channels_;
    std::vector<ChunkIndex> chunk_indexes_;
    std::vector<MetadataIndex> metadata_indexes_;
    // The open chunk: its records, time span and each channel's (log time, offset) pairs.
    std::string chunk_;
    std::uint64_t chunk_start_time_ = 0, chunk_end_time_ = 0;
    bool chunk_has_messages_ = false;
    std::map<std::uint16_t, std::vector<std::pair<std::uint64_t, std::uint64_t>>> chunk_message_index_;
    // Statistics.
    std::uint64_t message_count_ = 0;
    std::uint64_t first_time_ = 0, last_time_ = 0;
    std::map<std::uint16_t, std::uint64_t> channel_message_counts_;
};

}  // namespace rig::harness
