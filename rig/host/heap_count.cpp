#include "rig/host/heap_count.h"

#include <atomic>

namespace rig {

namespace {

// Each thread's own: read by the thread that made them. Trivial, so a
// thread's first allocation needs no constructor of it.
thread_local std::uint64_t allocations = 0;
// Relaxed: totals read between runs; no order with other memory is needed.
std::atomic<std::uint64_t> stepping{0};
std::atomic<bool> counted{false};

}  // namespace

std::uint64_t heap_allocations() { return allocations; }
bool heap_allocations_counted() { return counted.load(std::memory_order_relaxed); }
void add_stepping_allocations(std::uint64_t added) { stepping.fetch_add(added, std::memory_order_relaxed); }
std::uint64_t stepping_allocations() { return stepping.load(std::memory_order_relaxed); }
void count_heap_allocation() { ++allocations; }
void mark_heap_allocations_counted() { counted.store(true, std::memory_order_relaxed); }

}  // namespace rig
