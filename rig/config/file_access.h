#pragma once
// Reading files whose names come from users (case files, NMEA captures, the
// controller's breakpoint store) without trusting what the name points at.
//
// What a careless or hostile name can be, and what goes wrong without this:
// a FIFO blocks open() or read() forever, /dev/zero reads until memory runs
// out, a directory "opens" and then fails in odd ways, a symlink leads out of
// the directory the file was meant to be in. So: the type is checked before
// opening (a device is never opened, as opening some has side effects) and
// again on the open descriptor (the name may have been swapped in between;
// O_NONBLOCK keeps even that open from blocking), only regular files are
// read, and never more than a stated number of bytes.
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <stdexcept>
#include <streambuf>
#include <string>
#include <string_view>

namespace rig {

// A file that cannot be used. what() is "PATH: PROBLEM", e.g.
//   cases/x.yaml: is a FIFO (named pipe), expected a regular file
class FileAccessError : public std::runtime_error {
public:
    FileAccessError(std::filesystem::path path, std::string problem, int error_number = 0);
    const std::filesystem::path& path() const { return path_; }
    const std::string& problem() const { return problem_; }
    // errno of the failing call (ENOENT for a missing file); 0 for a wrong type or size.
    int error_number() const { return error_number_; }

private:
    std::filesystem::path path_;
    std::string problem_;
    int error_number_;
};

// "a directory", "a FIFO (named pipe)", "a character device", ... for st_mode.
std::string describe_file_type(unsigned int st_mode);

// Owns a POSIX file descriptor.
class FileDescriptor {
public:
    FileDescriptor() = default;
    explicit FileDescriptor(int fd) : fd_(fd) {}
    FileDescriptor(FileDescriptor&& other) noexcept : fd_(other.release()) {}
    FileDescriptor& operator=(FileDescriptor&& other) noexcept;
    FileDescriptor(const FileDescriptor&) = delete;
    FileDescriptor& operator=(const FileDescriptor&) = delete;
    ~FileDescriptor();
    int get() const { return fd_; }
    int release();
    // Closes now and returns close()'s result (it can report a deferred write error).
    int close_now();

private:
    int fd_ = -1;
};

struct OpenOptions {
    // Refuse a symbolic link as the last component (O_NOFOLLOW): for files that
    // must stay inside a directory.
    bool no_follow = false;
    // Larger files are refused (checked on the size and again while reading).
    std::uint64_t max_bytes = 0;
    // What the file is, for messages: "case file", "breakpoint store".
    std::string_view what = "file";
};

// Opens `name` (relative to `dir_fd`, or AT_FDCWD) for reading if it is a
// regular file no larger than options.max_bytes; `display` is what errors call
// it. Throws FileAccessError.
FileDescriptor open_regular_file(int dir_fd, const std::filesystem::path& name, const OpenOptions& options,
                                 const std::filesystem::path& display);
// Reads a descriptor from open_regular_file() to its end; refuses more than max_bytes.
std::string read_all(const FileDescriptor& fd, const OpenOptions& options, const std::filesystem::path& display);
// Both: the whole content of a regular file.
std::string read_regular_file(const std::filesystem::path& path, const OpenOptions& options);

// An input stream buffer over a descriptor (for streaming a large capture
// line by line); does not own it.
class FdInputBuffer : public std::streambuf {
public:
    explicit FdInputBuffer(int fd) : fd_(fd) {}
    // errno of a failed read (which ended the input), else 0.
    int read_error() const { return read_error_; }

protected:
    int_type underflow() override;

private:
    int fd_;
    int read_error_ = 0;
    char buffer_[8192];
};

// Empty when `name` can be a file name inside a directory the program owns;
// otherwise why not. Allowed: letters, digits, '.', '_', '-', at most
// max_length characters, not starting with '.' (that excludes "." and "..",
// which are directories of the path, and hidden names). So the name has no
// '/': it cannot reach outside the directory it is joined to.
std::string plain_file_name_problem(std::string_view name, std::size_t max_length);

}  // namespace rig
