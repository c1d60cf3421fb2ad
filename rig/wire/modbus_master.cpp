#include "rig/wire/modbus_master.h"

#include <arpa/inet.h>
#include <poll.h>
#include <unistd.h>
#include <modbus/modbus.h>

#include <cerrno>

namespace rig::modbus {
namespace {

bool is_exception_errno(int error) { return error >= EMBXILFUN && error <= EMBXGTAR; }

bool is_bad_response_errno(int error) {
    return error == EMBBADCRC || error == EMBBADDATA || error == EMBBADEXC || error == EMBUNKEXC ||
           error == EMBMDATA || error == EMBBADSLAVE;
}

std::string two_digits(int code) { return (code < 10 ? "0" : "") + std::to_string(code); }

// libmodbus takes seconds + microseconds.
void split_timeout(std::chrono::milliseconds timeout, std::uint32_t& seconds, std::uint32_t& microseconds) {
    const auto total_us = std::chrono::duration_cast<std::chrono::microseconds>(timeout).count();
    seconds = static_cast<std::uint32_t>(total_us / 1'000'000);
    microseconds = static_cast<std::uint32_t>(total_us % 1'000'000);
}

}  // namespace

struct ModbusMaster::Context {
    explicit Context(modbus_t* context) : handle(context) {}
    ~Context() {
        modbus_close(handle);
        modbus_free(handle);
    }
    Context(const Context&) = delete;
    Context& operator=(const Context&) = delete;
    modbus_t* handle;
    bool tcp = false;
};

ModbusMaster::ModbusMaster(const TcpMasterOptions& options, MasterTimeouts timeouts) : timeouts_(timeouts) {
    const std::string where = options.slave.address + ":" + std::to_string(options.slave.port);
    in_addr parsed{};
    if (inet_pton(AF_INET, options.slave.address.c_str(), &parsed) != 1) {
        throw std::invalid_argument("Modbus master: slave address '" + options.slave.address + "' is not an IPv4 address");
    }
    if (!options.allow_non_loopback && !is_loopback_ipv4(options.slave.address)) {
        throw std::invalid_argument("Modbus master: slave address " + where +
                                    " is not loopback (127.0.0.0/8); these machines talk to 127.0.0.1 only "
                                    "(set allow_non_loopback for a bench with a board on Ethernet)");
    }
    if (options.slave.port == 0) throw std::invalid_argument("Modbus master: slave port 0 (" + where + ") is not a port");
    endpoint_ = "tcp " + where + " unit " + std::to_string(options.unit_id);
    modbus_t* handle = modbus_new_tcp(options.slave.address.c_str(), options.slave.port);
    if (handle == nullptr) {
        throw ModbusMasterError(ModbusMasterError::Kind::connect_failed, endpoint_,
                                "Modbus master " + endpoint_ + ": cannot create a libmodbus context: " +
                                    modbus_strerror(errno));
    }
    context_ = std::make_unique<Context>(handle);
    context_->tcp = true;
    modbus_set_slave(handle, options.unit_id);
    connect();
}

ModbusMaster::ModbusMaster(const RtuMasterOptions& options, MasterTimeouts timeouts) : timeouts_(timeouts) {
    if (auto problem = serial_settings_problem(options.line); !problem.empty()) {
        throw std::invalid_argument("Modbus master: " + problem);
    }
    if (options.slave_id < 1 || options.slave_id > 247) {
        throw std::invalid_argument("Modbus master: slave id " + std::to_string(options.slave_id) + " outside 1..247");
    }
    endpoint_ = "rtu " + describe(options.line) + " slave " + std::to_string(options.slave_id);
    modbus_t* handle = modbus_new_rtu(options.line.device.c_str(), options.line.baud, parity_letter(options.line.parity),
                                      options.line.data_bits, options.line.stop_bits);
    if (handle == nullptr) {
        throw ModbusMasterError(ModbusMasterError::Kind::connect_failed, endpoint_,
                                "Modbus master " + endpoint_ + ": cannot create a libmodbus context: " +
                                    modbus_strerror(errno));
    }
    context_ = std::make_unique<Context>(handle);
    modbus_set_slave(handle, options.slave_id);
    connect();
}

ModbusMaster::~ModbusMaster() = default;

void ModbusMaster::connect() {
    std::uint32_t seconds = 0;
    std::uint32_t microseconds = 0;
    split_timeout(timeouts_.response_timeout, seconds, microseconds);
    modbus_set_response_timeout(context_->handle, seconds, microseconds);
    split_timeout(timeouts_.byte_timeout, seconds, microseconds);
    modbus_set_byte_timeout(context_->handle, seconds, microseconds);
    if (modbus_connect(context_->handle) != 0) {
        const int error = errno;
        throw ModbusMasterError(ModbusMasterError::Kind::connect_failed, endpoint_,
                                "Modbus master " + endpoint_ + ": cannot connect: " + modbus_strerror(error));
    }
    connected_ = true;
}

void ModbusMaster::drain_serial_line() {
    // The rest of a broken frame (the bytes after a hit one, a noise burst in
    // front of a response) may still be arriving: a bare flush now would leave
    // them to be read as the retry's response, and the retry would fail on the
    // last request's leftovers. So: discard until the line has been quiet for
    // kLineSettleSilence, then flush. Bounded: at most kMaxDrainReads reads.
    // 20 ms: USB-serial adapters deliver a frame in chunks up to ~16 ms apart
    // (the slave's frame_end_silence, rig/wire/modbus_slave.h, has the same reason).
    constexpr int kLineSettleSilenceMs = 20;
    constexpr int kMaxDrainReads = 64;
    const int fd = modbus_get_socket(context_->handle);
    for (int reads = 0; fd >= 0 && reads < kMaxDrainReads; ++reads) {
        pollfd watch{fd, POLLIN, 0};
        const int ready = ::poll(&watch, 1, kLineSettleSilenceMs);
        if (ready < 0 && errno == EINTR) continue;
        if (ready <= 0 || (watch.revents & POLLIN) == 0) break;
        std::uint8_t discard[256];
        if (::read(fd, discard, sizeof discard) <= 0) break;
    }
    modbus_flush(context_->handle);
}

void ModbusMaster::fail(const std::string& operation, int error) {
    using Kind = ModbusMasterError::Kind;
    const std::string prefix = "Modbus master " + endpoint_ + ": " + operation + ": ";
    if (is_exception_errno(error)) {
        // The slave is there and answered: the connection stays as it is.
        const int code = error - MODBUS_ENOBASE;
        throw ModbusMasterError(Kind::exception_response, endpoint_,
                                prefix + "slave answered exception " + two_digits(code) + " " +
                                    exception_name(static_cast<std::uint8_t>(code)),
                                static_cast<std::uint8_t>(code));
    }
    // A late or broken response may still be on its way: over TCP start a
    // fresh connection at the next call, on a serial line drop what arrived.
    if (context_->tcp || !(error == ETIMEDOUT || is_bad_response_errno(error))) {
        modbus_close(context_->handle);
        connected_ = false;
    } else {
        drain_serial_line();
    }
    if (error == ETIMEDOUT) {
        throw ModbusMasterError(Kind::timeout, endpoint_,
                                prefix + "no response within " + std::to_string(timeouts_.response_timeout.count()) +
                                    " ms (timeout)");
    }
    if (is_bad_response_errno(error)) {
        throw ModbusMasterError(Kind::bad_response, endpoint_, prefix + "bad response: " + modbus_strerror(error));
    }
    throw ModbusMasterError(Kind::io_error, endpoint_, prefix + modbus_strerror(error));
}

template <typename Call>
int ModbusMaster::transact(const std::string& operation, int expected, Call call) {
    if (!connected_) connect();
    errno = 0;
    const int result = call(context_->handle);
    if (result < 0) fail(operation, errno);
    if (result != expected) {
        throw ModbusMasterError(ModbusMasterError::Kind::bad_response, endpoint_,
                                "Modbus master " + endpoint_ + ": " + operation + ": " + std::to_string(result) +
                                    " items in the response, expected " + std::to_string(expected));
    }
    return result;
}

std::uint16_t ModbusMaster::read_map_version() {
    std::uint16_t version = 0;
    transact("read input register " + std::to_string(kInputMapVersion) + " (FC 04)", 1,
             [&](modbus_t* handle) { return modbus_read_input_registers(handle, kInputMapVersion, 1, &version); });
    return version;
}

io::DeviceSignals ModbusMaster::read_device_signals() {
    InputRegisters registers{};
    transact("read input registers 0.." + std::to_string(kInputRegisterCount - 1) + " (FC 04)", kInputRegisterCount,
             [&](modbus_t* handle) { return modbus_read_input_registers(handle, 0, kInputRegisterCount, registers.data()); });
    if (map_version_of(registers) != kRegisterMapVersion) {
        throw ModbusMasterError(ModbusMasterError::Kind::map_mismatch, endpoint_,
                                "Modbus master " + endpoint_ + ": slave serves register map version " +
                                    std::to_string(map_version_of(registers)) + ", this master speaks version " +
                                    std::to_string(kRegisterMapVersion));
    }
    std::uint8_t bits[kDiscreteInputCount] = {};
    transact("read discrete inputs 0.." + std::to_string(kDiscreteInputCount - 1) + " (FC 02)", kDiscreteInputCount,
             [&](modbus_t* handle) { return modbus_read_input_bits(handle, 0, kDiscreteInputCount, bits); });
    DiscreteInputs inputs{};
    for (std::size_t i = 0; i < inputs.size(); ++i) inputs[i] = bits[i] != 0;
    return decode_device_signals(registers, inputs);
}

void ModbusMaster::write_actuator_commands(const io::ActuatorCommands& commands) {
    const Coils coils = encode_coils(commands);
    std::uint8_t bits[kCoilCount] = {};
    for (std::size_t i = 0; i < coils.size(); ++i) bits[i] = coils[i] ? 1 : 0;
    transact("write coils 0.." + std::to_string(kCoilCount - 1) + " (FC 15)", kCoilCount,
             [&](modbus_t* handle) { return modbus_write_bits(handle, 0, kCoilCount, bits); });
}

void ModbusMaster::write_indicators(const io::ControllerIndicators& indicators) {
    const HoldingRegisters registers = encode_holding_registers(indicators);
    transact("write holding registers 0.." + std::to_string(kHoldingRegisterCount - 1) + " (FC 16)",
             kHoldingRegisterCount,
             [&](modbus_t* handle) { return modbus_write_registers(handle, 0, kHoldingRegisterCount, registers.data()); });
}

io::ActuatorCommands ModbusMaster::read_actuator_commands() {
    std::uint8_t bits[kCoilCount] = {};
    transact("read coils 0.." + std::to_string(kCoilCount - 1) + " (FC 01)", kCoilCount,
             [&](modbus_t* handle) { return modbus_read_bits(handle, 0, kCoilCount, bits); });
    Coils coils{};
    for (std::size_t i = 0; i < coils.size(); ++i) coils[i] = bits[i] != 0;
    return decode_coils(coils);
}

io::ControllerIndicators ModbusMaster::read_indicators() {
    HoldingRegisters registers{};
    transact("read holding registers 0.." + std::to_string(kHoldingRegisterCount - 1) + " (FC 03)",
             kHoldingRegisterCount,
             [&](modbus_t* handle) { return modbus_read_registers(handle, 0, kHoldingRegisterCount, registers.data()); });
    return decode_holding_registers(registers);
}

}  // namespace rig::modbus
