#include "rig/wire/modbus_slave.h"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/eventfd.h>
#include <sys/file.h>
#include <sys/socket.h>
#include <termios.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <condition_variable>
#include <cstring>
#include <mutex>
#include <stdexcept>
#include <thread>
#include <utility>
#include <vector>

#include "rig/runtime/clock.h"
#include "rig/runtime/realtime.h"

namespace rig::modbus {
namespace {

constexpr TimeNs kNsPerMs = 1'000'000;
// Longest poll() between looks at the clock: stop() does not depend on it (it
// wakes the thread through an eventfd), it only bounds how stale a deadline gets.
constexpr int kMaxPollMs = 1000;
// After a failed accept() for lack of resources, or a serial line that hung up,
// wait this long before trying again instead of spinning on a ready descriptor.
constexpr TimeNs kRetryPauseNs = 200 * kNsPerMs;
// Reads per connection per wake-up, so one chatty client cannot starve the others.
constexpr int kMaxReadsPerWake = 8;

class UniqueFd {
public:
    UniqueFd() = default;
    explicit UniqueFd(int fd) : fd_(fd) {}
    ~UniqueFd() { reset(); }
    UniqueFd(UniqueFd&& other) noexcept : fd_(std::exchange(other.fd_, -1)) {}
    UniqueFd& operator=(UniqueFd&& other) noexcept {
        if (this != &other) {
            reset();
            fd_ = std::exchange(other.fd_, -1);
        }
        return *this;
    }
    UniqueFd(const UniqueFd&) = delete;
    UniqueFd& operator=(const UniqueFd&) = delete;
    int get() const { return fd_; }
    void reset() {
        if (fd_ >= 0) ::close(fd_);
        fd_ = -1;
    }

private:
    int fd_ = -1;
};

std::string errno_text(int error) { return std::strerror(error); }

int poll_timeout_ms(TimeNs deadline_ns, TimeNs now_ns) {
    if (deadline_ns == kNever) return kMaxPollMs;
    if (deadline_ns <= now_ns) return 0;
    const TimeNs wait_ms = (deadline_ns - now_ns + kNsPerMs - 1) / kNsPerMs;  // round up: never wake early
    return static_cast<int>(std::min<TimeNs>(wait_ms, kMaxPollMs));
}

speed_t termios_speed(int baud) {
    switch (baud) {
        case 1200: return B1200;
        case 2400: return B2400;
        case 4800: return B4800;
        case 9600: return B9600;
        case 19200: return B19200;
        case 38400: return B38400;
        case 57600: return B57600;
        case 115200: return B115200;
        case 230400: return B230400;
        case 460800: return B460800;
        case 921600: return B921600;
        default: throw std::invalid_argument("baud rate " + std::to_string(baud) + " is not supported");
    }
}

UniqueFd open_serial_line(const SerialLineSettings& line) {
    UniqueFd fd(::open(line.device.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC));
    if (fd.get() < 0) {
        throw std::runtime_error("cannot open serial device " + line.device + ": " + errno_text(errno));
    }
    termios settings{};
    if (::tcgetattr(fd.get(), &settings) != 0) {
        throw std::runtime_error(line.device + " is not a serial device (tcgetattr: " + errno_text(errno) + ")");
    }
    // An advisory lock: two rig processes on one line would each see half the frames.
    if (::flock(fd.get(), LOCK_EX | LOCK_NB) != 0) {
        throw std::runtime_error("serial device " + line.device + " is in use by another process (" +
                                 errno_text(errno) + ")");
    }
    ::cfmakeraw(&settings);
    settings.c_cflag |= CLOCAL | CREAD;
    settings.c_cflag &= ~static_cast<tcflag_t>(CSIZE | PARENB | PARODD | CSTOPB | CRTSCTS);
    settings.c_cflag |= line.data_bits == 7 ? CS7 : CS8;
    if (line.parity != Parity::none) settings.c_cflag |= PARENB;
    if (line.parity == Parity::odd) settings.c_cflag |= PARODD;
    if (line.stop_bits == 2) settings.c_cflag |= CSTOPB;
    settings.c_iflag &= ~static_cast<tcflag_t>(IXON | IXOFF | IXANY);
    if (line.parity != Parity::none) settings.c_iflag |= INPCK;
    settings.c_cc[VMIN] = 0;
    settings.c_cc[VTIME] = 0;
    const speed_t speed = termios_speed(line.baud);
    if (::cfsetispeed(&settings, speed) != 0 || ::cfsetospeed(&settings, speed) != 0 ||
        ::tcsetattr(fd.get(), TCSANOW, &settings) != 0) {
        throw std::runtime_error("cannot configure serial device " + describe(line) + ": " + errno_text(errno));
    }
    ::tcflush(fd.get(), TCIOFLUSH);  // bytes from before we owned the line are no frame of ours
    return fd;
}

std::string endpoint_text(const sockaddr_in& address) {
    char text[INET_ADDRSTRLEN] = "?";
    ::inet_ntop(AF_INET, &address.sin_addr, text, sizeof text);
    return std::string(text) + ":" + std::to_string(ntohs(address.sin_port));
}

UniqueFd listen_tcp(const std::string& bind_address, std::uint16_t port, std::uint16_t& bound_port) {
    const std::string where = bind_address + ":" + std::to_string(port);
    sockaddr_in address{};
    address.sin_family = AF_INET;
    address.sin_port = htons(port);
    if (::inet_pton(AF_INET, bind_address.c_str(), &address.sin_addr) != 1) {
        throw std::invalid_argument("Modbus TCP bind address '" + bind_address + "' is not an IPv4 address");
    }
    UniqueFd fd(::socket(AF_INET, SOCK_STREAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0));
    if (fd.get() < 0) throw std::runtime_error("cannot create a socket for Modbus TCP on " + where + ": " + errno_text(errno));
    const int reuse = 1;  // restart at once after a stop, while old connections sit in TIME_WAIT
    ::setsockopt(fd.get(), SOL_SOCKET, SO_REUSEADDR, &reuse, sizeof reuse);
    if (::bind(fd.get(), reinterpret_cast<const sockaddr*>(&address), sizeof address) != 0) {
        const int error = errno;
        throw std::runtime_error("cannot listen for Modbus TCP on " + where + ": " + errno_text(error) +
                                 (error == EADDRINUSE ? " (another slave or `rig modbus serve` running?)" : ""));
    }
    if (::listen(fd.get(), 16) != 0) {
        throw std::runtime_error("cannot listen for Modbus TCP on " + where + ": " + errno_text(errno));
    }
    sockaddr_in bound{};
    socklen_t length = sizeof bound;
    ::getsockname(fd.get(), reinterpret_cast<sockaddr*>(&bound), &length);
    bound_port = ntohs(bound.sin_port);
    return fd;
}

struct Connection {
    UniqueFd fd;
    std::string peer;                 // "tcp 127.0.0.1:40512"
    std::vector<std::uint8_t> buffer;  // bytes of frames not yet complete
    TimeNs last_activity_ns = 0;
    TimeNs frame_started_ns = 0;      // first byte of the incomplete frame in `buffer`
    bool open = true;
};

}  // namespace

class ModbusSlave::Impl {
public:
    explicit Impl(ModbusSlaveCallbacks callbacks) : callbacks_(std::move(callbacks)) {
        encode_device_signals(io::DeviceSignals{}, image_);
        previous_coils_ = image_.coils;
        previous_holding_ = image_.holding_registers;
    }

    ~Impl() {
        try {
            stop();
        } catch (...) {
        }
    }

    void start_tcp(const TcpSlaveOptions& options) {
        if (!options.allow_non_loopback && !is_loopback_ipv4(options.bind_address)) {
            throw std::invalid_argument("Modbus TCP bind address '" + options.bind_address +
                                        "' is not loopback (127.0.0.0/8); these machines talk to 127.0.0.1 only "
                                        "(set allow_non_loopback for a bench with a board on Ethernet)");
        }
        if (options.max_connections < 1) {
            throw std::invalid_argument("Modbus TCP max_connections must be >= 1, got " +
                                        std::to_string(options.max_connections));
        }
        if (options.partial_frame_timeout.count() <= 0) {
            throw std::invalid_argument("Modbus TCP partial_frame_timeout must be > 0 ms");
        }
        check_failsafe_options(options.failsafe);
        tcp_options_ = options;
        failsafe_ = options.failsafe;
        listen_fd_ = listen_tcp(options.bind_address, options.port, tcp_port_);
        endpoint_ = "tcp " + options.bind_address + ":" + std::to_string(tcp_port_);
        start_thread([this] { run_tcp(); });
    }

    void start_rtu(const RtuSlaveOptions& options) {
        if (auto problem = serial_settings_problem(options.line); !problem.empty()) throw std::invalid_argument(problem);
        if (options.slave_id < 1 || options.slave_id > 247) {
            throw std::invalid_argument("Modbus RTU slave id " + std::to_string(options.slave_id) + " for " +
                                        options.line.device + " outside 1..247");
        }
        if (options.frame_end_silence.count() <= 0 || options.write_timeout.count() <= 0) {
            throw std::invalid_argument("Modbus RTU frame_end_silence and write_timeout must be > 0 ms");
        }
        check_failsafe_options(options.failsafe);
        rtu_options_ = options;
        failsafe_ = options.failsafe;
        serial_fd_ = open_serial_line(options.line);
        endpoint_ = "rtu " + describe(options.line) + " slave " + std::to_string(options.slave_id);
        start_thread([this] { run_rtu(); });
    }

    static void check_failsafe_options(const CommsFailsafe& failsafe) {
        if (failsafe.timeout.count() < 0) throw std::invalid_argument("Modbus fail-safe timeout must be >= 0 ms (0 = off)");
    }

    std::string raise_to_realtime(int priority) {
        std::lock_guard stop_lock(stop_mutex_);
        return raise_thread_to_realtime(thread_, priority);
    }

    void stop() {
        std::lock_guard stop_lock(stop_mutex_);
        if (thread_.joinable()) {
            if (std::this_thread::get_id() == thread_.get_id()) {
                throw std::logic_error("ModbusSlave::stop() called from its own callback (" + endpoint_ + ")");
            }
            stop_requested_ = true;
            const std::uint64_t one = 1;
            if (::write(wake_fd_.get(), &one, sizeof one) < 0) {
                // The eventfd cannot be full after one write; the flag is read every poll anyway.
            }
            thread_.join();
        }
        listen_fd_.reset();
        serial_fd_.reset();
    }

    // ---- rig side (any thread)

    void set_device_signals(const io::DeviceSignals& signals) {
        RegisterImage encoded;
        encode_device_signals(signals, encoded);  // may throw; nothing changed yet
        std::lock_guard lock(mutex_);
        image_.input_registers = encoded.input_registers;
        image_.discrete_inputs = encoded.discrete_inputs;
    }

    io::DeviceSignals device_signals() const {
        std::lock_guard lock(mutex_);
        return decode_device_signals(image_.input_registers, image_.discrete_inputs);
    }

    io::ActuatorCommands actuator_commands() const {
        std::lock_guard lock(mutex_);
        return decode_coils(image_.coils);
    }

    io::ControllerIndicators indicators() const {
        std::lock_guard lock(mutex_);
        return decode_holding_registers(image_.holding_registers);
    }

    std::uint64_t master_write_count() const {
        std::lock_guard lock(mutex_);
        return stats_.master_writes;
    }

    std::uint64_t wait_for_master_write(std::uint64_t seen, std::chrono::milliseconds timeout) const {
        std::unique_lock lock(mutex_);
        write_cv_.wait_for(lock, timeout, [&] { return stats_.master_writes > seen; });
        return stats_.master_writes;
    }

    ModbusSlaveStatistics statistics() const {
        std::lock_guard lock(mutex_);
        return stats_;
    }

    std::optional<std::string> server_failure() const {
        std::lock_guard lock(mutex_);
        return failure_;
    }

    std::optional<std::chrono::nanoseconds> since_last_request() const {
        std::lock_guard lock(mutex_);
        if (!last_request_ns_) return std::nullopt;
        return std::chrono::nanoseconds(clock_.now_ns() - *last_request_ns_);
    }

    bool failsafe_active() const {
        std::lock_guard lock(mutex_);
        return failsafe_tripped_;
    }

    const std::string& endpoint() const { return endpoint_; }
    std::uint16_t tcp_port() const { return tcp_port_; }

private:
    template <typename Loop>
    void start_thread(Loop loop) {
        wake_fd_ = UniqueFd(::eventfd(0, EFD_NONBLOCK | EFD_CLOEXEC));
        if (wake_fd_.get() < 0) throw std::runtime_error("Modbus slave " + endpoint_ + ": eventfd: " + errno_text(errno));
        thread_ = std::thread([this, loop] {
            try {
                loop();
            } catch (const std::exception& error) {
                fail(error.what());
            } catch (...) {
                fail("unknown exception");
            }
        });
    }

    void fail(const std::string& what) {
        const std::string line = "Modbus slave " + endpoint_ + " stopped serving: " + what;
        {
            std::lock_guard lock(mutex_);
            failure_ = line;
        }
        report_problem(line);
    }

    template <typename Update>
    void count(Update update) {
        std::lock_guard lock(mutex_);
        update(stats_);
    }

    void report_problem(const std::string& line) {
        {
            std::lock_guard lock(mutex_);
            stats_.last_problem = line;
        }
        if (!callbacks_.on_problem) return;
        try {
            callbacks_.on_problem(line);
        } catch (...) {
            count([](auto& stats) { ++stats.callback_errors; });
        }
    }

    // Serves one request PDU from `origin`; the response PDU (empty = none).
    std::vector<std::uint8_t> serve(std::span<const std::uint8_t> pdu, const std::string& origin, bool broadcast) {
        ServedRequest served;
        std::optional<MasterWrite> write;
        {
            std::lock_guard lock(mutex_);
            served = serve_request(pdu, image_);
            ++stats_.valid_requests;
            last_request_ns_ = clock_.now_ns();
            failsafe_tripped_ = false;
            if (served.exception) {
                switch (*served.exception) {
                    case ExceptionCode::illegal_function: ++stats_.illegal_function; break;
                    case ExceptionCode::illegal_data_address: ++stats_.illegal_data_address; break;
                    case ExceptionCode::illegal_data_value: ++stats_.illegal_data_value; break;
                    case ExceptionCode::server_device_failure: break;
                }
            } else if (broadcast) {
                ++stats_.broadcast_requests;
            } else if (!served.response_pdu.empty()) {
                ++stats_.requests_answered;
            }
            if (served.wrote_outputs) {
                MasterWrite report;
                report.commands = decode_coils(image_.coils);
                report.indicators = decode_holding_registers(image_.holding_registers);
                report.commands_changed = image_.coils != previous_coils_;
                report.indicators_changed = image_.holding_registers != previous_holding_;
                report.sequence = ++stats_.master_writes;
                previous_coils_ = image_.coils;
                previous_holding_ = image_.holding_registers;
                write = report;
            }
        }
        if (write) write_cv_.notify_all();
        if (!served.problem.empty()) report_problem(origin + ": " + served.problem);
        if (write && callbacks_.on_master_write) {
            try {
                callbacks_.on_master_write(*write);
            } catch (...) {
                count([](auto& stats) { ++stats.callback_errors; });
            }
        }
        if (broadcast) return {};  // never answered, not even with an exception
        return std::move(served.response_pdu);
    }

    bool wake_requested(const pollfd& wake) const { return stop_requested_ || (wake.revents & POLLIN) != 0; }

    // ---------------------------------------------------------------- comms-loss watchdog

    // When the watchdog trips next (kNever: off, not armed before the first
    // request, or already tripped).
    TimeNs failsafe_deadline_ns() const {
        if (failsafe_.timeout.count() <= 0) return kNever;
        std::lock_guard lock(mutex_);
        if (!last_request_ns_ || failsafe_tripped_) return kNever;
        return *last_request_ns_ + failsafe_.timeout.count() * kNsPerMs;
    }

    void check_failsafe(TimeNs now) {
        const TimeNs deadline = failsafe_deadline_ns();
        if (deadline == kNever || now < deadline) return;
        std::optional<MasterWrite> write;
        {
            std::lock_guard lock(mutex_);
            failsafe_tripped_ = true;
            ++stats_.failsafe_trips;
            if (failsafe_.mode == FailsafeMode::safe && image_.coils != Coils{}) {
                image_.coils = Coils{};
                MasterWrite report;
                report.commands = decode_coils(image_.coils);
                report.indicators = decode_holding_registers(image_.holding_registers);
                report.commands_changed = true;
                report.sequence = stats_.master_writes;
                previous_coils_ = image_.coils;
                write = report;
            }
        }
        report_problem(endpoint_ + ": no valid request for " + std::to_string(failsafe_.timeout.count()) +
                       " ms: comms-loss fail-safe (" + std::string(to_string(failsafe_.mode)) + ")" +
                       (write ? ", every coil de-energised" : ""));
        // Told like a write, so whoever shows the outputs sees them change at once.
        if (write && callbacks_.on_master_write) {
            try {
                callbacks_.on_master_write(*write);
            } catch (...) {
                count([](auto& stats) { ++stats.callback_errors; });
            }
        }
    }

    // ---------------------------------------------------------------- TCP

    void run_tcp() {
        std::vector<Connection> connections;
        std::vector<pollfd> fds;
        TimeNs accept_paused_until_ns = 0;
        while (!stop_requested_) {
            const TimeNs now = clock_.now_ns();
            TimeNs deadline = kNever;
            for (const auto& connection : connections) {
                if (!connection.buffer.empty()) {
                    deadline = std::min(deadline, connection.frame_started_ns +
                                                      tcp_options_.partial_frame_timeout.count() * kNsPerMs);
                }
            }
            const bool accepting = now >= accept_paused_until_ns;
            if (!accepting) deadline = std::min(deadline, accept_paused_until_ns);
            deadline = std::min(deadline, failsafe_deadline_ns());
            fds.clear();
            fds.push_back({wake_fd_.get(), POLLIN, 0});
            fds.push_back({accepting ? listen_fd_.get() : -1, POLLIN, 0});  // fd -1: ignored by poll
            for (const auto& connection : connections) fds.push_back({connection.fd.get(), POLLIN, 0});
            if (::poll(fds.data(), fds.size(), poll_timeout_ms(deadline, now)) < 0) {
                if (errno == EINTR) continue;
                throw std::runtime_error(std::string("poll: ") + errno_text(errno));
            }
            if (wake_requested(fds[0])) break;
            const TimeNs after = clock_.now_ns();
            for (std::size_t i = 0; i < connections.size(); ++i) {
                if (fds[i + 2].revents != 0) read_from(connections[i], after);
            }
            if ((fds[1].revents & POLLIN) != 0 && !accept_connections(connections, after)) {
                accept_paused_until_ns = after + kRetryPauseNs;
            }
            expire_partial_frames(connections, after);
            check_failsafe(after);
            std::erase_if(connections, [](const Connection& connection) { return !connection.open; });
        }
    }

    // False when accept() failed for lack of resources (pause accepting).
    bool accept_connections(std::vector<Connection>& connections, TimeNs now) {
        for (;;) {
            sockaddr_in peer{};
            socklen_t length = sizeof peer;
            const int fd = ::accept4(listen_fd_.get(), reinterpret_cast<sockaddr*>(&peer), &length,
                                     SOCK_NONBLOCK | SOCK_CLOEXEC);
            if (fd < 0) {
                const int error = errno;
                if (error == EINTR || error == ECONNABORTED || error == EPROTO) continue;
                if (error == EAGAIN || error == EWOULDBLOCK) return true;
                report_problem(endpoint_ + ": accept: " + errno_text(error));
                return false;
            }
            const int no_delay = 1;  // a response is one small segment: send it now
            ::setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &no_delay, sizeof no_delay);
            count([](auto& stats) { ++stats.connections_accepted; });
            const auto open_count = std::count_if(connections.begin(), connections.end(),
                                                  [](const Connection& connection) { return connection.open; });
            if (open_count >= tcp_options_.max_connections) evict_least_recently_active(connections);
            Connection connection;
            connection.fd = UniqueFd(fd);
            connection.peer = "tcp " + endpoint_text(peer);
            connection.last_activity_ns = now;
            connections.push_back(std::move(connection));
        }
    }

    void evict_least_recently_active(std::vector<Connection>& connections) {
        Connection* oldest = nullptr;
        for (auto& connection : connections) {
            if (connection.open && (oldest == nullptr || connection.last_activity_ns < oldest->last_activity_ns)) {
                oldest = &connection;
            }
        }
        if (oldest == nullptr) return;
        count([](auto& stats) { ++stats.connections_evicted; });
        report_problem(oldest->peer + ": closed to admit a new connection (max_connections " +
                       std::to_string(tcp_options_.max_connections) + ", this one least recently active)");
        close(*oldest);
    }

    static void close(Connection& connection) {
        connection.fd.reset();
        connection.buffer.clear();
        connection.open = false;
    }

    void read_from(Connection& connection, TimeNs now) {
        std::uint8_t chunk[4096];
        for (int reads = 0; reads < kMaxReadsPerWake && connection.open; ++reads) {
            const ssize_t received = ::recv(connection.fd.get(), chunk, sizeof chunk, 0);
            if (received > 0) {
                if (connection.buffer.empty()) connection.frame_started_ns = now;
                connection.buffer.insert(connection.buffer.end(), chunk, chunk + received);
                connection.last_activity_ns = now;
                process_frames(connection, now);
                continue;
            }
            if (received < 0 && errno == EINTR) continue;
            if (received < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) return;
            // Orderly close (0) or reset: the peer is gone.
            const bool mid_frame = !connection.buffer.empty();
            count([mid_frame](auto& stats) {
                ++stats.connections_closed_by_peer;
                if (mid_frame) ++stats.connections_closed_mid_frame;
            });
            if (mid_frame) {
                report_problem(connection.peer + ": disconnected with " + std::to_string(connection.buffer.size()) +
                               " bytes of an incomplete frame");
            }
            close(connection);
        }
    }

    void process_frames(Connection& connection, TimeNs now) {
        std::size_t consumed = 0;
        while (connection.open && connection.buffer.size() - consumed >= kMbapHeaderSize) {
            const std::uint8_t* frame = connection.buffer.data() + consumed;
            const MbapHeader header = parse_mbap_header(std::span<const std::uint8_t, kMbapHeaderSize>(frame, kMbapHeaderSize));
            if (auto problem = mbap_header_problem(header); !problem.empty()) {
                // Framing is lost: where the next frame starts is unknowable.
                count([](auto& stats) { ++stats.malformed_frames; });
                report_problem(connection.peer + ": " + problem + "; connection closed");
                close(connection);
                return;
            }
            const std::size_t frame_size = 6 + static_cast<std::size_t>(header.length);
            if (connection.buffer.size() - consumed < frame_size) break;
            const std::span<const std::uint8_t> pdu(frame + kMbapHeaderSize, header.length - 1u);
            const std::vector<std::uint8_t> response = serve(pdu, connection.peer, false);
            consumed += frame_size;
            if (!response.empty()) send_response(connection, frame_tcp_response(header, response));
        }
        if (!connection.open) return;
        connection.buffer.erase(connection.buffer.begin(), connection.buffer.begin() + static_cast<std::ptrdiff_t>(consumed));
        if (consumed > 0 && !connection.buffer.empty()) connection.frame_started_ns = now;
    }

    void send_response(Connection& connection, const std::vector<std::uint8_t>& adu) {
        for (;;) {
            const ssize_t sent = ::send(connection.fd.get(), adu.data(), adu.size(), MSG_NOSIGNAL | MSG_DONTWAIT);
            if (sent == static_cast<ssize_t>(adu.size())) return;
            if (sent < 0 && errno == EINTR) continue;
            // Short or refused: the socket buffer is full of responses the client
            // does not read, or the client is gone. A half-sent ADU would corrupt
            // the stream, so the connection ends here.
            const std::string why = sent < 0 ? errno_text(errno) : "only " + std::to_string(sent) + " bytes taken";
            count([](auto& stats) { ++stats.responses_not_sent; });
            report_problem(connection.peer + ": response not sent (" + why + "); connection closed");
            close(connection);
            return;
        }
    }

    void expire_partial_frames(std::vector<Connection>& connections, TimeNs now) {
        const TimeNs timeout_ns = tcp_options_.partial_frame_timeout.count() * kNsPerMs;
        for (auto& connection : connections) {
            if (!connection.open || connection.buffer.empty() || now - connection.frame_started_ns < timeout_ns) continue;
            count([](auto& stats) { ++stats.connections_timed_out; });
            report_problem(connection.peer + ": frame incomplete after " +
                           std::to_string(tcp_options_.partial_frame_timeout.count()) + " ms (" +
                           std::to_string(connection.buffer.size()) + " bytes); connection closed");
            close(connection);
        }
    }

    // ---------------------------------------------------------------- RTU

    void run_rtu() {
        RtuRequestAssembler::Timing timing;
        timing.discard_silence_ns = rtu_inter_frame_gap_ns(rtu_options_.line.baud);
        timing.frame_end_silence_ns = rtu_options_.frame_end_silence.count() * kNsPerMs;
        RtuRequestAssembler assembler(rtu_options_.slave_id, timing);
        std::vector<RtuRequestAssembler::Event> events;
        TimeNs last_byte_ns = 0;
        bool line_down = false;      // pausing before looking at the line again
        bool line_failing = false;   // reported as failing, not yet working again
        while (!stop_requested_) {
            const TimeNs now = clock_.now_ns();
            check_failsafe(now);  // also while the line is down
            pollfd fds[2] = {{wake_fd_.get(), POLLIN, 0}, {serial_fd_.get(), POLLIN, 0}};
            // A hung-up line reports POLLHUP at once, forever: look at it again only after a pause.
            const nfds_t watched = line_down ? 1 : 2;
            const TimeNs deadline = std::min(assembler.next_deadline_ns(), failsafe_deadline_ns());
            const int timeout_ms = line_down ? static_cast<int>(std::min<TimeNs>(kRetryPauseNs, std::max<TimeNs>(
                                                                    failsafe_deadline_ns() - now, 0)) / kNsPerMs)
                                             : poll_timeout_ms(deadline, now);
            const int ready = ::poll(fds, watched, timeout_ms);
            if (ready < 0) {
                if (errno == EINTR) continue;
                throw std::runtime_error(std::string("poll: ") + errno_text(errno));
            }
            if (wake_requested(fds[0])) break;
            const TimeNs after = clock_.now_ns();
            if (line_down) {
                line_down = false;
                continue;
            }
            if (ready == 0) {
                assembler.silence(after, events);
            } else if ((fds[1].revents & POLLIN) != 0) {
                std::string failure;
                if (read_serial(assembler, after, events, failure)) {
                    last_byte_ns = after;
                    if (line_failing) report_problem(endpoint_ + ": serial line working again");
                    line_failing = false;
                } else {
                    line_down = true;
                    if (!line_failing) report_problem(endpoint_ + ": " + failure + "; retrying every " +
                                                      std::to_string(kRetryPauseNs / kNsPerMs) + " ms");
                    line_failing = true;
                }
            } else if ((fds[1].revents & (POLLHUP | POLLERR | POLLNVAL)) != 0) {
                line_down = true;
                if (!line_failing) report_problem(endpoint_ + ": serial line hung up; retrying every " +
                                                  std::to_string(kRetryPauseNs / kNsPerMs) + " ms");
                line_failing = true;
            }
            for (auto& event : events) handle_rtu_event(event, last_byte_ns);
            events.clear();
            check_failsafe(clock_.now_ns());
        }
    }

    // False when the line failed (a read error other than "nothing there"), with why.
    bool read_serial(RtuRequestAssembler& assembler, TimeNs now, std::vector<RtuRequestAssembler::Event>& events,
                     std::string& failure) {
        std::uint8_t chunk[512];
        for (int reads = 0; reads < kMaxReadsPerWake; ++reads) {
            const ssize_t received = ::read(serial_fd_.get(), chunk, sizeof chunk);
            if (received > 0) {
                assembler.receive(std::span<const std::uint8_t>(chunk, static_cast<std::size_t>(received)), now, events);
                continue;
            }
            if (received < 0 && errno == EINTR) continue;
            if (received == 0 || errno == EAGAIN || errno == EWOULDBLOCK) return true;
            failure = "serial read: " + errno_text(errno);
            return false;
        }
        return true;
    }

    void handle_rtu_event(RtuRequestAssembler::Event& event, TimeNs last_byte_ns) {
        using Kind = RtuRequestAssembler::Event::Kind;
        switch (event.kind) {
            case Kind::request: {
                const bool broadcast = event.address == kBroadcastAddress;
                const std::vector<std::uint8_t> response = serve(event.pdu, endpoint_, broadcast);
                if (response.empty()) return;
                // The spec's 3.5 characters of silence after the request before answering
                // (a half-duplex RS-485 master needs them to turn its line around).
                clock_.sleep_until_ns(last_byte_ns + rtu_inter_frame_gap_ns(rtu_options_.line.baud));
                write_serial(frame_rtu(rtu_options_.slave_id, response));
                return;
            }
            case Kind::bad_crc:
                count([](auto& stats) { ++stats.bad_crc_frames; });
                report_problem(endpoint_ + ": frame with a bad CRC dropped");
                return;
            case Kind::other_slave:
                // Normal on a multi-drop line: counted, not reported.
                count([](auto& stats) { ++stats.other_slave_frames; });
                return;
            case Kind::malformed:
                count([](auto& stats) { ++stats.malformed_frames; });
                report_problem(endpoint_ + ": truncated or oversized frame dropped");
                return;
        }
    }

    void write_serial(const std::vector<std::uint8_t>& frame) {
        const TimeNs deadline = clock_.now_ns() + rtu_options_.write_timeout.count() * kNsPerMs;
        std::size_t written = 0;
        while (written < frame.size() && !stop_requested_) {
            const ssize_t result = ::write(serial_fd_.get(), frame.data() + written, frame.size() - written);
            if (result > 0) {
                written += static_cast<std::size_t>(result);
                continue;
            }
            if (result < 0 && errno == EINTR) continue;
            if (result < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) {
                const TimeNs now = clock_.now_ns();
                if (now >= deadline) break;
                pollfd fds[2] = {{wake_fd_.get(), POLLIN, 0}, {serial_fd_.get(), POLLOUT, 0}};
                ::poll(fds, 2, poll_timeout_ms(deadline, now));
                continue;
            }
            break;
        }
        if (written == frame.size()) return;
        count([](auto& stats) { ++stats.responses_not_sent; });
        report_problem(endpoint_ + ": response not sent (line did not take it within " +
                       std::to_string(rtu_options_.write_timeout.count()) + " ms)");
    }

    // ---------------------------------------------------------------- state

    mutable std::mutex mutex_;  // guards image_, previous_*, stats_, failure_
    mutable std::condition_variable write_cv_;
    RegisterImage image_;
    Coils previous_coils_{};
    HoldingRegisters previous_holding_{};
    ModbusSlaveStatistics stats_;
    std::optional<std::string> failure_;
    std::optional<TimeNs> last_request_ns_;  // clock_ time of the last valid request
    bool failsafe_tripped_ = false;
    CommsFailsafe failsafe_;

    ModbusSlaveCallbacks callbacks_;
    std::string endpoint_;
    std::uint16_t tcp_port_ = 0;
    TcpSlaveOptions tcp_options_;
    RtuSlaveOptions rtu_options_;
    UniqueFd listen_fd_;
    UniqueFd serial_fd_;
    UniqueFd wake_fd_;
    RealtimeClock clock_;

    std::mutex stop_mutex_;
    std::atomic<bool> stop_requested_{false};
    std::thread thread_;
};

ModbusSlave::ModbusSlave(const TcpSlaveOptions& options, ModbusSlaveCallbacks callbacks)
    : impl_(std::make_unique<Impl>(std::move(callbacks))) {
    impl_->start_tcp(options);
}

ModbusSlave::ModbusSlave(const RtuSlaveOptions& options, ModbusSlaveCallbacks callbacks)
    : impl_(std::make_unique<Impl>(std::move(callbacks))) {
    impl_->start_rtu(options);
}

ModbusSlave::~ModbusSlave() = default;

const std::string& ModbusSlave::endpoint() const { return impl_->endpoint(); }
std::uint16_t ModbusSlave::tcp_port() const { return impl_->tcp_port(); }
void ModbusSlave::set_device_signals(const io::DeviceSignals& signals) { impl_->set_device_signals(signals); }
io::DeviceSignals ModbusSlave::device_signals() const { return impl_->device_signals(); }
io::ActuatorCommands ModbusSlave::actuator_commands() const { return impl_->actuator_commands(); }
io::ControllerIndicators ModbusSlave::indicators() const { return impl_->indicators(); }
std::uint64_t ModbusSlave::master_write_count() const { return impl_->master_write_count(); }
std::uint64_t ModbusSlave::wait_for_master_write(std::uint64_t seen, std::chrono::milliseconds timeout) const {
    return impl_->wait_for_master_write(seen, timeout);
}
ModbusSlaveStatistics ModbusSlave::statistics() const { return impl_->statistics(); }
std::optional<std::chrono::nanoseconds> ModbusSlave::since_last_request() const { return impl_->since_last_request(); }
bool ModbusSlave::failsafe_active() const { return impl_->failsafe_active(); }
std::optional<std::string> ModbusSlave::server_failure() const { return impl_->server_failure(); }
void ModbusSlave::stop() { impl_->stop(); }
std::string ModbusSlave::raise_to_realtime(int priority) { return impl_->raise_to_realtime(priority); }

}  // namespace rig::modbus
