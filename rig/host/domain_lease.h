#pragma once
// Each concurrently running case uses its own DDS domain id (docs/design.md). A lease
// is an flock() on /tmp/rig-dds-domain-N.lock held for the run: two rig processes
// (parallel ctest, --jobs) never share a domain, and a crashed holder frees its
// lease automatically when the kernel closes its file.
#include <cstdint>
#include <string>

namespace rig {

class DomainLease {
public:
    // Takes the first free domain in [first, last]; throws if all are taken.
    static DomainLease acquire(std::uint32_t first = 10, std::uint32_t last = 200);
    // Exactly this domain (`rig run --domain N`, so an observer knows where to
    // look); throws std::runtime_error when another run holds it.
    static DomainLease acquire_exact(std::uint32_t domain);
    DomainLease(DomainLease&& other) noexcept;
    DomainLease& operator=(DomainLease&&) = delete;
    DomainLease(const DomainLease&) = delete;
    ~DomainLease();

    std::uint32_t domain_id() const { return domain_id_; }

private:
    DomainLease(std::uint32_t domain_id, int fd) : domain_id_(domain_id), fd_(fd) {}
    std::uint32_t domain_id_;
    int fd_;
};

}  // namespace rig
