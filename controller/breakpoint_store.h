#pragma once
// The controller's breakpoint store, persisted to one file: the paper's SD card
// (seed 000 sec. 2.5.1: breakpoint coordinates are stored and survive until the
// sprayer comes back to them, possibly after a power cut).
//
// File format (text, one record per line, every line ending in '\n'):
//   rig-breakpoint-store v1 next_id=4
//   bp 1 40.180001234 116.44 90
//   bp 3 40.18 116.440023 270
//   crc32 ee5830ba
// Record fields: id, latitude and longitude in degrees (WGS84, as the GNSS sent
// them), course in degrees [0, 360). Doubles are written in the shortest form
// that reads back to the same value (std::to_chars), so a save/load round trip is
// exact. next_id survives removals, so an id is never reused. The last line is
// the CRC-32 (IEEE 802.3) of every byte before it: a truncated or damaged file is
// detected instead of silently losing breakpoints.
//
// Crash safety: save() writes FILE.tmp, fsyncs it, renames it over FILE and
// fsyncs the directory. rename() replaces the name atomically, so a power cut or
// a kill at any instant leaves FILE holding either the previous or the new
// complete store (a leftover FILE.tmp is ignored and overwritten by the next
// save). One writer per file: two processes saving the same store concurrently
// is not supported.
//
// A corrupt FILE is never dropped: load() renames it to FILE.corrupt-N (the first
// N from 1 that is free) and throws BreakpointStoreError naming the file and line.
//
// Confinement: FILE is DIR/NAME with NAME a plain file name (no '/', not '.' or
// '..'; breakpoint_store_name_problem()); every file the store touches (NAME,
// NAME.tmp, NAME.corrupt-N) is opened or renamed relative to DIR, without
// following a symbolic link. Only a regular file of at most kMaxStoreBytes is
// read: anything else (a FIFO, a device, a directory, a symlink, a larger file)
// is refused with BreakpointStoreFileError and left as it is.
#include <cstdint>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace rig::controller {

// A store holds the breakpoints of unfinished rows: a handful in the field.
// 32 MiB is over 700,000 records, far beyond any, and bounds the memory and
// time a wrong file can take.
inline constexpr std::uint64_t kMaxStoreBytes = 32u << 20;

// Empty when `name` can be a store file name (a plain name, see above), else why not.
std::string breakpoint_store_name_problem(std::string_view name);

struct StoredBreakpoint {
    std::uint32_t id = 0;
    double lat_deg = 0.0;
    double lon_deg = 0.0;
    double course_deg = 0.0;  // sprayer course when the breakpoint was stored
    bool operator==(const StoredBreakpoint&) const = default;
};

// A store file that cannot be read back. what() is
//   FILE:LINE: PROBLEM; moved aside to FILE.corrupt-N
class BreakpointStoreError : public std::runtime_error {
public:
    BreakpointStoreError(std::filesystem::path file, int line, std::string problem, std::filesystem::path kept_as);
    const std::filesystem::path& file() const { return file_; }
    int line() const { return line_; }  // 1-based
    const std::string& problem() const { return problem_; }
    // Where the corrupt file now is; empty if moving it aside failed (then it is
    // still at file() and what() says why).
    const std::filesystem::path& kept_as() const { return kept_as_; }

private:
    std::filesystem::path file_;
    int line_;
    std::string problem_;
    std::filesystem::path kept_as_;
};

// A store file that is not a store at all (not a regular file, too large) or
// cannot be read. what(): "breakpoint store FILE: is a FIFO (named pipe), ...".
class BreakpointStoreFileError : public std::runtime_error {
public:
    BreakpointStoreFileError(const std::filesystem::path& file, const std::string& problem);
};

class BreakpointStore {
public:
    // Nothing is read until load(); a new store is empty. Throws
    // std::invalid_argument when file's name is not a plain file name.
    explicit BreakpointStore(std::filesystem::path file);

    // Replaces the contents with the file's. A missing file is an empty store.
    // A corrupt one is moved aside and BreakpointStoreError is thrown; one that
    // is no store file, BreakpointStoreFileError; the in-memory contents are
    // then unchanged. I/O failures throw std::system_error.
    void load();

    // Appends a breakpoint with the next free id and returns it (course wrapped
    // to [0, 360)). Throws std::invalid_argument for a latitude outside
    // [-90, 90], a longitude outside [-180, 180] or non-finite values.
    // Changes memory only; call save() to persist.
    StoredBreakpoint add(double lat_deg, double lon_deg, double course_deg);
    // Removes the breakpoint with this id; false if there is none.
    bool remove(std::uint32_t id);
    // In the order they were added.
    const std::vector<StoredBreakpoint>& list() const { return breakpoints_; }
    std::uint32_t next_id() const { return next_id_; }

    // Atomically replaces the file with the current contents (see above).
    // Throws std::system_error on an I/O failure; the old file is then intact.
    void save() const;

    const std::filesystem::path& path() const { return file_; }

private:
    std::filesystem::path file_;
    std::filesystem::path directory_;  // file_'s directory ("" = the current one)
    std::string name_;                 // file_'s name in it
    std::vector<StoredBreakpoint> breakpoints_;
    std::uint32_t next_id_ = 1;
};

// A store file's text, as save() writes it and load() reads it (without the
// file): for tests and the fuzzer. parse_store_text() throws
// BreakpointStoreError (file "(text)", no kept_as) naming the line.
struct StoreText {
    std::vector<StoredBreakpoint> breakpoints;
    std::uint32_t next_id = 1;
};
std::string format_store_text(const StoreText& contents);
StoreText parse_store_text(std::string_view text);

// CRC-32 as in IEEE 802.3 / zlib (reflected polynomial 0xEDB88320, initial and
// final XOR 0xFFFFFFFF); crc32_ieee("123456789") == 0xCBF43926.
std::uint32_t crc32_ieee(std::string_view bytes);

}  // namespace rig::controller
