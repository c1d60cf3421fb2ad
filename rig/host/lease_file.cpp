#include "rig/host/lease_file.h"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <cerrno>

namespace rig {

int try_lease_file(const std::string& path, int* open_error) {
    if (open_error != nullptr) *open_error = 0;
    const int fd = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0666);
    if (fd < 0) {
        if (open_error != nullptr) *open_error = errno;
        return -1;
    }
    if (::flock(fd, LOCK_EX | LOCK_NB) == 0) return fd;
    ::close(fd);
    return -1;
}

}  // namespace rig
