#pragma once
// Shared-memory segments that Fast DDS participants of killed processes leave
// in /dev/shm (issue 14, "Signals"). Fast DDS 2.9's shared-memory transport
// gives each participant a segment `fastrtps_<16 hex digits>` (about 0.5 MB)
// and each unicast listening port a segment `fastrtps_port<N>`; beside each it
// keeps a lock file of the same name plus `_el`, which the owning process holds
// with flock(LOCK_EX) for as long as the segment is in use. A process that exits
// normally removes both; one that is killed (a controller the rig ends with
// SIGKILL, a crashed run) leaves both behind, and Fast DDS 2.9 never removes
// another process's segment, so they pile up (hundreds of MB over a day of
// test runs). The kernel drops a dead process's flock, so a lock file nobody
// holds marks a segment whose owner is gone: that is the test here, the same
// one Fast DDS applies to its own ports when it reopens them.
//
// A segment whose lock is held (a live participant of any program, the rig's
// or another's) is never touched, and neither is a lock file younger than
// min_age: its creator may be between creating the file and locking it.
#include <chrono>
#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

namespace rig {

// Where POSIX shared memory lives on Linux (shm_open's directory).
inline const std::filesystem::path kPosixShmDir = "/dev/shm";
// A lock file this old has long been locked by a live creator: Fast DDS
// creates and locks it in two consecutive calls (microseconds apart).
inline constexpr std::chrono::seconds kShmLockMinAge{2};

struct ShmCleanup {
    std::vector<std::string> removed;  // segment names whose owner was gone (files removed: NAME and NAME_el)
    std::size_t bytes_freed = 0;
    std::vector<std::string> problems;  // a file that could not be removed, and why
};

// Removes the Fast DDS segments in `dir` whose owner has exited (see above).
// Only names of the two forms above are looked at, only regular files (a
// symlink or anything else with such a name is left alone), and only when their
// `_el` file is older than min_age and nobody holds its lock.
ShmCleanup remove_dead_participant_segments(const std::filesystem::path& dir = kPosixShmDir,
                                            std::chrono::seconds min_age = kShmLockMinAge);

// True for `fastrtps_` + 16 lowercase hex digits, or `fastrtps_port` + decimal digits.
bool is_fast_dds_segment_name(const std::string& name);

}  // namespace rig
