#include "rig/host/shm_cleanup.h"

#include <dirent.h>
#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cctype>
#include <cerrno>
#include <cstring>
#include <ctime>

namespace rig {

namespace {

constexpr const char* kLockSuffix = "_el";

bool all_of(const std::string& text, std::size_t from, int (*is)(int)) {
    if (from >= text.size()) return false;
    for (std::size_t i = from; i < text.size(); ++i) {
        if (!is(static_cast<unsigned char>(text[i]))) return false;
    }
    return true;
}

int is_lower_hex(int c) { return std::isdigit(c) || (c >= 'a' && c <= 'f'); }

}  // namespace

bool is_fast_dds_segment_name(const std::string& name) {
    static const std::string participant = "fastrtps_";
    static const std::string port = "fastrtps_port";
    if (name.rfind(port, 0) == 0) return all_of(name, port.size(), [](int c) { return std::isdigit(c); });
    return name.rfind(participant, 0) == 0 && name.size() == participant.size() + 16 &&
           all_of(name, participant.size(), is_lower_hex);
}

ShmCleanup remove_dead_participant_segments(const std::filesystem::path& dir, std::chrono::seconds min_age) {
    ShmCleanup result;
    const int dir_fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (dir_fd < 0) return result;  // no /dev/shm: nothing to clean
    std::vector<std::string> lock_files;
    if (DIR* listing = ::fdopendir(::dup(dir_fd))) {
        while (const dirent* entry = ::readdir(listing)) {
            const std::string name = entry->d_name;
            const std::size_t suffix = std::strlen(kLockSuffix);
            if (name.size() > suffix && name.compare(name.size() - suffix, suffix, kLockSuffix) == 0 &&
                is_fast_dds_segment_name(name.substr(0, name.size() - suffix))) {
                lock_files.push_back(name);
            }
        }
        ::closedir(listing);
    }
    const std::time_t now = std::time(nullptr);
    for (const std::string& lock_name : lock_files) {
        // O_NONBLOCK and O_NOFOLLOW: whatever sits under such a name, opening it neither blocks nor leaves /dev/shm.
        const int lock_fd = ::openat(dir_fd, lock_name.c_str(), O_RDONLY | O_NOFOLLOW | O_NONBLOCK | O_CLOEXEC);
        if (lock_fd < 0) continue;  // gone meanwhile (its owner exited), or not ours to open
        struct stat lock_status {};
        const bool candidate = ::fstat(lock_fd, &lock_status) == 0 && S_ISREG(lock_status.st_mode) &&
                               now - lock_status.st_ctime >= static_cast<std::time_t>(min_age.count());
        // Held by a live process: LOCK_NB fails with EWOULDBLOCK and the segment stays.
        if (candidate && ::flock(lock_fd, LOCK_EX | LOCK_NB) == 0) {
            const std::string segment = lock_name.substr(0, lock_name.size() - std::strlen(kLockSuffix));
            struct stat segment_status {};
            const bool segment_is_file = ::fstatat(dir_fd, segment.c_str(), &segment_status, AT_SYMLINK_NOFOLLOW) == 0 &&
                                         S_ISREG(segment_status.st_mode);
            bool removed = true;
            // The segment first, the lock last (while we hold it): a process that
            // opens the name meanwhile finds either both or a fresh lock of its own.
            if (segment_is_file && ::unlinkat(dir_fd, segment.c_str(), 0) != 0 && errno != ENOENT) {
                result.problems.push_back(segment + ": " + std::strerror(errno));
                removed = false;
            }
            if (removed && ::unlinkat(dir_fd, lock_name.c_str(), 0) != 0 && errno != ENOENT) {
                result.problems.push_back(lock_name + ": " + std::strerror(errno));
                removed = false;
            }
            if (removed) {
                result.removed.push_back(segment);
                if (segment_is_file) result.bytes_freed += static_cast<std::size_t>(segment_status.st_size);
            }
            ::flock(lock_fd, LOCK_UN);
        }
        ::close(lock_fd);
    }
    ::close(dir_fd);
    return result;
}

}  // namespace rig
