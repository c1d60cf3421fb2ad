#include "rig/host/domain_lease.h"

#include <unistd.h>

#include <atomic>
#include <stdexcept>

#include "rig/host/lease_file.h"

namespace rig {

DomainLease DomainLease::acquire(std::uint32_t first, std::uint32_t last) {
    // Round-robin from after the last domain this process took: a domain a case
    // has just left is not reused at once, while the previous controller process
    // may still be on its way out and discovery still remembers it. Each process
    // starts at a place of its own (from its pid), so rig runs started together
    // (ctest -j) do not all queue for the same first domains.
    static std::atomic<std::uint32_t> next{static_cast<std::uint32_t>(::getpid())};
    const std::uint32_t span = last - first + 1;
    const std::uint32_t start = next.fetch_add(1) % span;
    for (std::uint32_t k = 0; k < span; ++k) {
        const std::uint32_t domain = first + (start + k) % span;
        const int fd = try_lease_file("/tmp/rig-dds-domain-" + std::to_string(domain) + ".lock");
        if (fd >= 0) return DomainLease(domain, fd);
    }
    throw std::runtime_error("no free DDS domain id in [" + std::to_string(first) + ", " + std::to_string(last) +
                             "]: too many rig runs at once?");
}

DomainLease DomainLease::acquire_exact(std::uint32_t domain) {
    // Fast DDS's well-known ports (7400 + 250 domain + ...) run out above 232.
    if (domain > 232) throw std::runtime_error("DDS domain " + std::to_string(domain) + " is above 232");
    const std::string path = "/tmp/rig-dds-domain-" + std::to_string(domain) + ".lock";
    int open_error = 0;
    const int fd = try_lease_file(path, &open_error);
    if (fd >= 0) return DomainLease(domain, fd);
    if (open_error != 0) throw std::runtime_error("cannot open " + path + " to lease DDS domain " + std::to_string(domain));
    throw std::runtime_error("DDS domain " + std::to_string(domain) + " is in use by another rig run (" + path + ")");
}

DomainLease::DomainLease(DomainLease&& other) noexcept : domain_id_(other.domain_id_), fd_(other.fd_) {
    other.fd_ = -1;
}

DomainLease::~DomainLease() {
    if (fd_ >= 0) ::close(fd_);  // closing releases the flock
}

}  // namespace rig
