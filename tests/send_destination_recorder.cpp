// LD_PRELOAD library for tests/network_loopback_test.cpp: records the
// destination of every connect/sendto/sendmsg/sendmmsg made by the process
// (and, through the inherited environment, by every child it spawns) into the
// file named by RIG_SEND_LOG, one line per distinct destination:
//   <pid> <call> <family> <address> <port>
//
// Why not only strace: ptrace stops every traced thread on each send, and the
// rig's lockstep round trips become so slow under `strace -f` that a whole
// case does not finish in a CI budget. Interposing at the libc boundary costs
// a mutex and a table lookup per send; Fast DDS (through asio) sends every
// datagram with these libc calls. The kernel-level strace check still runs on
// a short DDS exchange in the same test suite.
#include <arpa/inet.h>
#include <dlfcn.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <pthread.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>

namespace {

struct SeenDestination {
    int family;
    char address[INET6_ADDRSTRLEN];
    unsigned port;
};

constexpr int kMaxSeen = 256;
SeenDestination g_seen[kMaxSeen];
int g_seen_count = 0;
pthread_mutex_t g_mutex = PTHREAD_MUTEX_INITIALIZER;

template <typename Fn>
Fn next_symbol(const char* name) {
    return reinterpret_cast<Fn>(dlsym(RTLD_NEXT, name));
}

void record(const char* call, const sockaddr* address, socklen_t length) {
    if (address == nullptr || length < static_cast<socklen_t>(sizeof(sa_family_t))) return;
    SeenDestination entry{};
    entry.family = address->sa_family;
    if (address->sa_family == AF_INET && length >= static_cast<socklen_t>(sizeof(sockaddr_in))) {
        sockaddr_in v4;
        std::memcpy(&v4, address, sizeof v4);
        inet_ntop(AF_INET, &v4.sin_addr, entry.address, sizeof entry.address);
        entry.port = ntohs(v4.sin_port);
    } else if (address->sa_family == AF_INET6 && length >= static_cast<socklen_t>(sizeof(sockaddr_in6))) {
        sockaddr_in6 v6;
        std::memcpy(&v6, address, sizeof v6);
        inet_ntop(AF_INET6, &v6.sin6_addr, entry.address, sizeof entry.address);
        entry.port = ntohs(v6.sin6_port);
    } else {
        return;  // AF_UNIX, AF_NETLINK: not network traffic
    }
    pthread_mutex_lock(&g_mutex);
    bool known = false;
    for (int i = 0; i < g_seen_count && !known; ++i) {
        known = g_seen[i].family == entry.family && g_seen[i].port == entry.port &&
                std::strcmp(g_seen[i].address, entry.address) == 0;
    }
    if (!known) {
        if (g_seen_count < kMaxSeen) g_seen[g_seen_count++] = entry;
        if (const char* log_path = std::getenv("RIG_SEND_LOG")) {
            const int fd = open(log_path, O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
            if (fd >= 0) {
                char line[160];
                const int n = std::snprintf(line, sizeof line, "%d %s %s %s %u\n", static_cast<int>(getpid()), call,
                                            entry.family == AF_INET ? "inet" : "inet6", entry.address, entry.port);
                if (n > 0) (void)!write(fd, line, static_cast<size_t>(n));
                close(fd);
            }
        }
    }
    pthread_mutex_unlock(&g_mutex);
}

}  // namespace

extern "C" {

int connect(int fd, const sockaddr* address, socklen_t length) {
    static const auto real = next_symbol<int (*)(int, const sockaddr*, socklen_t)>("connect");
    record("connect", address, length);
    return real(fd, address, length);
}

ssize_t sendto(int fd, const void* buffer, size_t size, int flags, const sockaddr* address, socklen_t length) {
    static const auto real =
        next_symbol<ssize_t (*)(int, const void*, size_t, int, const sockaddr*, socklen_t)>("sendto");
    record("sendto", address, length);
    return real(fd, buffer, size, flags, address, length);
}

ssize_t sendmsg(int fd, const msghdr* message, int flags) {
    static const auto real = next_symbol<ssize_t (*)(int, const msghdr*, int)>("sendmsg");
    if (message != nullptr) record("sendmsg", static_cast<const sockaddr*>(message->msg_name), message->msg_namelen);
    return real(fd, message, flags);
}

int sendmmsg(int fd, mmsghdr* messages, unsigned int count, int flags) {
    static const auto real = next_symbol<int (*)(int, mmsghdr*, unsigned int, int)>("sendmmsg");
    for (unsigned int i = 0; messages != nullptr && i < count; ++i) {
        record("sendmmsg", static_cast<const sockaddr*>(messages[i].msg_hdr.msg_name),
               messages[i].msg_hdr.msg_namelen);
    }
    return real(fd, messages, count, flags);
}

}  // extern "C"
