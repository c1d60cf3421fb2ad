#pragma once
// Fast DDS asks the kernel for the calling thread's id several times for every
// sample it receives; this answers from a per-thread cache instead
// (rig/runtime/thread_id_cache.cpp says why and what it cost).
namespace rig {

// True when the process's `syscall` is the rig's (so Fast DDS's thread-id
// requests are answered from the cache): in every program linking rig::runtime.
bool thread_id_cache_in_use();

}  // namespace rig
