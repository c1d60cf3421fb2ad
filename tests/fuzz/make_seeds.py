#!/usr/bin/env python3
"""Writes the Modbus and breakpoint-store seed corpora (corpus/*/): run once,
the output is committed. NMEA and case-file seeds are copies (corpus/README.md)."""
import os
import struct
import zlib

HERE = os.path.dirname(os.path.abspath(__file__))


def crc16_modbus(data: bytes) -> int:
    crc = 0xFFFF
    for byte in data:
        crc ^= byte
        for _ in range(8):
            crc = (crc >> 1) ^ 0xA001 if crc & 1 else crc >> 1
    return crc


def write(target: str, name: str, data: bytes) -> None:
    directory = os.path.join(HERE, "corpus", target)
    os.makedirs(directory, exist_ok=True)
    with open(os.path.join(directory, name), "wb") as out:
        out.write(data)


# One request of each served function code, and some refused ones (PDUs).
REQUESTS = {
    "read-coils": bytes([0x01]) + struct.pack(">HH", 0, 8),
    "read-discrete": bytes([0x02]) + struct.pack(">HH", 0, 2),
    "read-holding": bytes([0x03]) + struct.pack(">HH", 0, 4),
    "read-input": bytes([0x04]) + struct.pack(">HH", 0, 10),
    "write-coil": bytes([0x05]) + struct.pack(">HH", 1, 0xFF00),
    "write-register": bytes([0x06]) + struct.pack(">HH", 0, 1234),
    "write-coils": bytes([0x0F]) + struct.pack(">HHB", 0, 10, 2) + bytes([0xA5, 0x01]),
    "write-registers": bytes([0x10]) + struct.pack(">HHB", 0, 2, 4) + struct.pack(">HH", 7, 9),
    "bad-function": bytes([0x2B, 0x0E, 0x01, 0x00]),
    "bad-quantity": bytes([0x03]) + struct.pack(">HH", 0, 0),
    "bad-address": bytes([0x04]) + struct.pack(">HH", 0xFFF0, 100),
    "bad-coil-value": bytes([0x05]) + struct.pack(">HH", 0, 0x1234),
}

for name, pdu in REQUESTS.items():
    write("modbus_request_fuzz", "pdu-" + name, bytes([0]) + pdu)
    # RTU: slave 1, the frame in one chunk (control byte: length, then silence).
    frame = bytes([1]) + pdu
    frame += struct.pack("<H", crc16_modbus(frame))
    chunks = b""
    for start in range(0, len(frame), 31):
        part = frame[start:start + 31]
        chunks += bytes([len(part)]) + part
    write("modbus_request_fuzz", "rtu-" + name, bytes([1]) + chunks + bytes([0xC0]))
    # TCP: MBAP header (transaction 1, protocol 0, length, unit 1), then the PDU.
    write("modbus_request_fuzz", "tcp-" + name, bytes([2]) + struct.pack(">HHHB", 1, 0, len(pdu) + 1, 1) + pdu)

# A frame for another slave followed by one for us, and a bad CRC.
other = bytes([7, 0x03, 0, 0, 0, 1])
other += struct.pack("<H", crc16_modbus(other))
ours = bytes([1, 0x03, 0, 0, 0, 1])
ours += struct.pack("<H", crc16_modbus(ours))
write("modbus_request_fuzz", "rtu-other-slave-then-ours",
      bytes([1, len(other)]) + other + bytes([0x80, len(ours)]) + ours)
write("modbus_request_fuzz", "rtu-bad-crc", bytes([1, len(ours)]) + ours[:-1] + bytes([ours[-1] ^ 0xFF, 0xC0]))


def store(next_id: int, records: list) -> bytes:
    text = "rig-breakpoint-store v1 next_id=%d\n" % next_id
    for record in records:
        text += "bp %d %s %s %s\n" % record
    text += "crc32 %08x\n" % (zlib.crc32(text.encode()) & 0xFFFFFFFF)
    return text.encode()


write("breakpoint_store_fuzz", "empty", store(1, []))
write("breakpoint_store_fuzz", "one", store(2, [(1, "40.180001234", "116.44", "90")]))
write("breakpoint_store_fuzz", "after-removals",
      store(9, [(1, "40.18", "116.440023", "270"), (3, "-33.8688", "151.2093", "0.5"), (8, "0", "-180", "359.99")]))
write("breakpoint_store_fuzz", "torn", store(2, [(1, "40.18", "116.44", "90")])[:-9])
