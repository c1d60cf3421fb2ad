// The `rig` executable's global operator new: malloc, counted
// (rig/host/heap_count.h), so that `rig bench` can say how many allocations a
// lockstep round makes. The aligned forms stay the library's (they use
// aligned_alloc and free, never these).
#include <cstdlib>
#include <new>

#include "rig/host/heap_count.h"

namespace {

void* counted_allocation(std::size_t size) noexcept {
    rig::count_heap_allocation();
    return std::malloc(size == 0 ? 1 : size);
}

void* counted_allocation_or_throw(std::size_t size) {
    void* memory = counted_allocation(size);
    if (memory == nullptr) throw std::bad_alloc();
    return memory;
}

const bool counting = (rig::mark_heap_allocations_counted(), true);

}  // namespace

void* operator new(std::size_t size) { return counted_allocation_or_throw(size); }
void* operator new[](std::size_t size) { return counted_allocation_or_throw(size); }
void* operator new(std::size_t size, const std::nothrow_t&) noexcept { return counted_allocation(size); }
void* operator new[](std::size_t size, const std::nothrow_t&) noexcept { return counted_allocation(size); }
void operator delete(void* memory) noexcept { std::free(memory); }
void operator delete[](void* memory) noexcept { std::free(memory); }
void operator delete(void* memory, std::size_t) noexcept { std::free(memory); }
void operator delete[](void* memory, std::size_t) noexcept { std::free(memory); }
void operator delete(void* memory, const std::nothrow_t&) noexcept { std::free(memory); }
void operator delete[](void* memory, const std::nothrow_t&) noexcept { std::free(memory); }
