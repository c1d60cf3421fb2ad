#pragma once
// A lease on a named resource among every process of the machine: an
// exclusive flock() on a lock file, held through the returned descriptor and
// freed by closing it, or by the kernel when the holder dies. The DDS domain
// leases (domain_lease.h) and the CPU leases (cpu_lease.h) are made of these.
#include <string>

namespace rig {

// The descriptor holding the lock on `path` (created if missing), or -1 when
// another holder has it or the file cannot be opened; `open_error`, if given,
// gets errno for a file that could not be opened and 0 otherwise.
int try_lease_file(const std::string& path, int* open_error = nullptr);

}  // namespace rig
