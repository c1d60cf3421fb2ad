#pragma once
// Heap allocations: `rig bench` reports how many a lockstep round makes on
// the lockstep's thread (issue 32: no allocation per sample on the loop): the
// rig's nodes, an in-process controller, the recorder's drain, and what Fast
// DDS allocates on that thread; not the trace writer's or Fast DDS's own
// threads. They are counted by the `rig` executable's replacement of the
// global operator new (harness/commands/counting_new.cpp), per thread (a
// counter of each thread's own: no atomic, no cache line shared between
// threads on the hot path); C code's own malloc (SQLite's) is not counted. A
// program without the replacement counts nothing and says so
// (heap_allocations_counted() false).
#include <cstdint>

namespace rig {

// Allocations the calling thread has made so far (0 without the replacement).
std::uint64_t heap_allocations();
bool heap_allocations_counted();

// The lockstep's stepping (harness/run/case_loop.cpp) adds the allocations
// its thread made between its first and last instant; `rig bench` reads the
// total before and after each run.
void add_stepping_allocations(std::uint64_t allocations);
std::uint64_t stepping_allocations();

// For the replacement only.
void count_heap_allocation();
void mark_heap_allocations_counted();

}  // namespace rig
