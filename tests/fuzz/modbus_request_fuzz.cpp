// libFuzzer harness: the Modbus protocol engine the rig's slave answers with
// (rig/wire/modbus_protocol.h): serve_request() on any PDU, the RTU request
// assembler on any bytes and silences, the MBAP header check.
// Oracles beyond the sanitizers: after a silence, the assembler's next deadline
// lies ahead (or there is none); a response PDU is never empty for a non-empty
// request and never over 253 bytes; an exception response is exactly
// {function | 0x80, code}; a refused request changes nothing in the image
// (the spec's "checked completely before anything is stored"); only writes
// change the image.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <span>
#include <vector>

#include "rig/wire/modbus_protocol.h"
#include "rig/wire/modbus_register_map.h"

namespace {

using namespace rig::modbus;

void require(bool condition) {
    if (!condition) std::abort();  // a finding: libFuzzer keeps the input
}

bool same(const RegisterImage& a, const RegisterImage& b) {
    return a.input_registers == b.input_registers && a.discrete_inputs == b.discrete_inputs && a.coils == b.coils &&
           a.holding_registers == b.holding_registers;
}

void serve_and_check(std::span<const std::uint8_t> pdu, RegisterImage& image) {
    const RegisterImage before = image;
    const ServedRequest served = serve_request(pdu, image);
    if (pdu.empty()) {
        require(served.response_pdu.empty());
        return;
    }
    require(!served.response_pdu.empty() && served.response_pdu.size() <= kMaxPduSize);
    if (served.exception) {
        require(served.response_pdu.size() == 2);
        require(served.response_pdu[0] == (pdu[0] | 0x80u));
        require(served.response_pdu[1] == static_cast<std::uint8_t>(*served.exception));
        require(!served.problem.empty());
        require(same(before, image));
        require(!served.wrote_outputs);
    } else {
        require(served.response_pdu[0] == pdu[0]);
        if (!served.wrote_outputs) require(same(before, image));
        // Inputs are the rig's: no request may change them.
        require(before.input_registers == image.input_registers && before.discrete_inputs == image.discrete_inputs);
    }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    if (size == 0) return 0;
    const std::span<const std::uint8_t> input(data + 1, size - 1);
    RegisterImage image;
    // Something in every table, so reads have values to return.
    for (std::size_t i = 0; i < image.input_registers.size(); ++i) image.input_registers[i] = static_cast<std::uint16_t>(i * 7919u);
    for (std::size_t i = 0; i < image.discrete_inputs.size(); ++i) image.discrete_inputs[i] = (i % 3) == 0;
    switch (data[0] % 3) {
        case 0:  // one request PDU
            serve_and_check(input, image);
            break;
        case 1: {  // a serial line: chunks of bytes, separated by silences
            RtuRequestAssembler assembler(1, RtuRequestAssembler::Timing{});
            std::vector<RtuRequestAssembler::Event> events;
            rig::TimeNs now_ns = 0;
            std::size_t at = 0;
            while (at < input.size()) {
                // First byte of a chunk: its length (low 5 bits) and whether silence follows (high bit).
                const std::uint8_t control = input[at++];
                const std::size_t length = std::min<std::size_t>(control & 0x1Fu, input.size() - at);
                assembler.receive(input.subspan(at, length), now_ns, events);
                at += length;
                now_ns += 100'000;
                if ((control & 0x80u) != 0) {
                    now_ns += (control & 0x40u) != 0 ? 60'000'000 : 2'000'000;
                    assembler.silence(now_ns, events);
                    // Silence has done what it can at now_ns: what is left ends later.
                    // (Time only matters through silence(), modbus_protocol.h: chunks
                    // between silences may leave the deadline behind now_ns.)
                    const rig::TimeNs deadline = assembler.next_deadline_ns();
                    require(deadline == rig::kNever || deadline > now_ns);
                }
            }
            for (const auto& event : events) {
                if (event.kind != RtuRequestAssembler::Event::Kind::request) continue;
                require(event.address == 1 || event.address == kBroadcastAddress);
                require(event.pdu.size() + 3 <= kMaxRtuFrameSize);
                serve_and_check(event.pdu, image);
            }
            break;
        }
        default: {  // Modbus TCP: an MBAP header, then the PDU it announces
            if (input.size() < kMbapHeaderSize) return 0;
            const MbapHeader header = parse_mbap_header(input.first<kMbapHeaderSize>());
            if (!mbap_header_problem(header).empty()) return 0;
            const std::span<const std::uint8_t> pdu = input.subspan(kMbapHeaderSize);
            if (pdu.size() + 1 < header.length) return 0;  // incomplete: the slave waits for more
            const std::span<const std::uint8_t> request = pdu.first(header.length - 1u);
            const RegisterImage before = image;
            const ServedRequest served = serve_request(request, image);
            const std::vector<std::uint8_t> adu = frame_tcp_response(header, served.response_pdu);
            require(adu.size() == kMbapHeaderSize + served.response_pdu.size());
            if (served.exception) require(same(before, image));
            break;
        }
    }
    return 0;
}
