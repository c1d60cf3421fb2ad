#include "harness/trace/mcap_writer.h"

#include <array>
#include <stdexcept>

namespace rig::harness {

namespace {

// Opcodes (MCAP specification, "Records").
constexpr std::uint8_t kHeader = 0x01;
constexpr std::uint8_t kFooter = 0x02;
constexpr std::uint8_t kSchema = 0x03;
constexpr std::uint8_t kChannel = 0x04;
constexpr std::uint8_t kMessage = 0x05;
constexpr std::uint8_t kChunk = 0x06;
constexpr std::uint8_t kMessageIndex = 0x07;
constexpr std::uint8_t kChunkIndex = 0x08;
constexpr std::uint8_t kStatistics = 0x0B;
constexpr std::uint8_t kMetadata = 0x0C;
constexpr std::uint8_t kMetadataIndex = 0x0D;
constexpr std::uint8_t kSummaryOffset = 0x0E;
constexpr std::uint8_t kDataEnd = 0x0F;
// 0x89 "MCAP" then the format version '0', CR LF.
constexpr char kMagic[] = {'\x89', 'M', 'C', 'A', 'P', '0', '\r', '\n'};

// Serialization: little-endian integers, uint32-length-prefixed strings, maps and arrays.
void put_u8(std::string& out, std::uint8_t value) { out.push_back(static_cast<char>(value)); }
template <typename Unsigned>
void put_le(std::string& out, Unsigned value) {
    for (std::size_t i = 0; i < sizeof(Unsigned); ++i) out.push_back(static_cast<char>((value >> (8 * i)) & 0xff));
}
void put_u16(std::string& out, std::uint16_t value) { put_le(out, value); }
void put_u32(std::string& out, std::uint32_t value) { put_le(out, value); }
void put_u64(std::string& out, std::uint64_t value) { put_le(out, value); }
void put_string(std::string& out, const std::string& text) {
    if (text.size() > UINT32_MAX) throw std::runtime_error("MCAP: a string longer than 4 GiB");
    put_u32(out, static_cast<std::uint32_t>(text.size()));
    out += text;
}
void put_string_map(std::string& out, const std::map<std::string, std::string>& map) {
    std::string entries;
    for (const auto& [key, value] : map) {
        put_string(entries, key);
        put_string(entries, value);
    }
    put_string(out, entries);  // a map is its entries' byte length, then the entries
}
void put_u16_u64_map(std::string& out, const std::map<std::uint16_t, std::uint64_t>& map) {
    std::string entries;
    for (const auto& [key, value] : map) {
        put_u16(entries, key);
        put_u64(entries, value);
    }
    put_string(out, entries);
}
std::string record(std::uint8_t opcode, const std::string& content) {
    std::string bytes;
    bytes.reserve(content.size() + 9);
    put_u8(bytes, opcode);
    put_u64(bytes, content.size());
    bytes += content;
    return bytes;
}

const std::array<std::uint32_t, 256>& crc_table() {
    static const std::array<std::uint32_t, 256> table = [] {
        std::array<std::uint32_t, 256> entries{};
        for (std::uint32_t byte = 0; byte < 256; ++byte) {
            std::uint32_t crc = byte;
            for (int bit = 0; bit < 8; ++bit) crc = (crc & 1) != 0 ? 0xEDB88320u ^ (crc >> 1) : crc >> 1;
            entries[byte] = crc;
        }
        return entries;
    }();
    return table;
}

}  // namespace

std::uint32_t crc32_update(std::uint32_t crc, const void* data, std::size_t size) {
    const auto& table = crc_table();
    const auto* bytes = static_cast<const unsigned char*>(data);
    crc = ~crc;
    for (std::size_t i = 0; i < size; ++i) crc = table[(crc ^ bytes[i]) & 0xff] ^ (crc >> 8);
    return ~crc;
}

McapWriter::McapWriter(const std::filesystem::path& file, const std::string& profile, const std::string& library,
                       std::size_t chunk_bytes)
    : file_(file), out_(file, std::ios::binary | std::ios::trunc), chunk_bytes_(chunk_bytes) {
    if (!out_) throw std::runtime_error("MCAP " + file.string() + ": cannot open for writing");
    write_raw(std::string(kMagic, sizeof kMagic));
    std::string header;
    put_string(header, profile);
    put_string(header, library);
    write_record(kHeader, header);
}

McapWriter::~McapWriter() {
    if (closed_) return;
    try {
        close();
    } catch (const std::exception&) {  // the caller that wanted to know called close()
    }
}

void McapWriter::write_raw(const std::string& bytes) {
    out_.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    if (!out_) throw std::runtime_error("MCAP " + file_.string() + ": write failed at byte " + std::to_string(position_));
    data_crc_ = crc32_update(data_crc_, bytes.data(), bytes.size());
    position_ += bytes.size();
}

void McapWriter::write_record(std::uint8_t opcode, const std::string& content) { write_raw(record(opcode, content)); }

void McapWriter::chunk_record(std::uint8_t opcode, const std::string& content) { chunk_ += record(opcode, content); }

std::string McapWriter::schema_record(const Schema& schema) {
    std::string content;
    put_u16(content, schema.id);
    put_string(content, schema.name);
    put_string(content, schema.encoding);
    put_string(content, schema.data);  // uint32-length-prefixed bytes
    return content;
}

std::string McapWriter::channel_record(const Channel& channel) {
    std::string content;
    put_u16(content, channel.id);
    put_u16(content, channel.schema_id);
    put_string(content, channel.topic);
    put_string(content, channel.message_encoding);
    put_string_map(content, channel.metadata);
    return content;
}

std::uint16_t McapWriter::add_schema(const std::string& name, const std::string& encoding, const std::string& data) {
    if (schemas_.size() >= UINT16_MAX) throw std::runtime_error("MCAP: more than 65535 schemas");
    const Schema schema{static_cast<std::uint16_t>(schemas_.size() + 1), name, encoding, data};
    // In the data section before any chunk that uses it (the open chunk is written later).
    write_record(kSchema, schema_record(schema));
    schemas_.push_back(schema);
    return schema.id;
}

std::uint16_t McapWriter::add_channel(std::uint16_t schema_id, const std::string& topic,
                                      const std::string& message_encoding,
                                      const std::map<std::string, std::string>& metadata) {
    if (channels_.size() > UINT16_MAX) throw std::runtime_error("MCAP: more than 65536 channels");
    if (schema_id > schemas_.size()) throw std::invalid_argument("MCAP: channel " + topic + " names an unknown schema");
    const Channel channel{static_cast<std::uint16_t>(channels_.size()), schema_id, topic, message_encoding, metadata};
    write_record(kChannel, channel_record(channel));
    channels_.push_back(channel);
    return channel.id;
}

void McapWriter::add_message(std::uint16_t channel_id, std::uint32_t sequence, std::uint64_t log_time_ns,
                             std::uint64_t publish_time_ns, const std::string& data) {
    if (channel_id >= channels_.size()) throw std::invalid_argument("MCAP: message on an unknown channel");
    std::string content;
    content.reserve(data.size() + 22);
    put_u16(content, channel_id);
    put_u32(content, sequence);
    put_u64(content, log_time_ns);
    put_u64(content, publish_time_ns);
    content += data;  // the rest of the record
    chunk_message_index_[channel_id].emplace_back(log_time_ns, chunk_.size());
    chunk_record(kMessage, content);
    if (!chunk_has_messages_) {
        chunk_start_time_ = chunk_end_time_ = log_time_ns;
        chunk_has_messages_ = true;
    }
    chunk_start_time_ = std::min(chunk_start_time_, log_time_ns);
    chunk_end_time_ = std::max(chunk_end_time_, log_time_ns);
    if (message_count_ == 0) first_time_ = last_time_ = log_time_ns;
    first_time_ = std::min(first_time_, log_time_ns);
    last_time_ = std::max(last_time_, log_time_ns);
    ++message_count_;
    ++channel_message_counts_[channel_id];
    if (chunk_.size() >= chunk_bytes_) flush_chunk();
}

void McapWriter::flush_chunk() {
    if (chunk_.empty()) return;
    std::string content;
    put_u64(content, chunk_has_messages_ ? chunk_start_time_ : 0);
    put_u64(content, chunk_has_messages_ ? chunk_end_time_ : 0);
    put_u64(content, chunk_.size());                                   // uncompressed_size
    put_u32(content, crc32_update(0, chunk_.data(), chunk_.size()));   // uncompressed_crc
    put_string(content, "");                                           // no compression
    put_u64(content, chunk_.size());                                   // records: uint64-length-prefixed
    content += chunk_;
    ChunkIndex index{chunk_has_messages_ ? chunk_start_time_ : 0, chunk_has_messages_ ? chunk_end_time_ : 0,
                     position_, 0, {}, 0, chunk_.size()};
    write_record(kChunk, content);
    index.length = position_ - index.offset;
    // One Message Index per channel in the chunk, right after it.
    const std::uint64_t indexes_start = position_;
    for (const auto& [channel_id, entries] : chunk_message_index_) {
        std::string message_index;
        put_u16(message_index, channel_id);
        std::string pairs;
        for (const auto& [time, offset] : entries) {
            put_u64(pairs, time);
            put_u64(pairs, offset);
        }
        put_string(message_index, pairs);  // Array: byte length, then the tuples
        index.message_index_offsets[channel_id] = position_;
        write_record(kMessageIndex, message_index);
    }
    index.message_index_length = position_ - indexes_start;
    chunk_indexes_.push_back(std::move(index));
    chunk_.clear();
    chunk_message_index_.clear();
    chunk_has_messages_ = false;
}

void McapWriter::add_metadata(const std::string& name, const std::map<std::string, std::string>& metadata) {
    flush_chunk();  // not inside a chunk, and after the messages before it
    std::string content;
    put_string(content, name);
    put_string_map(content, metadata);
    const std::uint64_t offset = position_;
    write_record(kMetadata, content);
    metadata_indexes_.push_back({offset, position_ - offset, name});
}

void McapWriter::close() {
    if (closed_) return;
    closed_ = true;
    flush_chunk();
    // Data End carries the CRC of everything before it.
    std::string data_end;
    put_u32(data_end, data_crc_);
    write_record(kDataEnd, data_end);

    // The summary, grouped by opcode, each group's place kept for the summary offsets.
    const std::uint64_t summary_start = position_;
    std::uint32_t summary_crc = 0;
    std::vector<std::tuple<std::uint8_t, std::uint64_t, std::uint64_t>> groups;
    const auto summary_group = [&](std::uint8_t opcode, const std::vector<std::string>& contents) {
        if (contents.empty()) return;
        const std::uint64_t start = position_;
        for (const std::string& content : contents) {
            const std::string bytes = record(opcode, content);
            summary_crc = crc32_update(summary_crc, bytes.data(), bytes.size());
            write_raw(bytes);
        }
        groups.emplace_back(opcode, start, position_ - start);
    };
    std::vector<std::string> contents;
    for (const Schema& schema : schemas_) contents.push_back(schema_record(schema));
    summary_group(kSchema, contents);
    contents.clear();
    for (const Channel& channel : channels_) contents.push_back(channel_record(channel));
    summary_group(kChannel, contents);
    contents.clear();
    for (const ChunkIndex& index : chunk_indexes_) {
        std::string content;
        put_u64(content, index.start_time);
        put_u64(content, index.end_time);
        put_u64(content, index.offset);
        put_u64(content, index.length);
        put_u16_u64_map(content, index.message_index_offsets);
        put_u64(content, index.message_index_length);
        put_string(content, "");
        put_u64(content, index.records_size);  // compressed_size: uncompressed here
        put_u64(content, index.records_size);
        contents.push_back(std::move(content));
    }
    summary_group(kChunkIndex, contents);
    contents.clear();
    {
        std::string content;
        put_u64(content, message_count_);
        put_u16(content, static_cast<std::uint16_t>(schemas_.size()));
        put_u32(content, static_cast<std::uint32_t>(channels_.size()));
        put_u32(content, 0);  // attachments
        put_u32(content, static_cast<std::uint32_t>(metadata_indexes_.size()));
        put_u32(content, static_cast<std::uint32_t>(chunk_indexes_.size()));
        put_u64(content, message_count_ > 0 ? first_time_ : 0);
        put_u64(content, message_count_ > 0 ? last_time_ : 0);
        put_u16_u64_map(content, channel_message_counts_);
        contents.push_back(std::move(content));
    }
    summary_group(kStatistics, contents);
    contents.clear();
    for (const MetadataIndex& index : metadata_indexes_) {
        std::string content;
        put_u64(content, index.offset);
        put_u64(content, index.length);
        put_string(content, index.name);
        contents.push_back(std::move(content));
    }
    summary_group(kMetadataIndex, contents);

    const std::uint64_t summary_offset_start = position_;
    for (const auto& [opcode, start, length] : groups) {
        std::string content;
        put_u8(content, opcode);
        put_u64(content, start);
        put_u64(content, length);
        const std::string bytes = record(kSummaryOffset, content);
        summary_crc = crc32_update(summary_crc, bytes.data(), bytes.size());
        write_raw(bytes);
    }
    // The footer's CRC covers the summary through the footer's summary_offset_start field.
    std::string footer_head;
    put_u8(footer_head, kFooter);
    put_u64(footer_head, 8 + 8 + 4);
    put_u64(footer_head, summary_start);
    put_u64(footer_head, groups.empty() ? 0 : summary_offset_start);
    summary_crc = crc32_update(summary_crc, footer_head.data(), footer_head.size());
    std::string footer = footer_head;
    put_u32(footer, summary_crc);
    write_raw(footer);
    write_raw(std::string(kMagic, sizeof kMagic));
    out_.close();
    if (!out_) throw std::runtime_error("MCAP " + file_.string() + ": closing failed");
}

}  // namespace rig::harness
