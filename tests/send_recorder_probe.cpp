// Proves the network test's observers can see a non-loopback destination
// without sending anything off the machine: connect() on a UDP socket to
// 192.0.2.1 (TEST-NET-1, RFC 5737) only sets the default peer, no packet
// leaves; the one datagram actually sent goes to 127.0.0.1.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cstdio>

int main() {
    const int fd = socket(AF_INET, SOCK_DGRAM, 0);
    if (fd < 0) {
        std::perror("socket");
        return 1;
    }
    sockaddr_in loopback{};
    loopback.sin_family = AF_INET;
    loopback.sin_port = htons(9);  // discard
    loopback.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    (void)sendto(fd, "x", 1, 0, reinterpret_cast<const sockaddr*>(&loopback), sizeof loopback);

    sockaddr_in test_net = loopback;
    inet_pton(AF_INET, "192.0.2.1", &test_net.sin_addr);
    // May fail with ENETUNREACH inside a loopback-only namespace; the attempt is what is observed.
    (void)connect(fd, reinterpret_cast<const sockaddr*>(&test_net), sizeof test_net);
    close(fd);
    return 0;
}
