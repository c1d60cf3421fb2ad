#include "rig/config/file_access.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <utility>

namespace rig {

namespace {

std::string size_text(std::uint64_t bytes) {
    if (bytes >= (1u << 20) && bytes % (1u << 20) == 0) return std::to_string(bytes >> 20) + " MiB";
    return std::to_string(bytes) + " bytes";
}

[[noreturn]] void fail_errno(const std::filesystem::path& display, const std::string& action) {
    const int error = errno;
    if (error == ENOENT) throw FileAccessError(display, "no such file", error);
    throw FileAccessError(display, action + ": " + std::strerror(error), error);
}

void require_regular(const struct stat& status, const OpenOptions& options, const std::filesystem::path& display) {
    if (!S_ISREG(status.st_mode)) {
        throw FileAccessError(display, "is " + describe_file_type(status.st_mode) + ", expected a regular file (" +
                                           std::string(options.what) + ")");
    }
    if (static_cast<std::uint64_t>(status.st_size) > options.max_bytes) {
        throw FileAccessError(display, "is " + std::to_string(status.st_size) + " bytes, more than the " +
                                           size_text(options.max_bytes) + " a " + std::string(options.what) +
                                           " may have");
    }
}

}  // namespace

FileAccessError::FileAccessError(std::filesystem::path path, std::string problem, int error_number)
    : std::runtime_error(path.string() + ": " + problem),
      path_(std::move(path)),
      problem_(std::move(problem)),
      error_number_(error_number) {}

std::string describe_file_type(unsigned int st_mode) {
    if (S_ISREG(st_mode)) return "a regular file";
    if (S_ISDIR(st_mode)) return "a directory";
    if (S_ISFIFO(st_mode)) return "a FIFO (named pipe)";
    if (S_ISCHR(st_mode)) return "a character device";
    if (S_ISBLK(st_mode)) return "a block device";
    if (S_ISSOCK(st_mode)) return "a socket";
    if (S_ISLNK(st_mode)) return "a symbolic link";
    return "not a regular file";
}

FileDescriptor& FileDescriptor::operator=(FileDescriptor&& other) noexcept {
    if (this != &other) {
        if (fd_ >= 0) ::close(fd_);
        fd_ = other.release();
    }
    return *this;
}

FileDescriptor::~FileDescriptor() {
    if (fd_ >= 0) ::close(fd_);
}

int FileDescriptor::release() { return std::exchange(fd_, -1); }

int FileDescriptor::close_now() {
    const int result = ::close(fd_);
    fd_ = -1;
    return result;
}

FileDescriptor open_regular_file(int dir_fd, const std::filesystem::path& name, const OpenOptions& options,
                                 const std::filesystem::path& display) {
    // Look before opening: a device is never opened (opening a tape or a modem
    // line can do something), a FIFO never waits for a writer.
    struct stat before {};
    if (::fstatat(dir_fd, name.c_str(), &before, options.no_follow ? AT_SYMLINK_NOFOLLOW : 0) != 0) {
        fail_errno(display, "cannot examine");
    }
    require_regular(before, options, display);
    const int flags = O_RDONLY | O_CLOEXEC | O_NOCTTY | O_NONBLOCK | (options.no_follow ? O_NOFOLLOW : 0);
    FileDescriptor fd(::openat(dir_fd, name.c_str(), flags));
    if (fd.get() < 0) {
        if (errno == ELOOP && options.no_follow) {
            throw FileAccessError(display, "is a symbolic link, expected a regular file (" + std::string(options.what) +
                                               ")", ELOOP);
        }
        fail_errno(display, "cannot open");
    }
    // The name may have been replaced between the look and the open.
    struct stat opened {};
    if (::fstat(fd.get(), &opened) != 0) fail_errno(display, "cannot examine");
    require_regular(opened, options, display);
    return fd;
}

std::string read_all(const FileDescriptor& fd, const OpenOptions& options, const std::filesystem::path& display) {
    std::string text;
    char buffer[65536];
    while (true) {
        const ssize_t count = ::read(fd.get(), buffer, sizeof buffer);
        if (count < 0) {
            if (errno == EINTR) continue;
            fail_errno(display, "cannot read");
        }
        if (count == 0) return text;
        // A file that grows while it is read is held to the same limit.
        if (text.size() + static_cast<std::size_t>(count) > options.max_bytes) {
            throw FileAccessError(display, "grew past the " + size_text(options.max_bytes) + " a " +
                                               std::string(options.what) + " may have while it was read");
        }
        text.append(buffer, static_cast<std::size_t>(count));
    }
}

std::string read_regular_file(const std::filesystem::path& path, const OpenOptions& options) {
    const FileDescriptor fd = open_regular_file(AT_FDCWD, path, options, path);
    return read_all(fd, options, path);
}

FdInputBuffer::int_type FdInputBuffer::underflow() {
    if (gptr() < egptr()) return traits_type::to_int_type(*gptr());
    while (true) {
        const ssize_t count = ::read(fd_, buffer_, sizeof buffer_);
        if (count < 0 && errno == EINTR) continue;
        if (count < 0) read_error_ = errno;  // ends the input; the caller asks read_error()
        if (count <= 0) return traits_type::eof();
        setg(buffer_, buffer_, buffer_ + count);
        return traits_type::to_int_type(*gptr());
    }
}

std::string plain_file_name_problem(std::string_view name, std::size_t max_length) {
    if (name.empty()) return "must not be empty";
    if (name.size() > max_length) {
        return "is " + std::to_string(name.size()) + " characters long, at most " + std::to_string(max_length) +
               " allowed (it names a file)";
    }
    for (const char c : name) {
        // Spelled out rather than isalnum(): that follows the locale.
        const bool letter_or_digit = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9');
        if (!letter_or_digit && c != '.' && c != '_' && c != '-') {
            return "must be letters, digits, '.', '_' or '-' (it names a file; no '/', no spaces)";
        }
    }
    if (name.front() == '.') {
        return "must not start with '.' ('.' and '..' are directories of the path, and other dot names are hidden)";
    }
    return {};
}

}  // namespace rig
