#include "controller/breakpoint_store.h"

#include <fcntl.h>
#include <stdio.h>  // renameat2, RENAME_NOREPLACE (glibc 2.28)
#include <unistd.h>

#include <array>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <limits>
#include <optional>
#include <system_error>
#include <type_traits>
#include <unordered_set>
#include <utility>

#include "rig/config/file_access.h"
#include "rig/text/number_text.h"

namespace rig::controller {

using rig::FileAccessError;
using rig::FileDescriptor;
using rig::OpenOptions;

namespace {

constexpr std::string_view kHeaderPrefix = "rig-breakpoint-store v1 next_id=";
constexpr std::string_view kRecordTag = "bp";
constexpr std::string_view kChecksumPrefix = "crc32 ";
constexpr std::size_t kChecksumHexDigits = 8;

// What is wrong with a store file, and on which line (1-based).
struct CorruptStore {
    int line;
    std::string problem;
};

struct StoreContents {
    std::vector<StoredBreakpoint> breakpoints;
    std::unordered_set<std::uint32_t> ids;  // of breakpoints, for the duplicate check
    std::uint32_t next_id = 1;
};

[[noreturn]] void throw_errno(const std::string& what) {
    throw std::system_error(errno, std::generic_category(), "breakpoint store: " + what);
}

// Shortest text that reads back as exactly `value`, locale-independent.
std::string format_double(double value) { return shortest_text(value); }

std::string format_crc(std::uint32_t crc) {
    std::array<char, kChecksumHexDigits> digits{};
    for (std::size_t i = 0; i < digits.size(); ++i) {
        digits[digits.size() - 1 - i] = "0123456789abcdef"[(crc >> (4 * i)) & 0xfu];
    }
    return std::string(digits.data(), digits.size());
}

std::string serialize(const std::vector<StoredBreakpoint>& breakpoints, std::uint32_t next_id) {
    std::string text;
    text += kHeaderPrefix;
    text += std::to_string(next_id);
    text += '\n';
    for (const StoredBreakpoint& breakpoint : breakpoints) {
        text += kRecordTag;
        text += ' ' + std::to_string(breakpoint.id);
        text += ' ' + format_double(breakpoint.lat_deg);
        text += ' ' + format_double(breakpoint.lon_deg);
        text += ' ' + format_double(breakpoint.course_deg);
        text += '\n';
    }
    const std::uint32_t crc = crc32_ieee(text);
    text += kChecksumPrefix;
    text += format_crc(crc);
    text += '\n';
    return text;
}

// Whole-token number parsing; std::from_chars is locale-independent.
template <typename Number>
bool parse_number(std::string_view token, Number& value, int integer_base = 10) {
    const char* const first = token.data();
    const char* const last = token.data() + token.size();
    std::from_chars_result result{};
    if constexpr (std::is_floating_point_v<Number>) {
        result = std::from_chars(first, last, value);
    } else {
        result = std::from_chars(first, last, value, integer_base);
    }
    return !token.empty() && result.ec == std::errc() && result.ptr == last;
}

std::vector<std::string_view> split_on_spaces(std::string_view line) {
    std::vector<std::string_view> fields;
    std::size_t start = 0;
    while (true) {
        const std::size_t space = line.find(' ', start);
        fields.push_back(line.substr(start, space == std::string_view::npos ? std::string_view::npos : space - start));
        if (space == std::string_view::npos) return fields;
        start = space + 1;
    }
}

bool valid_position(double lat_deg, double lon_deg) {
    return std::isfinite(lat_deg) && std::isfinite(lon_deg) && std::abs(lat_deg) <= 90.0 && std::abs(lon_deg) <= 180.0;
}

StoredBreakpoint parse_record(std::string_view line, int line_number, StoreContents& so_far) {
    const std::vector<std::string_view> fields = split_on_spaces(line);
    if (fields.size() != 5 || fields[0] != kRecordTag) {
        throw CorruptStore{line_number, "expected `bp ID LAT_DEG LON_DEG COURSE_DEG`, got `" + std::string(line) + "`"};
    }
    StoredBreakpoint breakpoint;
    if (!parse_number(fields[1], breakpoint.id) || breakpoint.id == 0) {
        throw CorruptStore{line_number, "bad breakpoint id `" + std::string(fields[1]) + "`"};
    }
    if (!parse_number(fields[2], breakpoint.lat_deg) || !parse_number(fields[3], breakpoint.lon_deg) ||
        !valid_position(breakpoint.lat_deg, breakpoint.lon_deg)) {
        throw CorruptStore{line_number, "bad position `" + std::string(fields[2]) + " " + std::string(fields[3]) + "`"};
    }
    if (!parse_number(fields[4], breakpoint.course_deg) || !(breakpoint.course_deg >= 0.0) ||
        !(breakpoint.course_deg < 360.0)) {
        throw CorruptStore{line_number, "bad course `" + std::string(fields[4]) + "`"};
    }
    if (breakpoint.id >= so_far.next_id) {
        throw CorruptStore{line_number, "breakpoint id " + std::to_string(breakpoint.id) + " is not below next_id " +
                                            std::to_string(so_far.next_id)};
    }
    // Hashed: a list scan made loading n records O(n^2) (400,000 records: 82 s).
    if (!so_far.ids.insert(breakpoint.id).second) {
        throw CorruptStore{line_number, "duplicate breakpoint id " + std::to_string(breakpoint.id)};
    }
    return breakpoint;
}

// Parses a whole store file; throws CorruptStore.
StoreContents parse(std::string_view text) {
    if (text.empty()) throw CorruptStore{1, "empty file (expected the header line)"};
    StoreContents contents;
    std::size_t line_start = 0;
    int line_number = 0;
    while (line_start < text.size()) {
        ++line_number;
        const std::size_t newline = text.find('\n', line_start);
        if (newline == std::string_view::npos) {
            throw CorruptStore{line_number, "last line is not terminated (file truncated by a torn write?)"};
        }
        const std::string_view line = text.substr(line_start, newline - line_start);
        const std::size_t next_line_start = newline + 1;

        if (line_number == 1) {
            if (!line.starts_with(kHeaderPrefix) ||
                !parse_number(line.substr(kHeaderPrefix.size()), contents.next_id) || contents.next_id == 0) {
                throw CorruptStore{1, "bad header `" + std::string(line) + "`, expected `" +
                                          std::string(kHeaderPrefix) + "N`"};
            }
        } else if (line.starts_with(kChecksumPrefix)) {
            const std::string_view digits = line.substr(kChecksumPrefix.size());
            std::uint32_t stored_crc = 0;
            if (digits.size() != kChecksumHexDigits || !parse_number(digits, stored_crc, 16)) {
                throw CorruptStore{line_number, "bad checksum line `" + std::string(line) + "`"};
            }
            const std::uint32_t actual_crc = crc32_ieee(text.substr(0, line_start));
            if (stored_crc != actual_crc) {
                throw CorruptStore{line_number, "checksum mismatch: file says " + format_crc(stored_crc) +
                                                    ", contents give " + format_crc(actual_crc)};
            }
            if (next_line_start != text.size()) {
                throw CorruptStore{line_number + 1, "text after the checksum line"};
            }
            return contents;
        } else {
            contents.breakpoints.push_back(parse_record(line, line_number, contents));
        }
        line_start = next_line_start;
    }
    throw CorruptStore{line_number + 1, "missing checksum line (file truncated by a torn write?)"};
}

// The directory the store lives in, open, so every name below is looked up in
// it and nowhere else (openat/renameat with a plain name cannot leave it).
FileDescriptor open_directory(const std::filesystem::path& directory) {
    const std::filesystem::path name = directory.empty() ? std::filesystem::path(".") : directory;
    FileDescriptor fd(::open(name.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC));
    if (fd.get() < 0) throw_errno("open state directory " + name.string());
    return fd;
}

// Contents of the store, or nullopt when there is none. Refuses anything but a
// regular file of at most kMaxStoreBytes (a FIFO would block the controller, a
// device such as /dev/zero fill its memory), and a symbolic link (it could lead
// out of the state directory).
std::optional<std::string> read_store(int dir_fd, const std::string& name, const std::filesystem::path& display) {
    const OpenOptions options{.no_follow = true, .max_bytes = kMaxStoreBytes, .what = "breakpoint store"};
    try {
        const FileDescriptor fd = open_regular_file(dir_fd, name, options, display);
        return read_all(fd, options, display);
    } catch (const FileAccessError& error) {
        if (error.error_number() == ENOENT) return std::nullopt;
        throw BreakpointStoreFileError(display, error.problem() + "; not loaded, left as it is");
    }
}

void write_all(int fd, std::string_view bytes, const std::filesystem::path& file) {
    while (!bytes.empty()) {
        const ssize_t count = ::write(fd, bytes.data(), bytes.size());
        if (count < 0) {
            if (errno == EINTR) continue;
            throw_errno("write " + file.string());
        }
        bytes.remove_prefix(static_cast<std::size_t>(count));
    }
}

// Renames a corrupt store to NAME.corrupt-N (first free N) in the same
// directory; returns the new path, or an empty path with `failure` set.
// RENAME_NOREPLACE: an existing NAME.corrupt-N is never overwritten, even one
// made between a check and the rename.
std::filesystem::path move_aside(int dir_fd, const std::filesystem::path& directory, const std::string& name,
                                 std::string& failure) {
    for (int n = 1; n < 1000; ++n) {
        const std::string candidate = name + ".corrupt-" + std::to_string(n);
        if (::renameat2(dir_fd, name.c_str(), dir_fd, candidate.c_str(), RENAME_NOREPLACE) == 0) {
            return directory / candidate;
        }
        if (errno != EEXIST) {
            failure = std::strerror(errno);
            return {};
        }
    }
    failure = "no free .corrupt-N name below 1000";
    return {};
}

std::string describe_failure(const std::filesystem::path& file, int line, const std::string& problem,
                             const std::filesystem::path& kept_as) {
    std::string text = file.string() + ":" + std::to_string(line) + ": " + problem;
    if (!kept_as.empty()) text += "; moved aside to " + kept_as.string();
    return text;
}

}  // namespace

BreakpointStoreError::BreakpointStoreError(std::filesystem::path file, int line, std::string problem,
                                           std::filesystem::path kept_as)
    : std::runtime_error(describe_failure(file, line, problem, kept_as)),
      file_(std::move(file)),
      line_(line),
      problem_(std::move(problem)),
      kept_as_(std::move(kept_as)) {}

std::uint32_t crc32_ieee(std::string_view bytes) {
    // Bitwise form: stores are a few hundred bytes, a table would buy nothing.
    std::uint32_t crc = 0xffffffffu;
    for (const char character : bytes) {
        crc ^= static_cast<unsigned char>(character);
        for (int bit = 0; bit < 8; ++bit) crc = (crc >> 1) ^ (0xedb88320u & (0u - (crc & 1u)));
    }
    return crc ^ 0xffffffffu;
}

BreakpointStore::BreakpointStore(std::filesystem::path file)
    : file_(std::move(file)), directory_(file_.parent_path()), name_(file_.filename().string()) {
    if (const std::string problem = breakpoint_store_name_problem(name_); !problem.empty()) {
        throw std::invalid_argument("breakpoint store " + file_.string() + ": the file name " + problem);
    }
}

BreakpointStoreFileError::BreakpointStoreFileError(const std::filesystem::path& file, const std::string& problem)
    : std::runtime_error("breakpoint store " + file.string() + ": " + problem) {}

void BreakpointStore::load() {
    const FileDescriptor directory = open_directory(directory_);
    const std::optional<std::string> text = read_store(directory.get(), name_, file_);
    if (!text) {
        breakpoints_.clear();
        next_id_ = 1;
        return;
    }
    StoreContents contents;
    try {
        contents = parse(*text);
    } catch (const CorruptStore& corrupt) {
        std::string move_failure;
        const std::filesystem::path kept_as = move_aside(directory.get(), directory_, name_, move_failure);
        std::string problem = corrupt.problem;
        if (kept_as.empty()) problem += "; could not move it aside (" + move_failure + "), left in place";
        throw BreakpointStoreError(file_, corrupt.line, problem, kept_as);
    }
    breakpoints_ = std::move(contents.breakpoints);
    next_id_ = contents.next_id;
}

StoredBreakpoint BreakpointStore::add(double lat_deg, double lon_deg, double course_deg) {
    if (!valid_position(lat_deg, lon_deg)) {
        throw std::invalid_argument("breakpoint store: position " + std::to_string(lat_deg) + ", " +
                                    std::to_string(lon_deg) + " is not a valid latitude/longitude");
    }
    if (!std::isfinite(course_deg)) throw std::invalid_argument("breakpoint store: course must be finite");
    if (next_id_ == std::numeric_limits<std::uint32_t>::max()) {
        throw std::overflow_error("breakpoint store: breakpoint ids exhausted");
    }
    double wrapped_course_deg = std::fmod(course_deg, 360.0);
    if (wrapped_course_deg < 0.0) wrapped_course_deg += 360.0;
    // fmod of a tiny negative number plus 360 can round up to exactly 360.
    if (wrapped_course_deg >= 360.0) wrapped_course_deg = 0.0;
    const StoredBreakpoint breakpoint{next_id_, lat_deg, lon_deg, wrapped_course_deg};
    breakpoints_.push_back(breakpoint);
    ++next_id_;
    return breakpoint;
}

bool BreakpointStore::remove(std::uint32_t id) {
    for (auto it = breakpoints_.begin(); it != breakpoints_.end(); ++it) {
        if (it->id == id) {
            breakpoints_.erase(it);
            return true;
        }
    }
    return false;
}

void BreakpointStore::save() const {
    const std::string text = serialize(breakpoints_, next_id_);
    const FileDescriptor directory = open_directory(directory_);
    const std::string temporary = name_ + ".tmp";
    const std::filesystem::path temporary_path = directory_ / temporary;
    // A leftover NAME.tmp (or anything an intruder put there: a symlink, a FIFO)
    // is removed, and the new one created exclusively: the write lands in a
    // fresh regular file inside the state directory, never through a link.
    if (::unlinkat(directory.get(), temporary.c_str(), 0) != 0 && errno != ENOENT) {
        throw_errno("remove " + temporary_path.string());
    }
    try {
        FileDescriptor fd(::openat(directory.get(), temporary.c_str(),
                                   O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC, 0644));
        if (fd.get() < 0) throw_errno("create " + temporary_path.string());
        write_all(fd.get(), text, temporary_path);
        // The data must be on the medium before the rename can publish it;
        // otherwise a power cut could leave FILE naming an empty or partial file.
        if (::fsync(fd.get()) != 0) throw_errno("fsync " + temporary_path.string());
        if (fd.close_now() != 0) throw_errno("close " + temporary_path.string());
    } catch (...) {
        ::unlinkat(directory.get(), temporary.c_str(), 0);  // best effort; FILE itself is untouched
        throw;
    }
    if (::renameat(directory.get(), temporary.c_str(), directory.get(), name_.c_str()) != 0) {
        throw_errno("rename " + temporary_path.string() + " over " + file_.string());
    }
    // Makes the rename itself durable: without it a power cut could bring back
    // the old directory entry (still a complete store, but a lost save).
    if (::fsync(directory.get()) != 0) throw_errno("fsync directory " + directory_.string());
}

std::string format_store_text(const StoreText& contents) { return serialize(contents.breakpoints, contents.next_id); }

StoreText parse_store_text(std::string_view text) {
    try {
        StoreContents contents = parse(text);
        return StoreText{std::move(contents.breakpoints), contents.next_id};
    } catch (const CorruptStore& corrupt) {
        throw BreakpointStoreError("(text)", corrupt.line, corrupt.problem, {});
    }
}

std::string breakpoint_store_name_problem(std::string_view name) {
    // Room for the ".corrupt-N" and ".tmp" siblings within NAME_MAX (255).
    return plain_file_name_problem(name, 200);
}

}  // namespace rig::controller
