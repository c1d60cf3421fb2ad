// The thread-id cache (thread_id_cache.h).
//
// Why: Debian's Fast DDS 2.9.1 (libfastrtps.so.2.9.1, the build the rig uses)
// is compiled without NDEBUG, so the debug checks of its reliable reader's
// writer proxies run in every build: WriterProxy asserts that the calling
// thread owns the reader's mutex, and gets the thread's id for it with
// syscall(SYS_gettid). That is about eight system calls for every sample a
// reader receives and every sample it gives out: `perf trace -s` on one
// process-mode fusion case (3762 rounds) counted 329,000 of them, 87 a round,
// at 168 ns each on this machine (a loop of a million): about 15 us of CPU a
// round. In software-in-the-loop mode the rig's own nodes' part of a round went
// from 20 to 9 us without them (timed once with a stopwatch, not kept).
//
// What: the program's own `syscall` (the executable's definition comes before
// libc's for every library, Fast DDS included) answers SYS_gettid from a
// per-thread cache, filled by the first request of each thread and emptied in
// a forked child, and hands every other call to libc's `syscall` unchanged
// (its result and errno included). The answer is the same number the kernel
// gives, so Fast DDS's checks check exactly what they did. The linker is told
// to take this definition into every program that links rig::runtime
// (rig/runtime/CMakeLists.txt, -Wl,--undefined=syscall).
#include "rig/runtime/thread_id_cache.h"

#include <dlfcn.h>
#include <gnu/lib-names.h>
#include <pthread.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <cstdarg>
#include <cstdio>
#include <cstdlib>

namespace {

using SyscallFunction = long (*)(long, ...);

thread_local long cached_thread_id = 0;

// A forked child's thread has an id of its own; the forking thread's cache
// entry was copied into it.
void forget_thread_id_in_child() { cached_thread_id = 0; }

struct ForkHook {
    ForkHook() { pthread_atfork(nullptr, nullptr, forget_thread_id_in_child); }
};
const ForkHook fork_hook;

SyscallFunction libc_syscall() {
    // libc's own definition, asked of libc itself by name: the same answer
    // whether this copy is in the program or in a controller plugin.
    static const SyscallFunction function = [] {
        void* libc = dlopen(LIBC_SO, RTLD_LAZY | RTLD_NOLOAD);
        void* symbol = libc != nullptr ? dlsym(libc, "syscall") : nullptr;
        if (symbol == nullptr) {
            std::fprintf(stderr, "rig: cannot find libc's syscall (%s): %s\n", LIBC_SO, dlerror());
            std::abort();
        }
        return reinterpret_cast<SyscallFunction>(symbol);
    }();
    return function;
}

}  // namespace

// Every system call number takes at most six arguments, passed in registers on
// the ABIs the rig builds for (x86-64, AArch64): reading six and passing six on
// is what libc's own syscall() does with them.
extern "C" long syscall(long number, ...) noexcept {
    if (number == SYS_gettid) {
        if (cached_thread_id == 0) cached_thread_id = static_cast<long>(gettid());
        return cached_thread_id;
    }
    va_list arguments;
    va_start(arguments, number);
    const long a1 = va_arg(arguments, long);
    const long a2 = va_arg(arguments, long);
    const long a3 = va_arg(arguments, long);
    const long a4 = va_arg(arguments, long);
    const long a5 = va_arg(arguments, long);
    const long a6 = va_arg(arguments, long);
    va_end(arguments);
    return libc_syscall()(number, a1, a2, a3, a4, a5, a6);
}

namespace rig {

bool thread_id_cache_in_use() {
    return dlsym(RTLD_DEFAULT, "syscall") == reinterpret_cast<void*>(&::syscall);
}

}  // namespace rig
